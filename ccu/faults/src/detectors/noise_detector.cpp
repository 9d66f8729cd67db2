#include "bbw/faults/detectors/noise_detector.hpp"

#include <algorithm>
#include <cmath>

#include "bbw/faults/fault_monitor.hpp"

namespace bbw::faults {

void NoiseDetector::update(double residual_kN, double model_kN, double t, const MonitorParams& p, DiagnosisArbiter& a) {
  have_prev_difference_ = false;  // the difference path starts afresh when it is next used
  if (!have_prev_residual_) {
    have_prev_residual_ = true;
    prev_residual_kN_ = residual_kN;
    prev_model_kN_ = model_kN;
    return;
  }
  const double d = residual_kN - prev_residual_kN_;
  const double model_step_kN = std::isfinite(model_kN - prev_model_kN_) ? std::abs(model_kN - prev_model_kN_) : 0.0;
  prev_residual_kN_ = residual_kN;
  prev_model_kN_ = model_kN;
  // The learnt level counts once a whole time constant was learnt (a burst early in the run must
  // not be learnt as the healthy level before it is seen).
  const bool learnt = learnt_s_ >= p.noise_learn_time_constant_s;
  const double step_kN = learnt ? std::max(p.noise_step_kN, p.noise_learned_factor * mean_abs_step_kN_) : p.noise_step_kN;
  count(std::abs(d) > step_kN + model_step_kN, t, p, a);
  // Learn the healthy level while the window is below a finding (a burst is found within a
  // window, about 1/30 of the time constant: it moves the level by a few per cent at most).
  if (std::isfinite(d) && fraction_ < p.noise_min_fraction) {
    const double dt_s = have_learn_time_ ? t - learn_time_s_ : 0.0;
    if (dt_s > 0.0) {
      // The plain mean of what was learnt until the time constant is reached, then exponential.
      learnt_s_ += dt_s;
      const double weight = std::min(1.0, dt_s / std::min(learnt_s_, p.noise_learn_time_constant_s));
      mean_abs_step_kN_ += (std::abs(d) - mean_abs_step_kN_) * weight;
    }
    have_learn_time_ = true;
    learn_time_s_ = t;
  } else {
    have_learn_time_ = false;
  }
}

void NoiseDetector::update_load_cell_difference(double difference_kN, double t, const MonitorParams& p,
                                                DiagnosisArbiter& a) {
  if (!have_prev_difference_) {
    have_prev_difference_ = true;
    prev_difference_kN_ = difference_kN;
    return;
  }
  const double second_kN = difference_kN - prev_difference_kN_;
  prev_difference_kN_ = difference_kN;
  count(std::abs(second_kN) > p.noise_second_difference_kN, t, p, a);
}

void NoiseDetector::count(bool big, double t, const MonitorParams& p, DiagnosisArbiter& a) {
  const int w = p.noise_window_samples;
  const auto h = static_cast<std::size_t>(head_);
  if (count_ == w) big_count_ -= big_[h];
  big_[h] = big ? 1 : 0;
  big_count_ += big_[h];
  head_ = (head_ + 1) % w;
  if (count_ < w) ++count_;
  fraction_ = static_cast<double>(big_count_) / w;
  if (fraction_ >= p.noise_min_fraction) a.confirm(Finding::LoadCellNoisy, t, t);
}

}  // namespace bbw::faults
