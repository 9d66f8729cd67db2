// bbw_calibrate as a user runs it: a real recording from bbw_simulate's CSV schema with some
// corrupt lines, column mapping, and the error cases.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bbw/calibration/config_yaml.hpp"
#include "bbw/calibration/rig_recording.hpp"
#include "bbw/common/csv.hpp"
#include "bbw/scenario/load.hpp"

namespace fs = std::filesystem;

namespace {

struct Run {
  int exit_code;
  std::string output;
};

Run run(const std::string& args) {
  const std::string cmd = std::string(BBW_BINARY_DIR_FALLBACK) + "/bin/bbw_calibrate " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[512];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Writes the rig at 44 C in custom column names, with corrupt lines at known places.
fs::path write_recording(const fs::path& dir, bool corrupt) {
  const auto sc = bbw::scenario::load_scenario(std::string(BBW_SOURCE_DIR_FALLBACK) + "/config/scenarios/paper_rig_44C.yaml");
  const auto rec = bbw::calibration::record_corner(sc, 0);
  const fs::path file = dir / "rig.csv";
  std::ofstream f(file);
  f << "t,x,f_int,f_ext\n";
  for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
    if (corrupt && k == 100) f << "0.1,nan,1,1\n";
    if (corrupt && k == 200) f << "0.2,1,inf,1\n";
    if (corrupt && k == 300) f << "garbage line\n";
    char line[160];
    std::snprintf(line, sizeof line, "%.6f,%.9g,%.9g,%.9g\n", rec.time_s[k], rec.position_rev[k], rec.force_kN[k],
                  rec.truth_kN[k]);
    f << line;
  }
  return file;
}

}  // namespace

TEST(CalibrateCli, MappedColumnsCorruptLinesCountedOutputsWritten) {
  const auto dir = temp_dir("calibrate_cli");
  const auto csv = write_recording(dir, true);
  const auto out = dir / "out";
  const auto r = run("--input " + csv.string() + " --out " + out.string() +
                     " --time t --position x --force f_int --truth f_ext");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rejected 3 of"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("line 102"), std::string::npos) << r.output;  // header is line 1
  const std::string summary = read_file(out / "summary.json");
  for (const char* key : {"\"max_abs_error_kN\"", "\"rms_error_kN\"", "\"max_error_pct_fs\"", "\"samples_scored\"",
                          "\"warmup_s\"", "\"cycles_detected\"", "\"fits_accepted\"", "\"fits_rejected\"",
                          "\"curve\"", "\"friction\"", "\"mode\": \"robust\"", "\"lines_rejected\": 3"}) {
    EXPECT_NE(summary.find(key), std::string::npos) << key << "\n" << summary;
  }
  for (const char* png : {"force_position.png", "estimate_time.png", "error_time.png"}) {
    ASSERT_TRUE(fs::exists(out / png)) << png;
    EXPECT_GT(fs::file_size(out / png), 5000u) << png;
  }
  // estimates.csv: one row per usable input line, plus the header.
  std::ifstream est(out / "estimates.csv");
  std::size_t lines = 0;
  for (std::string l; std::getline(est, l);) ++lines;
  EXPECT_EQ(lines, 34000u + 1u);
}

TEST(CalibrateCli, SameNumbersAsTheLibrary) {
  const auto dir = temp_dir("calibrate_cli_same");
  const auto csv = write_recording(dir, false);
  const auto out = dir / "out";
  ASSERT_EQ(run("--input " + csv.string() + " --out " + out.string() + " --time t --position x --force f_int --truth f_ext")
                .exit_code,
            0);
  const std::string summary = read_file(out / "summary.json");
  // Score the library on the same (6-digit time, 9-digit value) data the CSV holds.
  bbw::csv::ReadOptions o;
  o.required = {"t", "x", "f_int", "f_ext"};
  const auto table = bbw::csv::read(csv.string(), o);
  bbw::calibration::Recording rec{table.column("t"), table.column("x"), table.column("f_int"), table.column("f_ext"), {}, {}};
  const auto cfg = bbw::calibration::load_config(std::string(BBW_SOURCE_DIR_FALLBACK) + "/config/calibrator/robust.yaml");
  const auto res = bbw::calibration::run_recording(cfg, rec);
  char expected[64];
  std::snprintf(expected, sizeof expected, "\"max_abs_error_kN\": %.9g", res.score.max_abs_error_kN);
  EXPECT_NE(summary.find(expected), std::string::npos) << expected << "\n" << summary;
}

