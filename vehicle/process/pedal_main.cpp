// bbw_pedal: the instrumented brake pedal over Fast DDS (issue 15, docs/vehicle.md): the driver's
// travel profile read by a travel and a force sensor (vehicle_run::PedalNode). A lockstep
// participant of the CCU's barrier: on the CCU's grant of period k (its command for the front-left
// corner, read in that corner's partition of the run) it publishes PedalSample k in the run's
// partition.
//
//   bbw_pedal --scenario VEHICLE_SCENARIO.yaml [--domain N] [--run-id HEX] [--discovery-timeout S]
//             [--peer-timeout S] [--dds-profiles FILE.xml] [--dds-participant-profile NAME]
//
// Lockstep only. Exit: 0 done, 1 runtime or DDS error, 2 bad arguments or config, 3 peers not
// discovered in time, 4 the CCU lost (no grant in time).
#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <bbw/idl/bbw_vehicle_msgsPubSubTypes.h>

#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/ports.hpp"
#include "bbw/dds/receive_runner.hpp"
#include "bbw/dds/run_id.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/node/corner_node.hpp"
#include "bbw/runtime/period_clock.hpp"
#include "bbw/runtime/process_cli.hpp"
#include "bbw/runtime/signals.hpp"
#include "bbw/security/dds_security.hpp"
#include "bbw/vehicle_run/vehicle_nodes.hpp"

namespace bbw::pedal_process {

namespace {
using runtime::kExitDiscovery;
using runtime::kExitOk;
using runtime::kExitPeerLost;
using runtime::kExitRuntime;
using runtime::kExitUsage;

class PedalApp {
 public:
  PedalApp(const vehicle_run::VehicleScenario& s, const runtime::ProcessOptions& o, dds::Events& events)
      : scenario_(s),
        options_(o),
        events_(events),
        node_(s),
        participant_([&] {
          dds::ParticipantOptions p = o.participant;
          if (p.name.empty()) p.name = "bbw_pedal";
          return p;
        }()),
        samples_(participant_, dds::kPedalTopic, dds::profiles_for(true).measurement_writer, events,
                 dds::Partition{dds::run_partition(o.participant.run_id)}),
        grants_(participant_, dds::kCommandTopic, dds::profiles_for(true).command_reader, events,
                dds::Partition{dds::corner_run_partition(security::corner_partition(0), o.participant.run_id)}) {
    node_.set_run_id(o.participant.run_id);
  }

  int run(std::string& error) {
    const bool found = events_.wait_for(options_.discovery_timeout, [&] { return samples_.peers() >= 1 && grants_.peers() >= 1; });
    if (!found) {
      if (events_.interrupted()) return kExitOk;
      error = "CCU not discovered within " + std::to_string(options_.discovery_timeout.count()) + " ms";
      return kExitDiscovery;
    }
    periods_ = node::periods_of(scenario_.corners.scenario);
    // The samples go out on the thread that receives their grant (bbw/dds/receive_runner.hpp)
    // until the end, a stop or a stall; then on this loop.
    std::uint64_t k_from = 0;
    if (dds::lockstep_on_receive()) {
      const auto end = dds::run_on_receive(events_, [this] { return advance_on_receive(); }, [this] { return periods_done_; });
      if (send_failed_) {
        error = "PedalSample write failed at period " + std::to_string(periods_done_);
        return kExitRuntime;
      }
      k_from = end == dds::ReceiveRunEnd::Interrupted || stopped_ ? periods_ : periods_done_;
    }
    runtime::LockstepClock period_clock(events_, options_.peer_timeout);
    period_clock.start(k_from);
    for (std::uint64_t k = k_from; k < periods_ && !events_.interrupted(); ++k) {
      // Lockstep only: the clock policy of bbw/runtime/period_clock.hpp.
      const runtime::PeriodStart begun = period_clock.begin(k, [&] { return take_grants(k); });
      if (begun == runtime::PeriodStart::Interrupted) break;
      if (begun == runtime::PeriodStart::TimedOut) {
        error = "no grant for period " + std::to_string(k) + " within " + std::to_string(options_.peer_timeout.count()) + " ms";
        return kExitPeerLost;
      }
      if (stopped_) break;
      if (!send_sample(k)) {
        error = "PedalSample write failed at period " + std::to_string(k);
        return kExitRuntime;
      }
    }
    samples_.get().get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
    return kExitOk;
  }
  std::uint64_t periods_done() const { return periods_done_; }

