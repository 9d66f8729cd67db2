// What bbw_ccu and bbw_corner share on their command lines and in their exit statuses
// (docs/distributed.md): the clock mode, the scenario, the domain, the DDS profile, the
// discovery and peer timeouts, DDS Security keys and the launcher's --process-faults.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "bbw/dds/participant.hpp"

namespace bbw::runtime {

enum class ClockMode { Lockstep, Realtime };

// Exit statuses of both processes.
enum ExitCode : int {
  kExitOk = 0,
  kExitRuntime = 1,    // a runtime or DDS error
  kExitUsage = 2,      // bad arguments or config
  kExitDiscovery = 3,  // peers not discovered in time
  kExitPeerLost = 4,   // a peer lost or failed
};

// Walks argv: flag() returns the next argument, value() the one after it (throws
// std::invalid_argument "missing value after FLAG" at the end).
class ArgCursor {
 public:
  ArgCursor(int argc, char** argv) : argc_(argc), argv_(argv) {}
  bool done() const { return i_ >= argc_; }
  const std::string& flag();
  std::string value();

 private:
  int argc_;
  char** argv_;
  int i_ = 1;
  std::string flag_;
};

// "--flag S": seconds in (0, max_s], as milliseconds; throws naming the flag and the rule.
std::chrono::milliseconds seconds_arg(const std::string& flag, const std::string& text, double max_s = 3600.0);

// "lockstep" or "realtime"; throws naming --mode otherwise.
ClockMode parse_clock_mode(const std::string& text);

// The options both processes run with (CcuOptions and CornerOptions extend them).
struct ProcessOptions {
  ClockMode mode = ClockMode::Lockstep;
  dds::ParticipantOptions participant;
  std::chrono::milliseconds discovery_timeout{20000};
  // Lockstep: the longest wait for the peer's next block (CCU) or command (corner).
  std::chrono::milliseconds peer_timeout{10000};
  // Process faults of the schedule are carried out (bbw_launch runs the process and kills it).
  bool process_faults = false;
  // The run has a hot-standby CCU (--standby, issue 16): commands under DDS exclusive ownership
  // (profiles *_owned), and the corners accept the two CCUs' command writers.
  bool standby = false;
};

// The flags both processes take. take() consumes one of them from the cursor; finish() checks
// what must hold once all are read (--scenario given) and resolves the domain id (--domain,
// else env BBW_DOMAIN, else 0) into options.participant.
struct ProcessFlags {
  std::string scenario_file;
  std::string mode_name = "lockstep";
  std::optional<std::string> domain_arg;
  std::string secure_dir;  // "" without DDS Security
  ProcessOptions options;

  // true when `flag` is one of the shared flags (its value, if any, taken from `args`).
  bool take(const std::string& flag, ArgCursor& args);
  void finish(const char* env_domain);
};

// "usage: PROGRAM LEAD" with the shared flags, then `own_lines` (the program's own flags) under them.
std::string process_usage(const std::string& program, const std::string& lead,
                          const std::vector<std::string>& own_lines);

}  // namespace bbw::runtime
