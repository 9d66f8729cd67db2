// The corner process: one e-caliper (CornerSim) at the DDS edge. Owns its DDS entities (RAII;
// construction throws DdsError), converts through bbw/dds/convert.hpp, reads the clock only to
// pace realtime runs.
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bbw/dds/convert.hpp"
#include "bbw/dds/corner.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/scenario/corner_sim.hpp"
#include "bbw/scenario/scenario.hpp"

namespace bbw::corner_process {

enum class ClockMode { Lockstep, Realtime };

struct CornerOptions {
  dds::Corner corner = dds::Corner::FL;
  std::size_t scenario_index = 0;               // the corner's index in the scenario
  ClockMode mode = ClockMode::Lockstep;
  dds::ParticipantOptions participant;
  std::chrono::milliseconds discovery_timeout{20000};
  std::chrono::milliseconds peer_timeout{10000};  // lockstep: longest wait for the next command
  std::string stats_file;                        // JSON with counters and jitter; "" for none
};

// Exit statuses (docs/distributed.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitRuntime = 1,
  kExitUsage = 2,
  kExitDiscovery = 3,
  kExitPeerLost = 4,
};

struct CornerStats {
  std::uint64_t periods = 0;
  std::uint64_t samples_published = 0;
  std::uint64_t blocks_published = 0;
  std::uint64_t write_failures = 0;
  std::uint64_t commands_received = 0;
  std::uint64_t commands_applied = 0;
  std::uint64_t command_seq_gaps = 0;
  std::uint64_t calibrations_applied = 0;
  std::uint64_t calibrations_rejected = 0;
  std::uint64_t overruns = 0;          // realtime: started a period more than one period late
  double max_jitter_s = 0.0;           // realtime: largest wake-up lateness
  double mean_jitter_s = 0.0;
  std::uint64_t command_deadlines_missed = 0;
  double wall_s = 0.0;
};

class CornerApp {
 public:
  // Validates (throws std::invalid_argument) before any DDS entity exists, then creates them.
  CornerApp(const scenario::Scenario& scenario, const CornerOptions& options, dds::Events& events);

  // Runs to the end of the scenario (or a stop command, or an interrupt). Returns an ExitCode;
  // `error` explains a non-zero result.
  int run(std::string& error);
  const CornerStats& stats() const { return stats_; }

 private:
  bool wait_for_ccu(std::string& error);
  void drain_inputs();
  void simulate_period(std::uint64_t k);
  void publish_health(std::uint8_t status);

  const scenario::Scenario& scenario_;
  CornerOptions options_;
  dds::Events& events_;
  scenario::CornerSim sim_;
  std::uint64_t steps_per_period_;
  std::uint64_t periods_;

  dds::Participant participant_;
  dds::Writer<msg::MeasurementBlockPubSubType> blocks_;
  dds::Writer<msg::CornerHealthPubSubType> health_;
  dds::Reader<msg::ClampCommandPubSubType> commands_;
  dds::Reader<msg::CalibrationStatePubSubType> calibration_;
  std::uint8_t my_id_;

  msg::MeasurementBlock block_;
  msg::ClampCommand latest_command_;
  bool have_command_ = false;
  std::optional<std::uint64_t> last_command_seq_;
  dds::CalibrationModel model_;
  std::vector<double> element_pos_rev_;
  bool elements_initialised_ = false;
  CornerStats stats_;
};

}  // namespace bbw::corner_process
