// bbw_pedal: the instrumented brake pedal over Fast DDS (issue 15, docs/vehicle.md): the driver's
// travel profile read by a travel and a force sensor (vehicle_run::PedalNode). A lockstep
// participant of the CCU's barrier that publishes PedalSample k (in PedalSamples messages of
// consecutive periods) in the run's partition. It starts
// on the CCU's first grant (its command for the front-left corner, read in that corner's partition
// of the run, then no longer read); after it, the pedal (open loop) runs ahead of the barrier, paced
// by the vehicle's CaliperTemperatures (vehicle_run::pedal_sample_allowed).
//
//   bbw_pedal --scenario VEHICLE_SCENARIO.yaml [--domain N] [--run-id HEX] [--discovery-timeout S]
//             [--peer-timeout S] [--dds-profiles FILE.xml] [--dds-participant-profile NAME]
//
// Lockstep only. Exit: 0 done, 1 runtime or DDS error, 2 bad arguments or config, 3 peers not
// discovered in time, 4 the CCU's first grant or the vehicle's pace not in time.
#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <bbw/idl/bbw_vehicle_msgsPubSubTypes.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <memory>
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
        grants_(std::make_unique<GrantInlet>(
            participant_, dds::kCommandTopic, dds::profiles_for(true).command_reader, events,
            dds::Partition{dds::corner_run_partition(security::corner_partition(0), o.participant.run_id)})),
        pace_(participant_, dds::kCaliperTemperatureTopic, dds::profiles_for(true).measurement_reader, events,
              dds::Partition{dds::run_partition(o.participant.run_id)}) {
    node_.set_run_id(o.participant.run_id);
    batch_.run_id(o.participant.run_id);
    batch_.samples().reserve(msg::PEDAL_SAMPLES_MAX);
  }

  int run(std::string& error) {
    const bool found = events_.wait_for(options_.discovery_timeout, [&] {
      return samples_.peers() >= 1 && grants_->peers() >= 1 && pace_.peers() >= 1;
    });
    if (!found) {
      if (events_.interrupted()) return kExitOk;
      error = "CCU and vehicle not discovered within " + std::to_string(options_.discovery_timeout.count()) + " ms";
      return kExitDiscovery;
    }
    periods_ = node::periods_of(scenario_.corners.scenario);
    // The CCU's first grant: every participant of the run has been discovered (the CCU waits for
    // them before it), so no early sample is lost on a reader not yet matched. Then the command
    // reader goes: the front-left commands reach the corner alone.
    const bool granted = events_.wait_for(options_.peer_timeout, [&] { return take_first_grant(); });
    if (!granted) {
      if (events_.interrupted()) return kExitOk;
      error = "no grant for period 0 within " + std::to_string(options_.peer_timeout.count()) + " ms";
      return kExitPeerLost;
    }
    grants_.reset();
    if (stopped_) return kExitOk;
    // The samples go out on the thread that receives the vehicle's pace (bbw/dds/receive_runner.hpp)
    // until the end or a stall; then on this loop.
    std::uint64_t k_from = 0;
    if (dds::lockstep_on_receive()) {
      const auto end = dds::run_on_receive(events_, [this] { return advance_on_receive(); }, [this] { return periods_done_; });
      if (send_failed_) {
        error = "PedalSamples write failed at period " + std::to_string(periods_done_);
        return kExitRuntime;
      }
      k_from = end == dds::ReceiveRunEnd::Interrupted ? periods_ : periods_done_;
    }
    runtime::LockstepClock period_clock(events_, options_.peer_timeout);
    period_clock.start(k_from);
    while (periods_done_ < periods_ && k_from < periods_ && !events_.interrupted()) {
      const std::uint64_t k = periods_done_;
      // Lockstep only: the clock policy of bbw/runtime/period_clock.hpp.
      const runtime::PeriodStart begun = period_clock.begin(k, [&] { return paced(k); });
      if (begun == runtime::PeriodStart::Interrupted) break;
      if (begun == runtime::PeriodStart::TimedOut) {
        error = "the vehicle's pace for period " + std::to_string(k) + " (its CaliperTemperatures of period " +
                std::to_string(static_cast<std::int64_t>(k) - static_cast<std::int64_t>(vehicle_run::kPedalLeadPeriods)) +
                ") not in within " + std::to_string(options_.peer_timeout.count()) + " ms";
        return kExitPeerLost;
      }
      if (!send_allowed()) {
        error = "PedalSamples write failed at period " + std::to_string(periods_done_);
        return kExitRuntime;
      }
    }
    samples_.get().get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
    return kExitOk;
  }
  std::uint64_t periods_done() const { return periods_done_; }

 private:
  using GrantInlet = dds::DdsInlet<msg::ClampCommandPubSubType>;

  // Takes the front-left commands; true once the CCU has granted a period (or stopped the run).
  bool take_first_grant() {
    while (grants_->take(command_)) {
      if (command_.run_id() != options_.participant.run_id || command_.corner_id() != 0) continue;
      if (command_.stop()) stopped_ = true;
      else granted_ = true;
    }
    return granted_ || stopped_;
  }

  // Takes the vehicle's CaliperTemperatures; true when sample k may go out.
  bool paced(std::uint64_t k) {
    while (pace_.take(temperatures_)) {
      if (temperatures_.run_id() != options_.participant.run_id) continue;
      vehicle_done_ = std::max(vehicle_done_, temperatures_.step() + 1);
    }
    return vehicle_run::pedal_sample_allowed(k, vehicle_done_);
  }

  // Publishes every sample the pace allows, PEDAL_SAMPLES_MAX to a message; false when a write failed.
  bool send_allowed() {
    // The period's end, computed as the CCU does (k T, then + T).
    const double T = scenario_.corners.scenario.ccu_period_s;
    while (periods_done_ < periods_ && vehicle_run::pedal_sample_allowed(periods_done_, vehicle_done_)) {
      batch_.samples().clear();
      for (std::uint64_t k = periods_done_; k < periods_ && batch_.samples().size() < msg::PEDAL_SAMPLES_MAX &&
                                            vehicle_run::pedal_sample_allowed(k, vehicle_done_);
           ++k) {
        batch_.samples().push_back(node_.sample(k, static_cast<double>(k) * T + T));
      }
      if (!samples_.send(batch_)) return false;
      periods_done_ += batch_.samples().size();
    }
    return true;
  }

  // Every sample the vehicle's pace allows; true when run()'s loop must carry on (the end, a failed write).
  bool advance_on_receive() {
    if (periods_done_ >= periods_ || events_.interrupted()) return true;
    if (!paced(periods_done_)) return false;
    if (!send_allowed()) {
      send_failed_ = true;
      return true;
    }
    return periods_done_ >= periods_;
  }

  const vehicle_run::VehicleScenario& scenario_;
  runtime::ProcessOptions options_;
  dds::Events& events_;
  vehicle_run::PedalNode node_;
  dds::Participant participant_;
  dds::DdsOutlet<msg::PedalSamplesPubSubType> samples_;
  msg::PedalSamples batch_;
  std::unique_ptr<GrantInlet> grants_;  // until the first grant
  dds::DdsInlet<msg::CaliperTemperaturesPubSubType> pace_;
  msg::ClampCommand command_;
  msg::CaliperTemperatures temperatures_;
  bool granted_ = false;
  bool stopped_ = false;
  std::uint64_t vehicle_done_ = 0;  // periods the vehicle has ended, from its CaliperTemperatures
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
