#include "bbw/runtime/process_cli.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "bbw/dds/domain.hpp"
#include "bbw/dds/run_id.hpp"

namespace bbw::runtime {

const std::string& ArgCursor::flag() {
  flag_ = argv_[i_++];
  return flag_;
}

std::string ArgCursor::value() {
  if (i_ >= argc_) throw std::invalid_argument("missing value after " + flag_);
  return argv_[i_++];
}

std::chrono::milliseconds seconds_arg(const std::string& flag, const std::string& text, double max_s) {
  char* end = nullptr;
  const double s = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(s > 0.0) || s > max_s) {
    char range[32];
    std::snprintf(range, sizeof range, "%g", max_s);
    throw std::invalid_argument(flag + " must be a number of seconds in (0, " + range + "], got '" + text + "'");
  }
  return std::chrono::milliseconds(static_cast<long long>(s * 1000.0));
}

ClockMode parse_clock_mode(const std::string& text) {
  if (text == "lockstep") return ClockMode::Lockstep;
  if (text == "realtime") return ClockMode::Realtime;
  throw std::invalid_argument("--mode must be lockstep or realtime, got '" + text + "'");
}

bool ProcessFlags::take(const std::string& flag, ArgCursor& args) {
  if (flag == "--scenario") scenario_file = args.value();
  else if (flag == "--domain") domain_arg = args.value();
  else if (flag == "--mode") options.mode = parse_clock_mode(mode_name = args.value());
  else if (flag == "--discovery-timeout") options.discovery_timeout = seconds_arg(flag, args.value());
  else if (flag == "--peer-timeout") options.peer_timeout = seconds_arg(flag, args.value());
  else if (flag == "--dds-profiles") options.participant.profiles_file = args.value();
  else if (flag == "--dds-participant-profile") options.participant.profile = args.value();
  else if (flag == "--secure") secure_dir = args.value();
  else if (flag == "--process-faults") options.process_faults = true;
  else if (flag == "--standby") options.standby = true;
  else if (flag == "--run-id") {
    const std::string text = args.value();
    const auto id = dds::parse_run_id(text);
    if (!id) throw std::invalid_argument("--run-id must be 1 to 16 hex digits, got '" + text + "'");
    options.participant.run_id = *id;
  }
  else return false;
  return true;
}

void ProcessFlags::finish(const char* env_domain) {
  if (scenario_file.empty()) throw std::invalid_argument("--scenario is required");
  options.participant.domain_id = dds::resolve_domain_id(domain_arg, env_domain);
}

std::string process_usage(const std::string& program, const std::string& lead,
                          const std::vector<std::string>& own_lines) {
  const std::string pad(std::string("usage: ").size() + program.size() + 1, ' ');
  std::string text = "usage: " + program + (lead.empty() ? "" : " " + lead) + " --scenario FILE [--domain N] [--mode lockstep|realtime]\n" + pad +
                     "[--discovery-timeout S] [--peer-timeout S] [--process-faults] [--run-id HEX] [--standby]\n" + pad +
                     "[--dds-profiles FILE.xml] [--dds-participant-profile NAME] [--secure KEYS_DIR]\n";
  for (const std::string& line : own_lines) text += pad + line + "\n";
  return text;
}

}  // namespace bbw::runtime
