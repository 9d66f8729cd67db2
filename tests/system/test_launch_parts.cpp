// The launcher's parts without processes: the run summary never claims an error of 0 over no
// sample (null and a reason), bbw_compare_feedback refuses a null error with the reason, and the
// run statistics round-trip through their one serialiser/parser pair (bbw/runtime/run_stats.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bbw/runtime/run_stats.hpp"
#include "summary.hpp"
#include "summary_reader.hpp"

namespace {

namespace fs = std::filesystem;

const char* kHeader =
    "time_s,position_rev,force_internal_kN,force_true_kN,command,force_mode,estimate_kN,curve_kN,fused_kN,valid,calibrated\n";

bbw::csv::Table table(const std::string& rows) {
  std::istringstream in(std::string(kHeader) + rows);
  return bbw::csv::read_stream(in, "ccu_FL.csv", bbw::launch::ccu_log_columns());
}

std::string temp_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("bbw_launch_parts_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p.string();
}

TEST(LaunchSummary, NothingScoredGivesNullErrorsAndAReason) {
  // Never calibrated, position commands only: nothing to score.
  const auto s = bbw::launch::summarize_corner("FL", table("0.001,0.1,1.0,1.0,0.1,0,1.0,1.0,1.0,0,0\n"
                                                           "0.002,0.1,1.1,1.0,0.1,0,1.0,1.0,1.0,0,0\n"));
  EXPECT_EQ(s.samples_scored, 0u);
  EXPECT_TRUE(std::isnan(s.fused_max_abs_error_kN));
  EXPECT_TRUE(std::isnan(s.fused_rms_error_kN));
  EXPECT_TRUE(std::isnan(s.compensated_max_abs_error_kN));
  EXPECT_TRUE(std::isnan(s.load_cell_rms_error_kN));
  EXPECT_TRUE(std::isnan(s.tracking_rms_error_kN));
  EXPECT_TRUE(std::isnan(s.tracking_steady_max_abs_error_kN));
  EXPECT_NE(bbw::launch::not_scored_reason(s, 0).find("no calibration fit was accepted"), std::string::npos);
  EXPECT_NE(bbw::launch::not_scored_reason(s, 2).find("no sample had a valid estimate"), std::string::npos);
  EXPECT_NE(bbw::launch::tracking_not_scored_reason(s).find("clamp-force command"), std::string::npos);
  bbw::launch::CornerSummary empty;  // a log without a data line is refused by the reader
  EXPECT_NE(bbw::launch::not_scored_reason(empty, 3).find("logged no sample"), std::string::npos);
}

TEST(LaunchSummary, ScoredSamplesGiveNumbersAndNoReason) {
  const auto s = bbw::launch::summarize_corner("FL", table("0.001,0.1,1.5,1.0,1.0,1,1.2,1.0,1.25,1,1\n"
                                                           "0.002,0.1,1.5,1.0,1.0,1,1.2,1.0,0.75,1,1\n"));
  EXPECT_EQ(s.samples_scored, 2u);
  EXPECT_DOUBLE_EQ(s.fused_max_abs_error_kN, 0.25);
  EXPECT_DOUBLE_EQ(s.fused_rms_error_kN, 0.25);
  EXPECT_DOUBLE_EQ(s.load_cell_rms_error_kN, 0.5);
  EXPECT_DOUBLE_EQ(s.tracking_rms_error_kN, 0.0);
  EXPECT_EQ(bbw::launch::not_scored_reason(s, 1), "");
  // Force commands but no hold of 0.3 s: the steady errors are null with their reason.
  EXPECT_TRUE(std::isnan(s.tracking_steady_rms_error_kN));
  EXPECT_NE(bbw::launch::tracking_not_scored_reason(s).find("no hold"), std::string::npos);
}

TEST(CompareFeedbackSummary, ANullTrackingErrorIsAClearError) {
  const std::string f = temp_file("null.json", R"({"corners": [{"corner": "FL", "fits_accepted": 0,
    "tracking_rms_error_kN": null, "tracking_max_abs_error_kN": null, "tracking_steady_rms_error_kN": null,
    "tracking_steady_max_abs_error_kN": null, "tracking_not_scored_reason": "no sample was under a clamp-force command"}]})");
  try {
    bbw::compare_feedback::read_summary(f);
    ADD_FAILURE() << "a null error was read as a number";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("corner FL"), std::string::npos) << m;
    EXPECT_NE(m.find("tracking_rms_error_kN"), std::string::npos) << m;
    EXPECT_NE(m.find("no sample was under a clamp-force command"), std::string::npos) << m;
  }
  fs::remove(f);
}

