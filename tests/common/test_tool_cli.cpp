// The command line bbw_inproc, bbw_vehicle_inproc and bbw_loop_check share (tools/cli): the
// shared flags, the tool's own through its callback, and every way to get it wrong.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bbw/tool_cli/tool_cli.hpp"

namespace {

struct Argv {
  explicit Argv(std::vector<std::string> a) : args(std::move(a)) {
    for (auto& s : args) ptrs.push_back(s.data());
  }
  int argc() const { return static_cast<int>(ptrs.size()); }
  char** argv() { return ptrs.data(); }
  std::vector<std::string> args;
  std::vector<char*> ptrs;
};

// A tool with one own flag taking a value (--out) and one without (--fast); --level must be 1-3.
struct Tool {
  std::string out;
  bool fast = false;
  int level = 1;
  bbw::tool_cli::ModelArgs args;
  std::optional<int> parse(std::vector<std::string> a) {
    a.insert(a.begin(), "bbw_tool");
    Argv v(a);
    return bbw::tool_cli::parse(v.argc(), v.argv(), "bbw_tool", "usage: bbw_tool ...\n", args,
                                [&](const std::string& f, const auto& value) {
                                  if (f == "--out") out = value();
                                  else if (f == "--fast") fast = true;
                                  else if (f == "--level") {
                                    level = std::stoi(value());
                                    if (level < 1 || level > 3) throw std::invalid_argument("--level must be 1-3");
                                  } else return false;
                                  return true;
                                });
  }
};

}  // namespace

TEST(ToolCli, TakesTheSharedFlagsTheToolsOwnAndOneScenario) {
  Tool t;
  EXPECT_FALSE(t.parse({"--calibrator", "c.yaml", "s.yaml", "--out", "o", "--fast", "--monitor", "m.yaml"}).has_value());
  EXPECT_EQ(t.args.scenario, "s.yaml");
  EXPECT_EQ(t.args.calibrator, "c.yaml");
  EXPECT_EQ(t.args.monitor, "m.yaml");
  EXPECT_EQ(t.out, "o");
  EXPECT_TRUE(t.fast);
}

// What a mistaken command line prints (its exit code must be 2).
std::string error_of(const std::vector<std::string>& a) {
  testing::internal::CaptureStderr();
  const auto code = Tool().parse(a);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 2) << err;
  return err;
}

TEST(ToolCli, HelpStopsWithZeroAndEveryMistakeWithTwo) {
  EXPECT_EQ(Tool().parse({"--help"}), 0);
  EXPECT_EQ(Tool().parse({"s.yaml", "-h"}), 0);
  const std::pair<std::vector<std::string>, std::string> cases[] = {
      {{}, "bbw_tool: a scenario file is required\nusage: bbw_tool ...\n"},
      {{"s.yaml", "--bogus"}, "bbw_tool: unknown argument '--bogus'\n"},
      {{"s.yaml", "t.yaml"}, "bbw_tool: one scenario only, got 't.yaml' too\n"},
      {{"s.yaml", "--out"}, "bbw_tool: --out needs a value\n"},
      {{"s.yaml", "--calibrator"}, "bbw_tool: --calibrator needs a value\n"},
      {{"s.yaml", "--level", "7"}, "bbw_tool: --level must be 1-3\nusage: bbw_tool ...\n"},
  };
  for (const auto& [args, message] : cases) {
    const std::string err = error_of(args);
    EXPECT_NE(err.find(message), std::string::npos) << err;
  }
}

TEST(ToolCli, LoadsTheShippedModelsWhenNoneIsNamedAndNamesAMissingFile) {
  bbw::tool_cli::ModelArgs a;
  EXPECT_NO_THROW(bbw::tool_cli::load_calibrator(a));
  EXPECT_NO_THROW(bbw::tool_cli::load_monitor(a));
  a.calibrator = "/nonexistent/calibrator.yaml";
  try {
    bbw::tool_cli::load_calibrator(a);
    FAIL() << "a missing calibrator file was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/calibrator.yaml"), std::string::npos) << e.what();
  }
}
