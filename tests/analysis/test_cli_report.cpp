#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bbw/common/csv.hpp"

#include "bbw/analyze/cli.hpp"
#include "bbw/analyze/report.hpp"
#include "synthetic.hpp"

using namespace bbw;

TEST(AnalyzeCli, ParsesAndRejects) {
  const auto a = analyze::parse_args({"--input", "f.csv", "--out", "d", "--channels", "A,B", "--truth", "none"});
  EXPECT_EQ(a.input, "f.csv");
  EXPECT_TRUE(a.channels_given);
  EXPECT_EQ(a.channels, (std::vector<std::string>{"A", "B"}));
  EXPECT_EQ(a.truth_col, "none");
  const auto b = analyze::parse_args({"--input", "f.csv", "--out", "d", "--channels", "none"});
  EXPECT_TRUE(b.channels.empty());
  EXPECT_THROW(analyze::parse_args({"--input", "f.csv"}), std::invalid_argument);
  EXPECT_THROW(analyze::parse_args({"--input", "f.csv", "--out", "d", "--bogus", "1"}), std::invalid_argument);
  EXPECT_THROW(analyze::parse_args({"--input"}), std::invalid_argument);
  EXPECT_EQ(analyze::unit_from_column("force_internal_kN"), "kN");
  EXPECT_EQ(analyze::unit_from_column("F_N"), "N");
}

// End to end through the CSV reader and the report writer on a synthetic recording with a
// viscous term: the outputs exist and carry the figures the issue asks for.
TEST(AnalyzeCli, WritesJsonReportAndPlots) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("bbw_analyze_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  analysis::test::SyntheticOptions so;
  so.duration_s = 6.0;
  so.effects = {"viscous_friction"};
  const auto rec = analysis::test::synthetic(so);
  {
    std::ofstream f(dir / "rec.csv");
    f << "time_s,position_rev,force_internal_kN,force_external_kN,temperature_C\n";
    f.precision(10);
    for (std::size_t k = 0; k < rec.time_s.size(); ++k)
      f << rec.time_s[k] << "," << rec.position[k] << "," << rec.force[k] << "," << rec.truth[k] << ","
        << rec.temperature[k] << "\n";
    f << "oops,1,2,3,4\n";
  }
  analyze::CliArgs a = analyze::parse_args({"--input", (dir / "rec.csv").string(), "--out", (dir / "out").string()});
  const auto in = analyze::load_recording(a);
  EXPECT_EQ(in.lines_rejected, 1u);
  EXPECT_EQ(in.truth_col, "force_external_kN");
  EXPECT_EQ(in.temperature_col, "temperature_C");
  EXPECT_TRUE(in.channel_cols.empty());
  EXPECT_EQ(in.force_unit, "kN");
  const analysis::AnalysisOptions o;
  const auto r = analysis::analyze(in.rec, o);
  analyze::write_outputs((dir / "out").string(), in, o, r, true);
  std::ifstream j(dir / "out" / "analysis.json");
  std::stringstream js;
  js << j.rdbuf();
  for (const char* key : {"\"baseline\"", "\"final\"", "\"rms_residual\"", "\"max_residual\"", "\"rms_truth_error\"",
                          "\"max_truth_error\"", "\"force_unit\": \"kN\"", "\"steps\"", "\"rejected\"",
                          "\"unexplained_structure\"", "\"structure_tests\"", "\"name\": \"viscous_friction\"",
                          "\"calibrator_effects\": {", "\"viscous_friction\": true"})
    EXPECT_NE(js.str().find(key), std::string::npos) << key;
  {
    std::ifstream md(dir / "out" / "report.md");
    std::stringstream ms;
    ms << md.rdbuf();
    EXPECT_NE(ms.str().find("effects:\n  viscous_friction: true\n"), std::string::npos) << ms.str();
  }
  for (const char* f : {"report.md", "residual_time.png", "residual_vs_regressor.png", "truth_error_time.png"})
    EXPECT_GT(fs::file_size(dir / "out" / f), 100u) << f;
  fs::remove_all(dir);
}

namespace {

struct ToolRun {
  int exit_code;
  std::string output;
};

ToolRun run_analyze(const std::string& args) {
  const std::string cmd = std::string(BBW_BINARY_DIR_FALLBACK) + "/bin/bbw_analyze " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[512];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace

// Issue 17: the input is checked for its kind before anything reads it (the header was read
// first: /dev/zero grew to 10.6 GB, a FIFO without a writer hung), and a data error is one line.
TEST(AnalyzeCli, RefusesDevicesFifosAndDirectoriesWithOneLine) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("bbw_analyze_kinds_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir / "fifo.csv").c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  for (const std::string& input : {std::string("/dev/zero"), (dir / "fifo.csv").string(), dir.string()}) {
    const auto r = run_analyze("--input " + input + " --out " + (dir / "out").string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(r.output.rfind("bbw_analyze: " + input + ": is ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20.0);
  // Garbage bytes are escaped, and a missing column is one line too (exit 2, no usage).
  {
    std::ofstream f(dir / "junk.csv", std::ios::binary);
    f << "\x1b[31m\xff,b\n1,2\n";
  }
  auto r = run_analyze("--input " + (dir / "junk.csv").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("header has: \\x1B[31m\\xFF, b"), std::string::npos) << r.output;
  for (const char c : r.output) EXPECT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f)) << r.output;
  EXPECT_EQ(r.output.find("usage"), std::string::npos) << r.output;
  r = run_analyze("--input " + (dir / "junk.csv").string() + " --out " + (dir / "out").string() + " --truth nope");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(r.output, "bbw_analyze: " + (dir / "junk.csv").string() + ": no column 'nope'\n");
  // Argument errors still show the usage.
  r = run_analyze("--bogus");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("usage: bbw_analyze"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The same reader as calibrate: a BOM and a quoted header are accepted; time must increase.
TEST(AnalyzeCli, QuotedHeaderWithBomAndUnsortedTime) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("bbw_analyze_quoted_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "q.csv", std::ios::binary);
    f << "\xEF\xBB\xBF\"time_s\",\"position_rev\",\"force_internal_kN\"\n0,1,2\n0.1,1,2\n0.1,1,2\n0.2,1,2\n";
  }
  analyze::CliArgs a = analyze::parse_args({"--input", (dir / "q.csv").string(), "--out", (dir / "o").string()});
  try {
    analyze::load_recording(a);
    ADD_FAILURE() << "time that does not increase was accepted";
  } catch (const csv::CsvError& e) {
    EXPECT_NE(std::string(e.what()).find("q.csv:4: time 'time_s' does not increase"), std::string::npos) << e.what();
  }
  a = analyze::parse_args(
      {"--input", (dir / "q.csv").string(), "--out", (dir / "o").string(), "--allow-unsorted-time"});
  const auto in = analyze::load_recording(a);
  EXPECT_EQ(in.rec.time_s, (std::vector<double>{0, 0.1, 0.2}));
  EXPECT_EQ(in.lines_unsorted_time, 1u);
  EXPECT_TRUE(in.channel_cols.empty());
  fs::remove_all(dir);
}
