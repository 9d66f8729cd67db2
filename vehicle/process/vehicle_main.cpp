// bbw_vehicle: the vehicle around the brakes over Fast DDS (issue 15, docs/vehicle.md): chassis,
// wheels, tyres, road, brake discs, the toothed-wheel sensors, the IMU and the driver
// (vehicle_run::VehicleNode). A lockstep participant of the CCU's barrier: for each CCU period k
// it takes every corner's measurement block k (their true clamp forces, one per plant step, in
// each corner's partition of the run), simulates the period and publishes VehicleSensors k in
// the run's partition. At the end: OUT/vehicle_truth.csv and OUT/vehicle.json.
//
//   bbw_vehicle --scenario VEHICLE_SCENARIO.yaml --out DIR [--no-plots] [--domain N] [--run-id HEX]
//               [--discovery-timeout S] [--peer-timeout S] [--dds-profiles FILE.xml]
//               [--dds-participant-profile NAME]
//
// Lockstep only. Exit: 0 done, 1 runtime or DDS error, 2 bad arguments or config, 3 peers not
// discovered in time, 4 a peer lost (no block in time).
#include <bbw/idl/bbw_msgsPubSubTypes.h>
#include <bbw/idl/bbw_vehicle_msgsPubSubTypes.h>

#include <array>
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
#include "bbw/vehicle_run/metrics.hpp"
#include "bbw/vehicle_run/vehicle_nodes.hpp"

namespace bbw::vehicle_process {

namespace {
using runtime::kExitDiscovery;
using runtime::kExitOk;
using runtime::kExitPeerLost;
using runtime::kExitRuntime;
using runtime::kExitUsage;

class VehicleApp {
 public:
  VehicleApp(const vehicle_run::VehicleScenario& s, const runtime::ProcessOptions& o, dds::Events& events)
      : scenario_(s),
        options_(o),
        events_(events),
        node_(s),
        participant_([&] {
          dds::ParticipantOptions p = o.participant;
          if (p.name.empty()) p.name = "bbw_vehicle";
          return p;
        }()),
        sensors_(participant_, dds::kVehicleSensorsTopic, dds::profiles_for(true).measurement_writer, events,
                 dds::Partition{dds::run_partition(o.participant.run_id)}),
        temperatures_(participant_, dds::kCaliperTemperatureTopic, dds::profiles_for(true).measurement_writer, events,
                      dds::Partition{dds::run_partition(o.participant.run_id)}) {
    node_.set_run_id(o.participant.run_id);
    for (std::size_t slot = 0; slot < 4; ++slot) {
      blocks_[slot] = std::make_unique<BlockInlet>(
          participant_, dds::kMeasurementTopic, dds::profiles_for(true).measurement_reader, events,
          dds::Partition{dds::corner_run_partition(security::corner_partition(static_cast<int>(slot)), o.participant.run_id)});
    }
    block_.samples().reserve(msg::MAX_BLOCK_SAMPLES);
  }

  int run(std::string& error) {
    // Peers: every corner's block writer, our sensors' reader (the CCU) and our temperatures'
    // readers (the four corners).
    const bool found = events_.wait_for(options_.discovery_timeout, [&] {
      bool all = sensors_.peers() >= 1 && temperatures_.peers() >= 4;
      for (const auto& b : blocks_) all = all && b->peers() >= 1;
      return all;
    });
    if (!found) {
      if (events_.interrupted()) return kExitOk;
      error = "CCU and corners not discovered within " + std::to_string(options_.discovery_timeout.count()) +
              " ms (sensor readers matched " + std::to_string(sensors_.peers()) + " of 1, temperature readers " +
              std::to_string(temperatures_.peers()) + " of 4)";
      return kExitDiscovery;
    }
    periods_ = node::periods_of(scenario_.corners.scenario);
    n_ = static_cast<std::size_t>(node::steps_per_period(scenario_.corners.scenario));
    // The periods run on the thread that receives their last block (bbw/dds/receive_runner.hpp)
    // until the end or a stall; then on this loop.
    std::uint64_t k_from = 0;
    if (dds::lockstep_on_receive()) {
      const auto end = dds::run_on_receive(events_, [this] { return advance_on_receive(); }, [this] { return periods_done_; });
      if (send_failed_) {
        error = "VehicleSensors or CaliperTemperatures write failed at period " + std::to_string(periods_done_);
        return kExitRuntime;
      }
      k_from = end == dds::ReceiveRunEnd::Interrupted ? periods_ : periods_done_;
    }
    runtime::LockstepClock period_clock(events_, options_.peer_timeout);
    period_clock.start(k_from);
    for (std::uint64_t k = k_from; k < periods_ && !events_.interrupted(); ++k) {
      // Lockstep only: the clock policy of bbw/runtime/period_clock.hpp.
      const runtime::PeriodStart begun = period_clock.begin(k, [&] { return take_blocks(k); });
      if (begun == runtime::PeriodStart::Interrupted) break;
      if (begun == runtime::PeriodStart::TimedOut) {
        error = "no measurement block for period " + std::to_string(k) + " within " +
                std::to_string(options_.peer_timeout.count()) + " ms";
        return kExitPeerLost;
      }
      if (!end_period(k)) {
        error = "VehicleSensors or CaliperTemperatures write failed at period " + std::to_string(k);
        return kExitRuntime;
      }
    }
    sensors_.get().get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
    temperatures_.get().get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
    return kExitOk;
  }

  const vehicle_run::VehicleNode& node() const { return node_; }

