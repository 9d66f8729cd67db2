// Corner -> CCU -> corner round trip over the default transport (profile bbw_localhost:
// SHM + UDPv4 on 127.0.0.1, data-sharing left to Fast DDS) with the real message types and
// QoS profiles: this process plays a corner and publishes a MeasurementBlock of 5 samples
// (one 5 ms CCU period at 1 kHz); a separate bbw_dds_echo process plays the CCU and answers
// with a ClampCommand for that corner; the corner receives it through its content filter.
//
// The block is written in partition corner_FL and read in corner_* (as in the system since
// issue 7). The *Secure variants run both participants with DDS Security (corner FL's and the
// CCU's identities: authentication, access control, AES-GCM on every sample; keys from env
// BBW_BENCH_KEYS, default keys/ in the repository, created by scripts/bbw-keys.sh if missing).
//
// Reports p50/p99/max of the round-trip time in microseconds as counters.
// Domain: env BBW_BENCH_DOMAIN (default 201).
#include <benchmark/benchmark.h>
#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/runtime/child.hpp"
#include "bbw/security/dds_security.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

int bench_domain() {
  const char* env = std::getenv("BBW_BENCH_DOMAIN");
  return env ? std::atoi(env) : 201;
}

// The keys directory for the secure variants ("" and an error when it cannot be made).
std::string bench_keys(std::string& error) {
  const char* env = std::getenv("BBW_BENCH_KEYS");
  const std::string dir = env && *env ? env : std::string(BBW_SOURCE_DIR) + "/keys";
  try {
    for (const auto& id : bbw::security::identities()) bbw::security::files_for(dir, id);
    return dir;
  } catch (const bbw::security::SecurityError&) {
  }
  const std::string log = std::filesystem::temp_directory_path() / "bbw_bench_keys";
  bbw::runtime::Child keys("bbw-keys.sh", {std::string(BBW_SOURCE_DIR) + "/scripts/bbw-keys.sh", dir}, log + ".out",
                          log + ".err");
  const auto st = keys.wait_until(Clock::now() + 120s);
  if (!st || !st->ok()) {
    error = "scripts/bbw-keys.sh " + dir + " failed (see " + log + ".err)";
    return "";
  }
  return dir;
}

void roundtrip(benchmark::State& state, bool lockstep_profiles, bool secure) {
  const int domain = bench_domain();
  const std::string mode = lockstep_profiles ? "lockstep" : "realtime";
  const std::string log_dir = std::filesystem::temp_directory_path() / "bbw_bench_dds";
  std::filesystem::create_directories(log_dir);
  std::string keys_error;
  const std::string keys = secure ? bench_keys(keys_error) : "";
  if (secure && keys.empty()) {
    state.SkipWithError(keys_error.c_str());
    return;
  }
  std::vector<std::string> echo_argv{bbw::runtime::executable_dir() + "/bbw_dds_echo", "--domain",
                                     std::to_string(domain), "--mode", mode, "--partition", "corner_*"};
  if (secure) echo_argv.insert(echo_argv.end(), {"--secure", keys});
  bbw::runtime::Child echo("bbw_dds_echo", echo_argv, log_dir + "/echo.out", log_dir + "/echo.err");
  bbw::dds::Events events;
  bbw::dds::ParticipantOptions opt;
  opt.domain_id = domain;
  opt.name = "bench_corner_FL";
  if (secure) {
    opt.properties = bbw::security::participant_properties(
        bbw::security::files_for(keys, bbw::security::corner_identity("FL")));
  }
  bbw::dds::Participant participant(opt);
  const auto profiles = bbw::dds::profiles_for(lockstep_profiles);
  bbw::dds::Writer<bbw::msg::MeasurementBlockPubSubType> blocks(
      participant, bbw::dds::kMeasurementTopic, profiles.measurement_writer, events,
      bbw::dds::Partition{bbw::security::corner_partition("FL")});
  const bbw::dds::ContentFilter filter{"ClampCommand_FL", "corner_id = %0", {"0"}};
  bbw::dds::Reader<bbw::msg::ClampCommandPubSubType> commands(
      participant, bbw::dds::kCommandTopic, profiles.command_reader, events, &filter);
  if (!blocks.wait_for_matched(1, 10s) || !commands.wait_for_matched(1, 10s)) {
    state.SkipWithError("echo peer not discovered within 10 s");
    return;
  }

  bbw::msg::MeasurementBlock block;
  block.corner_id(0);
  block.samples().resize(5);
  bbw::msg::ClampCommand reply;
  std::vector<double> rtt_us;
  rtt_us.reserve(1 << 16);
  std::uint64_t seq = 0;
  // Warm-up: the first exchanges also complete reliable-writer handshakes.
  for (int i = 0; i < 50; ++i) {
    block.block_seq(seq);
    blocks.write(block);
    const std::uint64_t want = seq++;
    if (!events.wait_for(5s, [&] {
          while (commands.take(reply)) if (reply.step() == want) return true;
          return false;
        })) {
      state.SkipWithError("warm-up reply lost");
      return;
    }
  }
  for (auto _ : state) {
    block.block_seq(seq);
    for (std::size_t i = 0; i < 5; ++i) block.samples()[i].seq(seq * 5 + i);
    const std::uint64_t want = seq++;
    bool got = false;
    const auto t0 = Clock::now();
    blocks.write(block);
    events.wait_for(5s, [&] {
      while (commands.take(reply)) got = got || reply.step() == want;
      return got;
    });
    const auto t1 = Clock::now();
    if (!got) {
      state.SkipWithError("reply not received within 5 s");
      break;
    }
    const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
    rtt_us.push_back(us);
    state.SetIterationTime(us * 1e-6);
  }
  echo.stop(2000ms);
  if (rtt_us.empty()) return;
  std::sort(rtt_us.begin(), rtt_us.end());
  auto pct = [&](double p) {
    const auto i = static_cast<std::size_t>(p * static_cast<double>(rtt_us.size() - 1));
    return rtt_us[i];
  };
  state.counters["p50_us"] = pct(0.50);
  state.counters["p99_us"] = pct(0.99);
  state.counters["max_us"] = rtt_us.back();
  state.counters["samples"] = static_cast<double>(rtt_us.size());
}

void BM_RoundTripRealtimeProfiles(benchmark::State& state) { roundtrip(state, false, false); }
void BM_RoundTripLockstepProfiles(benchmark::State& state) { roundtrip(state, true, false); }
void BM_RoundTripRealtimeProfilesSecure(benchmark::State& state) { roundtrip(state, false, true); }
void BM_RoundTripLockstepProfilesSecure(benchmark::State& state) { roundtrip(state, true, true); }

}  // namespace

BENCHMARK(BM_RoundTripRealtimeProfiles)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(5000);
BENCHMARK(BM_RoundTripLockstepProfiles)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(5000);
BENCHMARK(BM_RoundTripRealtimeProfilesSecure)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(5000);
BENCHMARK(BM_RoundTripLockstepProfilesSecure)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(5000);
