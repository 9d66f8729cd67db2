// The CCU process: the CCU core (one CornerSupervisor per corner: guard, calibrator, fault
// monitor, reactions; the Redistributor) fed with every sample received over DDS, the DDS QoS
// events (deadline missed, liveliness lost) as link events, the per-corner commands and
// calibration states, and the logs.
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/dds/process_cli.hpp"
#include "bbw/dds/corner.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/faults/schedule.hpp"
#include "bbw/scenario/scenario.hpp"
#include "ccu_core.hpp"

namespace bbw::ccu {

using dds::ClockMode;

using dds::ExitCode;
using dds::kExitDiscovery;
using dds::kExitOk;
using dds::kExitPeerLost;
using dds::kExitRuntime;
using dds::kExitUsage;

// Mode, participant, timeouts and process_faults from dds::ProcessOptions. With
// process_faults the CCU freezes itself (SIGSTOP) at its scheduled kill time for the launcher to
// SIGKILL it, and in lockstep holds the clock at a corner's scheduled restart until the new
// process has joined.
struct CcuOptions : dds::ProcessOptions {
  std::string out_dir;                            // per-corner CSVs and ccu.stats; "" for none
  bool friction_feedback = true;                  // let corners use compensated feedback
  faults::FaultSchedule schedule;
};

// One detection (a diagnosis confirmed, or confirmed again after it had cleared).
struct DetectionRecord {
  std::size_t slot = 0;
  faults::Finding finding = faults::Finding::None;
  double onset_s = 0.0;
  double detected_s = 0.0;
};

struct CornerChannel {
  dds::Corner corner;
  std::size_t slot = 0;
  std::uint64_t next_block = 0;
  std::uint64_t next_sample_seq = 1;
  std::uint32_t incarnation = 0;
  std::uint64_t blocks_received = 0;
  std::uint64_t samples_received = 0;
  std::uint64_t samples_invalid = 0;   // rejected by the sample guard
  // Received in this corner's partition with another corner id (a corner posing as another,
  // or a corner id that does not exist): dropped before anything reads them.
  std::uint64_t foreign_blocks = 0;
  std::uint64_t foreign_health = 0;
  // Flood guard: a token bucket of blocks this corner may still have processed (refilled by
  // kBlocksPerPeriod every CCU period up to kBlockBurst); blocks beyond it are taken and dropped
  // unread, so a corner sending at many times its rate cannot take the CCU's time from the
  // others (docs/security.md, "Flooding").
  static constexpr double kBlocksPerPeriod = 2.0;
  static constexpr double kBlockBurst = 40.0;
  double block_tokens = kBlockBurst;
  std::uint64_t blocks_over_rate = 0;
  std::uint64_t block_gaps = 0;        // blocks missing or out of order (within an incarnation)
  std::uint64_t sample_gaps = 0;       // samples missing between consecutive blocks (within one)
  std::uint64_t rejoins = 0;           // new incarnations seen
  std::uint64_t command_seq = 0;
  std::uint64_t calibration_version = 0;
  std::uint64_t published_fits = 0;
  std::uint64_t published_restarts = 0;
  std::uint64_t deadlines_missed = 0;  // DDS deadline-missed events for this corner
  std::uint64_t liveliness_lost = 0;   // DDS liveliness-lost events for this corner's writer
  bool finished = false;               // received the last block
  bool writer_alive = true;            // liveliness of the corner's measurement writer
  bool have_handles = false;
  eprosima::fastrtps::rtps::InstanceHandle_t instance;  // the corner's key instance
  eprosima::fastrtps::rtps::InstanceHandle_t writer;    // the current incarnation's writer
  int health = -1;
  std::uint32_t health_incarnation = 0;
  std::array<faults::Diagnosis, 5> seen{};  // last diagnoses recorded (detection log)
  std::FILE* csv = nullptr;
};

class CcuApp {
 public:
  CcuApp(const scenario::Scenario& scenario, const calibration::CalibratorConfig& calibrator,
         const CcuOptions& options, dds::Events& events);
  ~CcuApp();
  CcuApp(const CcuApp&) = delete;
  CcuApp& operator=(const CcuApp&) = delete;

  int run(std::string& error);
  void write_stats(const std::string& file) const;

 private:
  bool wait_for_corners(std::string& error);
  void send_commands(std::uint64_t step, bool stop, bool log = true);
  void process_block(CornerChannel& ch, const msg::MeasurementBlock& b,
                     const eprosima::fastdds::dds::SampleInfo& info, double arrival_s);
  void drain_blocks(double arrival_s);
  void drain_qos_events(double now_s, bool lockstep);
  void drain_health();
  void after_period(double now_s);
  void record_detections();
  void publish_calibration(CornerChannel& ch, double time_s);
  bool wait_for_rejoin(CornerChannel& ch, std::uint32_t incarnation, std::string& error);
  [[noreturn]] void freeze_for_kill(double at_s);
  CornerChannel* channel(std::uint8_t wire_id);
  double realtime_now_s() const;

  const scenario::Scenario& scenario_;
  CcuOptions options_;
  dds::Events& events_;
  CcuCore core_;
  std::uint64_t periods_;
  std::vector<CornerChannel> channels_;

  dds::Participant participant_;
  // One measurement and one health reader per corner (same index as channels_), each in that
  // corner's partition (corner_FL, ...): DDS Security lets a corner write only there.
  using BlockReader = dds::Reader<msg::MeasurementBlockPubSubType>;
  using HealthReader = dds::Reader<msg::CornerHealthPubSubType>;
  std::vector<std::unique_ptr<BlockReader>> blocks_;
  std::vector<std::unique_ptr<HealthReader>> health_;
  dds::Writer<msg::ClampCommandPubSubType> commands_;
  dds::Writer<msg::CalibrationStatePubSubType> calibration_;

  msg::MeasurementBlock block_;
  std::vector<DetectionRecord> detections_;
  std::FILE* periods_csv_ = nullptr;
  std::uint64_t unknown_corner_blocks_ = 0;
  std::uint64_t foreign_run_samples_ = 0;  // blocks and health of another run (run id), dropped
  std::chrono::steady_clock::time_point t0_{};
  double wall_s_ = 0.0;
  double sim_s_ = 0.0;
  std::uint64_t periods_done_ = 0;
  std::optional<double> kill_at_s_;                       // scheduled CCU kill
  std::vector<std::pair<std::uint64_t, std::size_t>> restarts_;  // lockstep: (step, slot)
};

}  // namespace bbw::ccu
