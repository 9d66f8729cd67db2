// The real-time caliper calibrator (docs/calibrator.md, ../shared/docs/calibration-algorithm.md).
//
// Pure: no DDS, no clock, no file, no thread. Memory is sized at construction; update() does
// not allocate. The same object runs per sample in the CCU, offline over a CSV and in tests.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "bbw/calibration/config.hpp"
#include "bbw/calibration/curve.hpp"

namespace bbw::calibration {

struct Sample {
  double time_s = 0.0;
  double position_rev = 0.0;  // resolver position, actuator revolutions
  double force_kN = 0.0;      // internal load-cell reading (true force + key friction)
};

struct Estimate {
  double force_kN = 0.0;        // f_hat = load cell minus estimated friction
  double friction_kN = 0.0;     // estimated key/keyway friction sum K_i Delta_i n_i
  double curve_force_kN = 0.0;  // A x^3 + B x^2 + C x + D at the sample's position
  bool valid = false;           // false when the sample was rejected (NaN, out of range)
  bool calibrated = false;      // true once at least one cycle fit was accepted
};

struct Stats {
  std::uint64_t samples_seen = 0;
  std::uint64_t samples_rejected = 0;  // non-finite or out of the configured physical range
  std::uint64_t cycles_detected = 0;
  std::uint64_t fits_accepted = 0;
  std::uint64_t fits_rejected = 0;
  double first_fit_time_s = -1.0;      // time of the first accepted fit; -1 before it
  double last_fit_rms_kN = 0.0;        // residual RMS of the last accepted cycle fit
  double last_fit_span_rev = 0.0;      // displacement span of the last cycle fitted
};

// Friction part of the model: thresholds and fitted stiffnesses (K_i in kN/rev).
struct FrictionParams {
  std::vector<double> delta_rev;        // Delta_i
  std::vector<double> stiffness_kN_per_rev;  // K_i
};

class Calibrator {
 public:
  explicit Calibrator(const CalibratorConfig& config);  // throws std::invalid_argument

  // One sample in, one estimate out. Never allocates.
  Estimate update(const Sample& sample);

  const Curve& curve() const { return curve_; }
  const FrictionParams& friction() const { return friction_; }
  const Stats& stats() const { return stats_; }
  const CalibratorConfig& config() const { return config_; }
  // PF points' force coordinates (N + 1 of them) at X_k = Xmin + k (Xmax - Xmin) / N.
  const std::vector<double>& pf_forces_kN() const { return pf_force_kN_; }

  // Restart from a known curve (e.g. a restarted corner's last good curve). Keeps stats.
  void reset_curve(const Curve& curve);

  // Bytes owned by this object (itself plus its buffers), for the memory budget.
  std::size_t state_bytes() const;

 private:
  struct Slot;
  void start_cycle(double x_rev);
  void end_cycle(double time_s);
  void store(const Sample& s);
  double friction_now() const;
  void step_elements(double x_rev);
  bool fit_cycle(Curve& local, std::vector<double>& k_out);
  void refit_global();

  CalibratorConfig config_;
  Curve curve_;
  FrictionParams friction_;
  Stats stats_;
  std::vector<double> pf_force_kN_;

  // Cycle detector history (ring of 2 n0 + 1 positions).
  std::vector<double> history_rev_;
  std::size_t history_head_ = 0;
  std::uint64_t history_count_ = 0;
  bool in_cycle_ = false;
  std::uint64_t samples_since_start_ = 0;

  // Element states: x_i positions for the live (streaming) model.
  std::vector<double> element_pos_rev_;
  std::vector<double> cycle_start_pos_rev_;  // x0_i at the current cycle's start

  // Bounded store: L + 1 slots of (x, f, n_1..n_M), flattened.
  std::vector<double> store_x_rev_;
  std::vector<double> store_f_kN_;
  std::vector<double> store_n_;  // (L + 1) * M
  std::vector<double> dist_;     // L distances between consecutive slots
  std::size_t store_count_ = 0;

  // Fit workspace, sized at construction.
  std::vector<double> work_a_;  // design matrix rows
  std::vector<double> work_b_;
  std::vector<double> work_x_;
  std::vector<double> work_tmp_;
  std::vector<double> replay_pos_;
};

}  // namespace bbw::calibration