 private:
  // Takes the grants (the front-left commands); true when period k is granted or the run stopped.
  bool take_grants(std::uint64_t k) {
    while (grants_.take(command_)) {
      if (command_.run_id() != options_.participant.run_id || command_.corner_id() != 0) continue;
      if (command_.stop()) stopped_ = true;
      else granted_ = std::max(granted_, static_cast<std::int64_t>(command_.step()));
    }
    return stopped_ || granted_ >= static_cast<std::int64_t>(k);
  }

  // Publishes period k's sample; false when the write failed.
  bool send_sample(std::uint64_t k) {
    // The period's end, computed as the CCU does (k T, then + T).
    const double T = scenario_.corners.scenario.ccu_period_s;
    const double t_end = static_cast<double>(k) * T + T;
    if (!samples_.send(node_.sample(k, t_end))) return false;
    periods_done_ = k + 1;
    return true;
  }

  // Every granted period's sample; true when run()'s loop must carry on (the end, a stop, a failed write).
  bool advance_on_receive() {
    for (;;) {
      const std::uint64_t k = periods_done_;
      if (k >= periods_ || events_.interrupted()) return true;
      if (!take_grants(k)) return false;
      if (stopped_) return true;
      if (!send_sample(k)) {
        send_failed_ = true;
        return true;
      }
    }
  }

  const vehicle_run::VehicleScenario& scenario_;
  runtime::ProcessOptions options_;
  dds::Events& events_;
  vehicle_run::PedalNode node_;
  dds::Participant participant_;
  dds::DdsOutlet<msg::PedalSamplePubSubType> samples_;
  dds::DdsInlet<msg::ClampCommandPubSubType> grants_;
  msg::ClampCommand command_;
  std::int64_t granted_ = -1;
  bool stopped_ = false;
  std::uint64_t periods_ = 0;
  bool send_failed_ = false;
  std::uint64_t periods_done_ = 0;
};

std::string usage() { return runtime::process_usage("bbw_pedal", "", {}); }

}  // namespace
}  // namespace bbw::pedal_process

int main(int argc, char** argv) {
  using namespace bbw::pedal_process;

  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });
  bbw::runtime::ProcessFlags flags;
  try {
    for (bbw::runtime::ArgCursor args(argc, argv); !args.done();) {
      const std::string k = args.flag();
      if (flags.take(k, args)) continue;
      if (k == "-h" || k == "--help") { std::cout << usage(); return 0; }
      throw std::invalid_argument("unknown argument '" + k + "'");
    }
    flags.finish(std::getenv("BBW_DOMAIN"));
    if (flags.options.mode != bbw::runtime::ClockMode::Lockstep) throw std::invalid_argument("bbw_pedal runs in lockstep only");
    if (!flags.secure_dir.empty()) throw std::invalid_argument("--secure is not supported for vehicle runs yet");
  } catch (const std::exception& e) {
    std::cerr << "bbw_pedal: " << e.what() << "\n" << usage();
    return kExitUsage;
  }
  std::optional<bbw::vehicle_run::VehicleScenario> scenario;
  try {
    scenario = bbw::vehicle_run::load_vehicle_scenario(flags.scenario_file);
  } catch (const std::exception& e) {
    std::cerr << "bbw_pedal: " << e.what() << "\n";
    return kExitUsage;
  }
  std::string error;
  int rc = kExitOk;
  try {
    PedalApp app(*scenario, flags.options, events);
    rc = app.run(error);
    std::cout << "bbw_pedal: " << app.periods_done() << " periods" << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "bbw_pedal: " << e.what() << "\n";
    return kExitRuntime;
  }
  if (rc != kExitOk) {
    std::cerr << "bbw_pedal: " << error << "\n";
    return rc;
  }
  if (const int sig = signals.received(); sig != 0) return 128 + sig;
  return kExitOk;
}