TEST(CompareFeedbackSummary, NumbersAreRead) {
  const std::string f = temp_file("ok.json", R"({"corners": [{"corner": "RR", "fits_accepted": 3,
    "tracking_rms_error_kN": 0.5, "tracking_max_abs_error_kN": 1.5, "tracking_steady_rms_error_kN": 0.25,
    "tracking_steady_max_abs_error_kN": 0.75, "tracking_not_scored_reason": null}]})");
  const auto m = bbw::compare_feedback::read_summary(f);
  ASSERT_EQ(m.count("RR"), 1u);
  EXPECT_DOUBLE_EQ(m.at("RR").rms, 0.5);
  EXPECT_DOUBLE_EQ(m.at("RR").steady_max, 0.75);
  EXPECT_EQ(m.at("RR").fits, 3);
  fs::remove(f);
}

bbw::runtime::CcuRunStats sample_ccu_stats() {
  bbw::runtime::CcuRunStats s;
  s.mode = "lockstep";
  s.periods_planned = 2000;
  s.periods_done = 1999;
  s.sim_s = 1.999;
  s.wall_s = 0.1 + 0.2;  // not exactly representable: must read back bit for bit
  s.foreign_runs = "0123456789abcdef:42:bbw_ccu";
  bbw::runtime::CcuCornerStats fl;
  fl.corner = "FL";
  fl.samples_received = 80000;
  fl.fits_accepted = 3;
  fl.first_fit_time_s = std::nan("");
  fl.curve_a = -1.0 / 3.0;
  bbw::runtime::CcuCornerStats rr = fl;
  rr.corner = "RR";
  rr.sample_gaps = 7;
  s.corners = {fl, rr};
  s.detections = {{"FR", "load_cell_offset", "load_cell", 2.5, 2.523}, {"RR", "link_lost", "link", 4.0, 4.1}};
  return s;
}

TEST(RunStats, CcuStatsRoundTripExactly) {
  const auto s = sample_ccu_stats();
  const std::string text = bbw::runtime::to_text(s);
  const auto r = bbw::runtime::parse_ccu_stats(text, "ccu.stats");
  EXPECT_EQ(bbw::runtime::to_text(r), text);
  EXPECT_EQ(r.wall_s, s.wall_s);
  ASSERT_EQ(r.corners.size(), 2u);
  EXPECT_EQ(r.corner("RR", "ccu.stats").sample_gaps, 7u);
  EXPECT_TRUE(std::isnan(r.corner("FL", "ccu.stats").first_fit_time_s));
  EXPECT_EQ(r.corner("FL", "ccu.stats").curve_a, -1.0 / 3.0);
  ASSERT_EQ(r.detections.size(), 2u);
  EXPECT_EQ(r.detections[1].finding, "link_lost");
  EXPECT_EQ(r.detections[0].detected_s, 2.523);
  EXPECT_THROW(r.corner("RL", "ccu.stats"), std::runtime_error);
  // The file format stays key=value, one per line, as before the typed struct.
  EXPECT_NE(text.find("\nFL.samples_received=80000\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\ncorners=FL,RR\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\ndetection.1.corner=RR\n"), std::string::npos) << text;
}

TEST(RunStats, CornerStatsRoundTripThroughAFile) {
  bbw::runtime::CornerRunStats s;
  s.corner = "RL";
  s.incarnation = 1;
  s.samples_published = 12345;
  s.ccu_lost_s = -1.0;
  s.gate_max_force_kN = 40.0;
  const std::string f = temp_file("corner.stats", "");
  bbw::runtime::save(s, f);
  const auto r = bbw::runtime::load_corner_stats(f);
  EXPECT_EQ(bbw::runtime::to_text(r), bbw::runtime::to_text(s));
  EXPECT_EQ(r.samples_published, 12345u);
  fs::remove(f);
}

