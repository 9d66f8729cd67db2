// bbw_intruder: a hostile DDS participant for security system tests (issue 7). It joins a
// domain as one of three intruders and tries, for a bounded time, to command every corner:
//   --as none     no DDS Security at all
//   --as rogue    DIR/rogue/intruder: certificate and documents of a CA bbw never trusted
//   --as corner   a correctly certified corner (--corner FL|FR|RL|RR), whose permissions
//                 do not grant bbw/ClampCommand
// Each command asks for --force-kN on every corner (valid, force mode) so that a run whose
// corners ever apply one is easy to spot. One JSON line on stdout reports what happened:
//   {"as":"rogue","participant":true,"writer":true,"max_matched":0,"written":600}
// Exit 0 when the attempt ran (refusals are results, not errors), 2 on bad usage, 1 otherwise.
//
//   bbw_intruder --as none|rogue|corner [--keys DIR] [--corner FL] [--domain N]
//                [--duration-s S] [--force-kN F] [--dds-profiles FILE.xml]
#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "bbw/dds/domain.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/security/dds_security.hpp"

namespace {

using CommandT = bbw::msg::ClampCommandPubSubType;

constexpr const char* kUsage =
    "usage: bbw_intruder --as none|rogue|corner [--keys DIR] [--corner FL|FR|RL|RR] [--domain N]\n"
    "                    [--duration-s S] [--force-kN F] [--dds-profiles FILE.xml]\n";

struct Options {
  std::string as;
  std::string keys_dir = "keys";
  std::string corner = "FL";
  std::optional<std::string> domain;
  double duration_s = 3.0;
  double force_kN = 99.0;
  std::string profiles_file;
};

double parse_positive(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  const double v = std::stod(text, &used);
  if (used != text.size() || !(v > 0.0) || v > 3600.0) {
    throw std::invalid_argument(what + " must be a number in (0, 3600], got '" + text + "'");
  }
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(k + " needs a value");
      return argv[++i];
    };
    if (k == "--as") o.as = next();
    else if (k == "--keys") o.keys_dir = next();
    else if (k == "--corner") o.corner = next();
    else if (k == "--domain") o.domain = next();
    else if (k == "--duration-s") o.duration_s = parse_positive(next(), "--duration-s");
    else if (k == "--force-kN") o.force_kN = parse_positive(next(), "--force-kN");
    else if (k == "--dds-profiles") o.profiles_file = next();
    else throw std::invalid_argument("unknown argument '" + k + "'");
  }
  if (o.as != "none" && o.as != "rogue" && o.as != "corner") {
    throw std::invalid_argument("--as must be none, rogue or corner, got '" + o.as + "'");
  }
  return o;
}

bbw::dds::ParticipantOptions participant_options(const Options& o) {
  bbw::dds::ParticipantOptions p;
  p.domain_id = bbw::dds::resolve_domain_id(o.domain, std::getenv("BBW_DOMAIN"));
  p.profiles_file = o.profiles_file;
  p.name = "bbw_intruder_" + o.as;
  if (o.as == "rogue") {
    bbw::security::SecurityFiles f;
    const std::string dir = o.keys_dir + "/rogue/";
    f.identity_ca = dir + "ca/ca.pem";
    f.identity_cert = dir + "intruder/cert.pem";
    f.private_key = dir + "intruder/key.pem";
    f.permissions_ca = f.identity_ca;
    f.governance = dir + "governance.p7s";
    f.permissions = dir + "intruder/permissions.p7s";
    p.properties = bbw::security::participant_properties(f);
  } else if (o.as == "corner") {
    p.properties = bbw::security::participant_properties(
        bbw::security::files_for(o.keys_dir, bbw::security::corner_identity(o.corner)));
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "bbw_intruder: " << e.what() << "\n" << kUsage;
    return 2;
  }
  bool participant_ok = false;
  bool writer_ok = false;
  int max_matched = 0;
  std::uint64_t written = 0;
  std::string refused;
  try {
    bbw::dds::Events events;
    bbw::dds::Participant participant(participant_options(o));
    participant_ok = true;
    std::unique_ptr<bbw::dds::Writer<CommandT>> writer;
    try {
      writer = std::make_unique<bbw::dds::Writer<CommandT>>(participant, bbw::dds::kCommandTopic,
                                                            "command_writer_realtime", events);
      writer_ok = true;
    } catch (const bbw::dds::DdsError& e) {
      refused = e.what();
    }
    if (writer) {
      // One command per corner every 5 ms until the deadline; waits are timed condition waits.
      const auto start = std::chrono::steady_clock::now();
      const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(o.duration_s));
      auto tick = start;
      std::uint64_t seq = 0;
      while (std::chrono::steady_clock::now() < end) {
        for (std::uint8_t c = 0; c < 4; ++c) {
          bbw::msg::ClampCommand cmd;
          cmd.corner_id(c);
          cmd.seq(++seq);
          cmd.step(seq);
          cmd.clamp_force_kN(o.force_kN);
          cmd.mode(bbw::msg::MODE_FORCE);
          cmd.valid(true);
          if (writer->write(cmd)) ++written;
        }
        max_matched = std::max(max_matched, writer->matched());
        tick += std::chrono::milliseconds(5);
        events.wait_until(std::min(tick, end), [] { return false; });
      }
    }
  } catch (const std::exception& e) {
    if (!participant_ok) {
      refused = e.what();
    } else {
      std::cerr << "bbw_intruder: " << e.what() << "\n";
      return 1;
    }
  }
  std::printf("{\"as\":\"%s\",\"participant\":%s,\"writer\":%s,\"max_matched\":%d,\"written\":%llu}\n",
              o.as.c_str(), participant_ok ? "true" : "false", writer_ok ? "true" : "false", max_matched,
              static_cast<unsigned long long>(written));
  if (!refused.empty()) std::fprintf(stderr, "bbw_intruder: refused: %s\n", refused.c_str());
  return 0;
}
