// bbw_intruder: a hostile DDS participant for security system tests (issue 7). It joins a
// domain as one of three intruders and tries, for a bounded time, to command every corner:
//   --as none     no DDS Security at all
//   --as rogue    DIR/rogue/intruder: certificate and documents of a CA bbw never trusted
//   --as corner   a correctly certified corner (--corner FL|FR|RL|RR), whose permissions
//                 do not grant bbw/ClampCommand
// Each command asks for --force-kN on every corner (valid, force mode) so that a run whose
// corners ever apply one is easy to spot. One JSON line on stdout reports what happened:
//   {"as":"rogue","participant":true,"writer":true,"max_matched":0,"written":600}
// SIGINT/SIGTERM end the attempt before --duration-s (the JSON line is still printed).
// Exit 0 when the attempt ran (refusals are results, not errors), 2 on bad usage, 1 otherwise.
//
// --measurements flood|hostile writes measurement blocks instead of commands, as corner
// --corner (its id, in its partition corner_<C>), with the realtime measurement QoS:
//   flood    --rate-x N blocks (5 plausible samples each, continuing seq and time) every 5 ms:
//            N times a corner's rate (docs/security.md, "Flooding")
//   hostile  one malformed block every 5 ms, cycling through: NaN position, infinite load cell,
//            position out of range, load cell out of range, sequence backwards (seq 1),
//            another corner's id, a corner id that does not exist (7)
// The JSON line then also gives "blocks" (written) and, for hostile, "foreign" (blocks with
// another corner's id), "unknown" (id 7) and "bad_samples" (NaN/inf/out of range/backwards).
//
//   bbw_intruder --as none|rogue|corner [--keys DIR] [--corner FL] [--domain N]
//                [--duration-s S] [--force-kN F] [--dds-profiles FILE.xml]
//                [--measurements flood|hostile [--rate-x N]] [--run-id HEX]
//
// --ready-file PATH: created (whole, by a rename) once the attempt is under way: its first command
// to every corner written, or its participant or writer refused. A test waits for it before it
// lets a run end, so that "never commanded a corner" was tried during the run.
//
// --run-id HEX: an intruder that knows a run's id (unsecured, anyone on the domain can read
// the partitions in discovery) writes in that run's partitions and stamps that id on every
// message (issue 17); without it, commands go partition-less and measurements to corner_<C>,
// which no run reads since runs have their own partitions. --stamp-run-id HEX stamps another
// id on the messages while writing in --run-id's partitions (a sample of another run that got
// into this run's partition: receivers must drop and count it).
#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bbw/dds/domain.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/runtime/signals.hpp"
#include "bbw/security/dds_security.hpp"