// The message of the exception `parse` throws ("" when it throws none).
template <class F>
std::string error_of(F&& parse) {
  try {
    parse();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(RunStats, MissingUnknownRepeatedAndMalformedKeysAreErrorsNamingFileAndKey) {
  const std::string text = bbw::runtime::to_text(sample_ccu_stats());
  auto without = [&](const std::string& key) {
    const auto p = text.find("\n" + key + "=");
    EXPECT_NE(p, std::string::npos) << key;
    return text.substr(0, p + 1) + text.substr(text.find('\n', p + 1) + 1);
  };
  auto parse = [](const std::string& t) { return [t] { bbw::runtime::parse_ccu_stats(t, "out/ccu.stats"); }; };
  std::string m = error_of(parse(without("RR.fits_rejected")));
  EXPECT_NE(m.find("out/ccu.stats"), std::string::npos) << m;
  EXPECT_NE(m.find("missing key 'RR.fits_rejected'"), std::string::npos) << m;
  m = error_of(parse(text + "FL.bogus=1\n"));
  EXPECT_NE(m.find("unknown key 'FL.bogus'"), std::string::npos) << m;
  m = error_of(parse(text + "sim_s=2\n"));
  EXPECT_NE(m.find("'sim_s' given twice"), std::string::npos) << m;
  m = error_of(parse(without("wall_s") + "wall_s=fast\n"));
  EXPECT_NE(m.find("'wall_s' is not a number"), std::string::npos) << m;
  m = error_of(parse(without("periods_done") + "periods_done=-3\n"));
  EXPECT_NE(m.find("'periods_done' is not a count"), std::string::npos) << m;
  m = error_of(parse(without("detection.1.part")));
  EXPECT_NE(m.find("missing key 'detection.1.part'"), std::string::npos) << m;
  // A detection beyond the count is unknown.
  m = error_of(parse(text + "detection.2.corner=FL\n"));
  EXPECT_NE(m.find("unknown key 'detection.2.corner'"), std::string::npos) << m;
  m = error_of([] { bbw::runtime::parse_corner_stats("corner=FL\n", "corner_FL.stats"); });
  EXPECT_NE(m.find("corner_FL.stats: missing key 'incarnation'"), std::string::npos) << m;
  m = error_of([] { bbw::runtime::load_corner_stats("/nonexistent/corner_FL.stats"); });
  EXPECT_NE(m.find("/nonexistent/corner_FL.stats"), std::string::npos) << m;
}

}  // namespace

#include "out_dir.hpp"
#include "vehicle_summary.hpp"

// A vehicle run's files (issue 15) are the launcher's own: a new run into the folder replaces them.
TEST(LaunchParts, VehicleRunFilesAreRunOutputs) {
  for (const char* f : {"vehicle.out", "pedal.err", "vehicle_truth.csv", "vehicle.json", "vehicle_plots.gp", "speeds.png",
                        "path.png"}) {
    EXPECT_TRUE(bbw::launch::is_run_output_name(f)) << f;
  }
  EXPECT_FALSE(bbw::launch::is_run_output_name("vehicle_notes.txt"));
}

// bbw_vehicle's vehicle.json becomes summary.json's `vehicle` object.
TEST(LaunchParts, VehicleSummaryIsMergedIntoSummaryJson) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("bbw_vehicle_merge_" + std::to_string(::getpid()))).string();
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/summary.json") << "{\n  \"scenario\": \"x\"\n}\n";
  std::ofstream(dir + "/vehicle.json") << "{\"vehicle\": {\"stopping_distance_m\": 42.5}}";
  bbw::launch::merge_vehicle_summary(dir);
  std::ifstream in(dir + "/summary.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "{\n  \"scenario\": \"x\"\n,\"vehicle\": {\"stopping_distance_m\": 42.5}}\n");
  std::ofstream(dir + "/vehicle.json") << "not json";
  EXPECT_THROW(bbw::launch::merge_vehicle_summary(dir), std::runtime_error);
  std::filesystem::remove_all(dir);
}