TEST(CalibrateCli, ErrorsAreClearAndNonZero) {
  const auto dir = temp_dir("calibrate_cli_err");
  {
    std::ofstream f(dir / "empty.csv");
    f << "time_s,position_rev,force_internal_kN\nnan,1,2\n";
  }
  auto r = run("--input " + (dir / "empty.csv").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no usable data line"), std::string::npos) << r.output;
  r = run("--input " + (dir / "missing.csv").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("cannot open file"), std::string::npos) << r.output;
  r = run("--input " + (dir / "empty.csv").string() + " --out " + (dir / "o").string() + " --position nope");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("required column 'nope' is missing"), std::string::npos) << r.output;
  r = run("--out x");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--input is required"), std::string::npos) << r.output;
  r = run("--input a --out b --bogus");
  EXPECT_EQ(r.exit_code, 2);
  {
    std::ofstream f(dir / "bad.yaml");
    f << "mode: robust\n";
  }
  r = run("--input " + (dir / "empty.csv").string() + " --out " + (dir / "o").string() + " --config " +
          (dir / "bad.yaml").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("bad.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("required key is missing"), std::string::npos) << r.output;
}

// --temperature maps the column that feeds the load-cell thermal offset term: the tool gives the
// library's numbers with it, and other numbers without it (the term did act).
TEST(CalibrateCli, TemperatureColumnFeedsTheThermalOffsetTerm) {
  const auto dir = temp_dir("calibrate_cli_temp");
  const auto sc = bbw::scenario::load_scenario(std::string(BBW_SOURCE_DIR_FALLBACK) + "/config/scenarios/paper_rig_44C.yaml");
  auto rec = bbw::calibration::record_corner(sc, 0);
  {
    std::ofstream f(dir / "rig.csv");
    f << "t,x,f_int,f_ext,temp\n";
    for (std::size_t k = 0; k < rec.time_s.size(); ++k) {
      const double temp_C = 40.0 + 0.5 * rec.time_s[k];  // a warming caliper: its load cell drifts
      char line[200];
      std::snprintf(line, sizeof line, "%.6f,%.9g,%.9g,%.9g,%.6f\n", rec.time_s[k], rec.position_rev[k],
                    rec.force_kN[k] + 0.02 * (temp_C - 40.0), rec.truth_kN[k], temp_C);
      f << line;
    }
  }
  {
    std::ofstream f(dir / "cal.yaml");
    f << read_file(std::string(BBW_SOURCE_DIR_FALLBACK) + "/config/calibrator/robust.yaml")
      << "effects:\n  load_cell_offset_kN_per_C: 0.02\n  load_cell_offset_reference_C: 40.0\n";
  }
  const std::string common = "--input " + (dir / "rig.csv").string() + " --config " + (dir / "cal.yaml").string() +
                             " --time t --position x --force f_int --truth f_ext";
  ASSERT_EQ(run(common + " --out " + (dir / "with").string() + " --temperature temp").exit_code, 0);
  ASSERT_EQ(run(common + " --out " + (dir / "without").string()).exit_code, 0);
  bbw::csv::ReadOptions o;
  o.required = {"t", "x", "f_int", "f_ext", "temp"};
  const auto table = bbw::csv::read((dir / "rig.csv").string(), o);
  bbw::calibration::Recording r{table.column("t"), table.column("x"), table.column("f_int"), table.column("f_ext"), {},
                                table.column("temp")};
  const auto res = bbw::calibration::run_recording(bbw::calibration::load_config((dir / "cal.yaml").string()), r);
  char expected[64];
  std::snprintf(expected, sizeof expected, "\"max_abs_error_kN\": %.9g", res.score.max_abs_error_kN);
  EXPECT_NE(read_file(dir / "with" / "summary.json").find(expected), std::string::npos) << expected;
  EXPECT_EQ(read_file(dir / "without" / "summary.json").find(expected), std::string::npos) << expected;
  EXPECT_NE(run(common + " --out " + (dir / "x").string() + " --temperature nope").output.find("'nope'"),
            std::string::npos);
}

// Honest failure (issue 17): a recording too short for a fit gives exit 1 naming the reason, a
// summary with status failed and null errors (not 0), and no plot.
TEST(CalibrateCli, NoAcceptedFitFailsWithTheReasonAndNullErrors) {
  const auto dir = temp_dir("calibrate_cli_nofit");
  {
    std::ofstream f(dir / "four.csv");
    f << "time_s,position_rev,force_internal_kN,force_external_kN\n0,0,0,0\n0.001,0.1,0.2,0.2\n0.002,0.2,0.4,0.4\n"
         "0.003,0.3,0.6,0.6\n";
  }
  const auto out = dir / "out";
  const auto r = run("--input " + (dir / "four.csv").string() + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("calibration failed: no fit accepted (0 cycles detected"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("gnuplot"), std::string::npos) << r.output;
  const std::string summary = read_file(out / "summary.json");
  for (const char* key : {"\"status\": \"failed\"", "\"reason\": \"no fit accepted", "\"max_abs_error_kN\": null",
                          "\"rms_error_kN\": null", "\"samples_scored\": 0",
                          "\"not_scored_reason\": \"no fit accepted, so no estimate to score\""}) {
    EXPECT_NE(summary.find(key), std::string::npos) << key << "\n" << summary;
  }
  for (const char* png : {"force_position.png", "estimate_time.png", "error_time.png"}) {
    EXPECT_FALSE(fs::exists(out / png)) << png;
  }
}

// One CSV reader: time that does not increase is refused with its line number, or dropped and
// counted with --allow-unsorted-time; a BOM and quoted header are fine; duplicates are refused.
TEST(CalibrateCli, UnsortedTimeBomAndDuplicateColumns) {
  const auto dir = temp_dir("calibrate_cli_csv");
  const auto csv = write_recording(dir, false);
  std::string body = read_file(csv);
  body.erase(0, body.find('\n') + 1);
  const std::string dup_line = body.substr(0, body.find('\n') + 1);  // the first data line again
  {
    std::ofstream f(dir / "unsorted.csv");
    f << "\xEF\xBB\xBF\"t\",\"x\",\"f_int\",\"f_ext\"\n" << body.substr(0, 1000) << body.substr(1000, body.size() - 1000);
    f << dup_line;  // time jumps back at the end: line 34002
  }
  const std::string cols = " --time t --position x --force f_int --truth f_ext";
  auto r = run("--input " + (dir / "unsorted.csv").string() + " --out " + (dir / "o1").string() + cols);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("unsorted.csv:34002: time 't' does not increase"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;  // one line, no usage
  r = run("--input " + (dir / "unsorted.csv").string() + " --out " + (dir / "o2").string() + cols +
          " --allow-unsorted-time");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("dropped 1 whose time did not increase (first: line 34002)"), std::string::npos) << r.output;
  EXPECT_NE(read_file(dir / "o2" / "summary.json").find("\"lines_unsorted_time_dropped\": 1"), std::string::npos);
  {
    std::ofstream f(dir / "dup.csv");
    f << "t,x,f_int,x\n0,1,2,3\n";
  }
  r = run("--input " + (dir / "dup.csv").string() + " --out " + (dir / "o3").string() + cols);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("dup.csv:1: column 'x' appears twice in the header (fields 2 and 4)"), std::string::npos)
      << r.output;
}

// A plotting failure names what failed and leaves no PNG (gnuplot cannot be found here).
TEST(CalibrateCli, PlotFailureNamesWhatFailedAndLeavesNoPng) {
  const auto dir = temp_dir("calibrate_cli_plotfail");
  const auto csv = write_recording(dir, false);
  const auto out = dir / "out";
  const std::string cmd = "/usr/bin/env PATH=/nonexistent " + std::string(BBW_BINARY_DIR_FALLBACK) +
                          "/bin/bbw_calibrate --input " + csv.string() + " --out " + out.string() +
                          " --time t --position x --force f_int --truth f_ext 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string text;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) text += buf;
  const int status = pclose(p);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << text;
  EXPECT_NE(text.find("plots: gnuplot could not be started (is gnuplot installed? ./bbw setup) on " +
                      (out / "plots.gp").string()),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("not written: " + (out / "force_position.png").string()), std::string::npos) << text;
  for (const char* png : {"force_position.png", "estimate_time.png", "error_time.png"}) {
    EXPECT_FALSE(fs::exists(out / png)) << png;
  }
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}