namespace {

using CommandT = bbw::msg::ClampCommandPubSubType;
using BlockT = bbw::msg::MeasurementBlockPubSubType;

constexpr const char* kUsage =
    "usage: bbw_intruder --as none|rogue|corner [--keys DIR] [--corner FL|FR|RL|RR] [--domain N]\n"
    "                    [--duration-s S] [--force-kN F] [--dds-profiles FILE.xml] [--run-id HEX [--stamp-run-id HEX]]\n"
    "                    [--ready-file PATH] [--measurements flood|hostile [--rate-x N]]\n";

struct Options {
  std::string as;
  std::string keys_dir = "keys";
  std::string corner = "FL";
  std::optional<std::string> domain;
  double duration_s = 3.0;
  double force_kN = 99.0;
  std::string profiles_file;
  std::string measurements;  // "", flood, hostile
  int rate_x = 20;
  std::string ready_file;    // created once the attempt is under way ("": none)
  std::optional<std::uint64_t> run_id;  // --run-id: write in that run's partitions, with its id
  std::optional<std::uint64_t> stamp;   // --stamp-run-id: the id written in the messages instead
  std::uint64_t stamped() const { return stamp.value_or(run_id.value_or(0)); }
};

// What the measurement modes wrote.
struct BlockCounts {
  std::uint64_t blocks = 0, foreign = 0, unknown = 0, bad_samples = 0;
  int max_matched = 0;
};

// One plausible rig sample (passes the CCU's sample guard).
bbw::msg::MeasurementSample plausible(std::uint64_t seq) {
  bbw::msg::MeasurementSample m;
  m.seq(seq);
  m.time_s(static_cast<double>(seq) * 0.001);
  m.position_rev(2.0 + std::sin(static_cast<double>(seq) * 0.01));
  m.speed_rev_per_s(0.5);
  m.force_internal_kN(10.0);
  m.force_external_kN(10.0);
  m.force_true_kN(10.0);
  m.temperature_C(40.0);
  m.motor_current_A(2.0);
  m.command(2.0);
  m.status(0);
  return m;
}

// Writes blocks as corner `corner_id` until `end`: flood (rate_x plausible blocks per 5 ms) or
// hostile (one malformed block per 5 ms, kinds in turn).
BlockCounts write_blocks(bbw::dds::Writer<BlockT>& w, bbw::dds::Events& events, const Options& o,
                         std::uint8_t corner_id, std::chrono::steady_clock::time_point end) {
  BlockCounts n;
  std::uint64_t seq = 0, block = 0, tick_n = 0;
  bbw::msg::MeasurementBlock b;
  auto tick = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < end && !events.interrupted()) {
    const int count = o.measurements == "flood" ? o.rate_x : 1;
    for (int i = 0; i < count; ++i) {
      b.corner_id(corner_id);
      b.run_id(o.stamped());
      b.block_seq(block++);
      b.incarnation(0);
      b.samples().clear();
      for (int k = 0; k < 5; ++k) b.samples().push_back(plausible(++seq));
      bool foreign = false, unknown = false;
      if (o.measurements == "hostile") {
        auto& s0 = b.samples()[0];
        switch (tick_n % 7) {
          case 0: s0.position_rev(std::nan("")); break;
          case 1: s0.force_internal_kN(std::numeric_limits<double>::infinity()); break;
          case 2: s0.position_rev(50.0); break;
          case 3: s0.force_internal_kN(1e6); break;
          case 4: s0.seq(1); s0.time_s(0.001); break;
          case 5: b.corner_id(static_cast<std::uint8_t>((corner_id + 1) % 4)); foreign = true; break;
          default: b.corner_id(7); unknown = true; break;
        }
      }
      b.first_sample_seq(b.samples().front().seq());
      b.period_start_s(b.samples().front().time_s() - 0.001);
      if (w.write(b)) {
        ++n.blocks;
        if (foreign) ++n.foreign;
        else if (unknown) ++n.unknown;
        else if (o.measurements == "hostile") ++n.bad_samples;
      }
    }
    n.max_matched = std::max(n.max_matched, w.matched());
    ++tick_n;
    tick += std::chrono::milliseconds(5);
    events.wait_until(std::min(tick, end), [] { return false; });
  }
  return n;
}

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
    else if (k == "--ready-file") o.ready_file = next();
    else if (k == "--run-id") {
      const std::string v = next();
      o.run_id = bbw::dds::parse_run_id(v);
      if (!o.run_id) throw std::invalid_argument("--run-id must be 1 to 16 hex digits, got '" + v + "'");
    } else if (k == "--stamp-run-id") {
      const std::string v = next();
      o.stamp = bbw::dds::parse_run_id(v);
      if (!o.stamp) throw std::invalid_argument("--stamp-run-id must be 1 to 16 hex digits, got '" + v + "'");
    }
    else if (k == "--measurements") o.measurements = next();
    else if (k == "--rate-x") {
      const double r = parse_positive(next(), "--rate-x");
      if (r != std::floor(r) || r > 1000) throw std::invalid_argument("--rate-x must be an integer in 1..1000");
      o.rate_x = static_cast<int>(r);
    }
    else throw std::invalid_argument("unknown argument '" + k + "'");
  }
  if (o.as != "none" && o.as != "rogue" && o.as != "corner") {
    throw std::invalid_argument("--as must be none, rogue or corner, got '" + o.as + "'");
  }
  if (!o.measurements.empty() && o.measurements != "flood" && o.measurements != "hostile") {
    throw std::invalid_argument("--measurements must be flood or hostile, got '" + o.measurements + "'");
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

// --ready-file: written whole (a temporary file renamed), once. False when it cannot be written.
bool mark_ready(const std::string& file, bool& done) {
  if (file.empty() || done) return true;
  done = true;
  const std::string tmp = file + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  const bool ok = f != nullptr && std::fputs("under way\n", f) >= 0 && std::fclose(f) == 0 &&
                  std::rename(tmp.c_str(), file.c_str()) == 0;
  if (!ok) std::fprintf(stderr, "bbw_intruder: --ready-file %s: cannot write it\n", file.c_str());
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  // SIGINT/SIGTERM end the attempt early, still with its JSON line (tests stop an intruder
  // when the run it attacked is over).
  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });
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
  BlockCounts blocks;
  std::string refused;
  bool ready_done = false, ready_ok = true;
  auto ready = [&] { ready_ok = mark_ready(o.ready_file, ready_done) && ready_ok; };
  try {
    bbw::dds::Participant participant(participant_options(o));
    participant_ok = true;
    // Commands: one writer per corner. With --run-id in each corner's partition of that run
    // (where the CCU writes that corner's commands); without it partition-less.
    std::vector<std::unique_ptr<bbw::dds::Writer<CommandT>>> writers;
    if (!o.measurements.empty()) {
      const std::string id = bbw::security::corner_identity(o.corner);  // validates the corner
      const int corner_id = id == "fl" ? 0 : id == "fr" ? 1 : id == "rl" ? 2 : 3;
      std::unique_ptr<bbw::dds::Writer<BlockT>> bw;
      try {
        bw = std::make_unique<bbw::dds::Writer<BlockT>>(
            participant, bbw::dds::kMeasurementTopic, "measurement_writer_realtime", events,
            bbw::dds::Partition{o.run_id ? bbw::dds::corner_run_partition(bbw::security::corner_partition(corner_id), *o.run_id)
                                         : bbw::security::corner_partition(corner_id)});
        writer_ok = true;
      } catch (const bbw::dds::DdsError& e) {
        refused = e.what();
        ready();  // refused: the attempt is decided
      }
      if (bw) {
        const auto end = std::chrono::steady_clock::now() +
                         std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double>(o.duration_s));
        // Write only once a reader listens (the CCU), within the duration.
        bw->wait_for_matched(1, end - std::chrono::steady_clock::now());
        ready();
        blocks = write_blocks(*bw, events, o, static_cast<std::uint8_t>(corner_id), end);
        max_matched = blocks.max_matched;
        written = blocks.blocks;
        bw->get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
      }
    } else try {
      for (int c = 0; c < 4; ++c) {
        writers.push_back(std::make_unique<bbw::dds::Writer<CommandT>>(
            participant, bbw::dds::kCommandTopic, "command_writer_realtime", events,
            bbw::dds::Partition{o.run_id ? bbw::dds::corner_run_partition(bbw::security::corner_partition(c), *o.run_id)
                                         : std::string()}));
      }
      writer_ok = true;
    } catch (const bbw::dds::DdsError& e) {
      refused = e.what();
      writers.clear();
      ready();  // refused: the attempt is decided
    }
    if (!writers.empty()) {
      // One command per corner every 5 ms until the deadline; waits are timed condition waits.
      const auto start = std::chrono::steady_clock::now();
      const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(o.duration_s));
      auto tick = start;
      std::uint64_t seq = 0;
      while (std::chrono::steady_clock::now() < end && !events.interrupted()) {
        for (std::uint8_t c = 0; c < 4; ++c) {
          bbw::msg::ClampCommand cmd;
          cmd.corner_id(c);
          cmd.run_id(o.stamped());
          cmd.seq(++seq);
          cmd.step(seq);
          cmd.clamp_force_kN(o.force_kN);
          cmd.mode(bbw::msg::MODE_FORCE);
          cmd.valid(true);
          if (writers[c]->write(cmd)) ++written;
        }
        int matched = 0;  // readers reached over all writers (one corner each with --run-id)
        for (const auto& w : writers) matched += w->matched();
        max_matched = std::max(max_matched, matched);
        ready();  // every corner's first command written
        tick += std::chrono::milliseconds(5);
        events.wait_until(std::min(tick, end), [] { return false; });
      }
    }
  } catch (const std::exception& e) {
    if (!participant_ok) {
      refused = e.what();
      ready();  // refused: the attempt is decided
    } else {
      std::cerr << "bbw_intruder: " << e.what() << "\n";
      return 1;
    }
  }
  std::printf("{\"as\":\"%s\",\"participant\":%s,\"writer\":%s,\"max_matched\":%d,\"written\":%llu",
              o.as.c_str(), participant_ok ? "true" : "false", writer_ok ? "true" : "false", max_matched,
              static_cast<unsigned long long>(written));
  if (!o.measurements.empty()) {
    std::printf(",\"blocks\":%llu,\"foreign\":%llu,\"unknown\":%llu,\"bad_samples\":%llu",
                static_cast<unsigned long long>(blocks.blocks), static_cast<unsigned long long>(blocks.foreign),
                static_cast<unsigned long long>(blocks.unknown), static_cast<unsigned long long>(blocks.bad_samples));
  }
  std::printf("}\n");
  if (!refused.empty()) std::fprintf(stderr, "bbw_intruder: refused: %s\n", refused.c_str());
  return ready_ok ? 0 : 1;
}
