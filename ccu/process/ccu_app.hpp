// The CCU process: one Calibrator per corner fed with every sample received over DDS, the
// fused clamp-force estimate, the per-corner commands, the calibration states, and the logs.
#pragma once

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bbw/calibration/calibrator.hpp"
#include "bbw/dds/corner.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/scenario/scenario.hpp"
#include "command_plan.hpp"

namespace bbw::ccu {

enum class ClockMode { Lockstep, Realtime };

enum ExitCode : int {
  kExitOk = 0,
  kExitRuntime = 1,
  kExitUsage = 2,
  kExitDiscovery = 3,
  kExitPeerLost = 4,
};

struct CcuOptions {
  ClockMode mode = ClockMode::Lockstep;
  dds::ParticipantOptions participant;
  std::chrono::milliseconds discovery_timeout{20000};
  std::chrono::milliseconds peer_timeout{10000};  // lockstep: longest wait for a block
  std::string out_dir;                            // per-corner CSVs and ccu.stats; "" for none
  double fusion_weight = 0.5;                     // load-cell share of the fused estimate
  bool friction_feedback = true;                  // let corners use compensated feedback
};

struct CornerChannel {
  dds::Corner corner;
  std::size_t scenario_index = 0;
  std::unique_ptr<calibration::Calibrator> calibrator;
  std::uint64_t next_block = 0;
  std::uint64_t next_sample_seq = 1;
  std::uint64_t blocks_received = 0;
  std::uint64_t samples_received = 0;
  std::uint64_t samples_invalid = 0;
  std::uint64_t block_gaps = 0;      // blocks missing or out of order
  std::uint64_t sample_gaps = 0;     // samples missing between consecutive blocks
  std::uint64_t command_seq = 0;
  std::uint64_t calibration_version = 0;
  std::uint64_t published_fits = 0;
  double last_friction_kN = 0.0;
  bool finished = false;             // received the last block (or health FINISHED)
  int health = -1;
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
  void send_command(CornerChannel& ch, std::uint64_t step, bool stop);
  void process_block(const msg::MeasurementBlock& b);
  void drain_health();
  CornerChannel* channel(std::uint8_t wire_id);
  std::string missing_corners(bool (*pred)(const CornerChannel&)) const;

  const scenario::Scenario& scenario_;
  CcuOptions options_;
  dds::Events& events_;
  CommandPlanner planner_;
  std::uint64_t periods_;
  std::vector<CornerChannel> channels_;

  dds::Participant participant_;
  dds::Reader<msg::MeasurementBlockPubSubType> blocks_;
  dds::Reader<msg::CornerHealthPubSubType> health_;
  dds::Writer<msg::ClampCommandPubSubType> commands_;
  dds::Writer<msg::CalibrationStatePubSubType> calibration_;

  msg::MeasurementBlock block_;
  std::uint64_t unknown_corner_blocks_ = 0;
  double wall_s_ = 0.0;
  double sim_s_ = 0.0;
  std::uint64_t periods_done_ = 0;
};

}  // namespace bbw::ccu