  // Takes the corners' blocks of period k; true when every corner's is in (or the corner is gone).
  bool take_blocks(std::uint64_t k) {
    for (std::size_t slot = 0; slot < 4; ++slot) {
      transport::EndpointId from = 0;
      while (blocks_[slot]->take(block_, from)) {
        if (block_.run_id() != options_.participant.run_id || block_.corner_id() != slot) continue;
        if (block_.block_seq() == k) {
          node_.on_block(slot, block_);
          have_[slot] = true;
        }
      }
      dds::QosEvent e;
      while (blocks_[slot]->get().take_event(e)) {
        if (e.kind == dds::QosEvent::Kind::WriterLost || e.kind == dds::QosEvent::Kind::LivelinessLost) lost_[slot] = true;
      }
      if (lost_[slot]) node_.corner_lost(slot);
    }
    bool all = true;
    for (std::size_t slot = 0; slot < 4; ++slot) all = all && (have_[slot] || lost_[slot]);
    return all;
  }

  // Integrates period k and publishes the vehicle's readings, and every N-th period the calipers'
  // temperatures; false when a write failed.
  bool end_period(std::uint64_t k) {
    const msg::VehicleSensors& sensors = node_.simulate_period(k, n_);
    if (!sensors_.send(sensors)) return false;
    if (node::caliper_temperature_sent_after(k)) {
      temperatures_msg_.run_id(sensors.run_id());
      temperatures_msg_.step(sensors.step());
      temperatures_msg_.time_s(sensors.time_s());
      temperatures_msg_.caliper_temperature_C(sensors.caliper_temperature_C());
      if (!temperatures_.send(temperatures_msg_)) return false;
    }
    periods_done_ = k + 1;
    have_ = {};
    return true;
  }

  // Every period whose blocks are in; true when run()'s loop must carry on (the end, a failed write).
  bool advance_on_receive() {
    for (;;) {
      const std::uint64_t k = periods_done_;
      if (k >= periods_ || events_.interrupted()) return true;
      if (!take_blocks(k)) return false;
      if (!end_period(k)) {
        send_failed_ = true;
        return true;
      }
    }
  }
  std::uint64_t periods_done() const { return periods_done_; }

 private:
  using BlockInlet = dds::DdsInlet<msg::MeasurementBlockPubSubType>;
  const vehicle_run::VehicleScenario& scenario_;
  runtime::ProcessOptions options_;
  dds::Events& events_;
  vehicle_run::VehicleNode node_;
  dds::Participant participant_;
  dds::DdsOutlet<msg::VehicleSensorsPubSubType> sensors_;
  dds::DdsOutlet<msg::CaliperTemperaturesPubSubType> temperatures_;
  msg::CaliperTemperatures temperatures_msg_;
  std::array<std::unique_ptr<BlockInlet>, 4> blocks_;
  std::array<bool, 4> lost_{};
  std::array<bool, 4> have_{};  // the corners' blocks of the period being waited for
  msg::MeasurementBlock block_;
  std::uint64_t periods_ = 0;
  std::size_t n_ = 0;           // plant steps per period
  std::uint64_t periods_done_ = 0;
  bool send_failed_ = false;
};

std::string usage() {
  return runtime::process_usage("bbw_vehicle", "", {"--out DIR [--no-plots]   (vehicle_truth.csv, vehicle.json, speeds/slips/clamp_forces/mu_used/path.png)"});
}

}  // namespace
}  // namespace bbw::vehicle_process

int main(int argc, char** argv) {
  using namespace bbw::vehicle_process;

  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });
  bbw::runtime::ProcessFlags flags;
  std::string out_dir;
  bool plots = true;
  try {
    for (bbw::runtime::ArgCursor args(argc, argv); !args.done();) {
      const std::string k = args.flag();
      if (flags.take(k, args)) continue;
      if (k == "--out") out_dir = args.value();
      else if (k == "--no-plots") plots = false;
      else if (k == "-h" || k == "--help") { std::cout << usage(); return 0; }
      else throw std::invalid_argument("unknown argument '" + k + "'");
    }
    flags.finish(std::getenv("BBW_DOMAIN"));
    if (out_dir.empty()) throw std::invalid_argument("--out DIR is required");
    if (flags.options.mode != bbw::runtime::ClockMode::Lockstep) throw std::invalid_argument("bbw_vehicle runs in lockstep only");
    if (!flags.secure_dir.empty()) throw std::invalid_argument("--secure is not supported for vehicle runs yet");
  } catch (const std::exception& e) {
    std::cerr << "bbw_vehicle: " << e.what() << "\n" << usage();
    return kExitUsage;
  }
  std::optional<bbw::vehicle_run::VehicleScenario> scenario;
  try {
    scenario = bbw::vehicle_run::load_vehicle_scenario(flags.scenario_file);
  } catch (const std::exception& e) {
    std::cerr << "bbw_vehicle: " << e.what() << "\n";
    return kExitUsage;
  }
  std::string error;
  int rc = kExitOk;
  try {
    VehicleApp app(*scenario, flags.options, events);
    std::cout << "bbw_vehicle: domain " << flags.options.participant.domain_id << ", scenario " << scenario->name << std::endl;
    rc = app.run(error);
    bbw::vehicle_run::write_truth_csv(out_dir + "/vehicle_truth.csv", app.node().truth());
    bbw::vehicle_run::write_vehicle_file(out_dir + "/vehicle.json", bbw::vehicle_run::vehicle_metrics(*scenario, app.node()));
    if (plots) bbw::vehicle_run::write_vehicle_plots(out_dir, scenario->name);
    std::cout << "bbw_vehicle: " << app.periods_done() << " periods" << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "bbw_vehicle: " << e.what() << "\n";
    return kExitRuntime;
  }
  if (rc != kExitOk) {
    std::cerr << "bbw_vehicle: " << error << "\n";
    return rc;
  }
  if (const int sig = signals.received(); sig != 0) return 128 + sig;
  return kExitOk;
}
