// The flags bbw_ccu and bbw_corner share (runtime/include/bbw/runtime/process_cli.hpp): each is taken
// with its value, bad values name the flag and the rule, and the domain comes from --domain,
// else BBW_DOMAIN, else 0.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bbw/runtime/process_cli.hpp"

namespace {

using bbw::runtime::ArgCursor;
using bbw::runtime::ClockMode;
using bbw::runtime::ProcessFlags;

// Parses argv (program name first) with the shared flags; returns the flags the parser did not
// know, in order.
std::vector<std::string> parse(ProcessFlags& f, std::vector<std::string> argv) {
  argv.insert(argv.begin(), "prog");
  std::vector<char*> ptrs;
  for (std::string& a : argv) ptrs.push_back(a.data());
  std::vector<std::string> rest;
  for (ArgCursor args(static_cast<int>(ptrs.size()), ptrs.data()); !args.done();) {
    const std::string k = args.flag();
    if (!f.take(k, args)) rest.push_back(k);
  }
  return rest;
}

std::string error_of(std::vector<std::string> argv, const char* env_domain = nullptr) {
  try {
    ProcessFlags f;
    parse(f, std::move(argv));
    f.finish(env_domain);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ProcessCli, TakesEverySharedFlagAndLeavesTheOthers) {
  ProcessFlags f;
  const auto rest = parse(f, {"--corner", "--scenario", "s.yaml", "--domain", "17", "--mode", "realtime",
                              "--discovery-timeout", "2.5", "--peer-timeout", "0.25", "--dds-profiles", "p.xml",
                              "--dds-participant-profile", "bbw_network", "--secure", "keys", "--process-faults",
                              "--out"});
  f.finish("99");
  EXPECT_EQ(rest, (std::vector<std::string>{"--corner", "--out"}));
  EXPECT_EQ(f.scenario_file, "s.yaml");
  EXPECT_EQ(f.options.participant.domain_id, 17);
  EXPECT_EQ(f.options.mode, ClockMode::Realtime);
  EXPECT_EQ(f.mode_name, "realtime");
  EXPECT_EQ(f.options.discovery_timeout.count(), 2500);
  EXPECT_EQ(f.options.peer_timeout.count(), 250);
  EXPECT_EQ(f.options.participant.profiles_file, "p.xml");
  EXPECT_EQ(f.options.participant.profile, "bbw_network");
  EXPECT_EQ(f.secure_dir, "keys");
  EXPECT_TRUE(f.options.process_faults);
}

TEST(ProcessCli, DefaultsAndTheDomainFromTheEnvironment) {
  ProcessFlags f;
  parse(f, {"--scenario", "s.yaml"});
  f.finish("42");
  EXPECT_EQ(f.options.participant.domain_id, 42);
  EXPECT_EQ(f.options.mode, ClockMode::Lockstep);
  EXPECT_EQ(f.options.discovery_timeout.count(), 20000);
  EXPECT_EQ(f.options.peer_timeout.count(), 10000);
  EXPECT_TRUE(f.secure_dir.empty());
  EXPECT_FALSE(f.options.process_faults);
  ProcessFlags g;
  parse(g, {"--scenario", "s.yaml"});
  g.finish(nullptr);
  EXPECT_EQ(g.options.participant.domain_id, 0);
}

TEST(ProcessCli, BadInputNamesTheFlagAndTheRule) {
  EXPECT_EQ(error_of({"--domain", "1"}), "--scenario is required");
  EXPECT_EQ(error_of({"--scenario"}), "missing value after --scenario");
  EXPECT_EQ(error_of({"--scenario", "s", "--mode", "fast"}), "--mode must be lockstep or realtime, got 'fast'");
  EXPECT_EQ(error_of({"--scenario", "s", "--peer-timeout", "0"}),
            "--peer-timeout must be a number of seconds in (0, 3600], got '0'");
  EXPECT_EQ(error_of({"--scenario", "s", "--discovery-timeout", "3601"}),
            "--discovery-timeout must be a number of seconds in (0, 3600], got '3601'");
  EXPECT_EQ(error_of({"--scenario", "s", "--discovery-timeout", "1s"}),
            "--discovery-timeout must be a number of seconds in (0, 3600], got '1s'");
  EXPECT_NE(error_of({"--scenario", "s", "--domain", "233"}).find("--domain"), std::string::npos);
  EXPECT_NE(error_of({"--scenario", "s"}, "x").find("BBW_DOMAIN"), std::string::npos);
}

TEST(ProcessCli, UsageListsTheSharedFlagsThenTheProgramsOwn) {
  const std::string u = bbw::runtime::process_usage("bbw_corner", "--corner FL|FR|RL|RR", {"[--stats FILE]"});
  EXPECT_EQ(u.rfind("usage: bbw_corner --corner FL|FR|RL|RR --scenario FILE", 0), 0u) << u;
  for (const char* flag : {"--domain", "--mode", "--discovery-timeout", "--peer-timeout", "--process-faults",
                           "--dds-profiles", "--dds-participant-profile", "--secure", "--stats"}) {
    EXPECT_NE(u.find(flag), std::string::npos) << flag;
  }
  EXPECT_NE(u.find("\n                  [--stats FILE]\n"), std::string::npos) << u;
}

}  // namespace
