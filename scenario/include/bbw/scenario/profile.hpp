// Reference profiles: a position profile (test rig) built from segments, and a clamp-force
// profile from breakpoints. Built once (may allocate); evaluated without allocation.
#pragma once

#include <cstddef>
#include <variant>
#include <vector>

namespace bbw::scenario {

// Paper Fig. 13: consecutive raised-cosine sinusoids from x_low_rev up to x_low_rev + amplitude
// and back, each amplitude repeated cycles_per_amplitude times. Every cycle starts and ends at
// x_low_rev (a falling-to-rising turn there starts the calibrator's cycle).
struct PaperSweep {
  double x_low_rev = 0.5;
  std::vector<double> amplitudes_rev;   // peak height above x_low_rev of each sinusoid
  double period_s = 2.0;
  int cycles_per_amplitude = 1;
};

// Paper Fig. 10: small loops around mid-range levels. At each level
// x = level - amplitude_rev sin(2 pi t / period_s) for cycles_per_level periods (down first,
// so each loop starts with a falling-to-rising turn); levels are joined by cosine ramps of ramp_s.
struct LocalLoops {
  std::vector<double> levels_rev;
  double amplitude_rev = 0.3;
  double period_s = 1.0;
  int cycles_per_level = 2;
  double ramp_s = 1.0;
};

// x = offset + amplitude sin(2 pi t / period) for `cycles` periods.
struct Sine {
  double offset_rev = 3.0;
  double amplitude_rev = 1.0;
  double period_s = 1.0;
  int cycles = 1;
};

// Position steps: jump to each level and hold it for hold_s.
struct Steps {
  std::vector<double> levels_rev;
  double hold_s = 1.0;
};

// Hold a position (e.g. for creep).
struct Hold {
  double position_rev = 0.0;
  double duration_s = 1.0;
};

using PositionSegment = std::variant<PaperSweep, LocalLoops, Sine, Steps, Hold>;

struct PositionProfileSpec {
  double start_rev = 0.0;   // where the actuator rests at t = 0
  double ramp_s = 1.0;      // smooth (cosine) ramp between segments whose ends differ
  std::vector<PositionSegment> segments;
};

struct Reference {
  double value = 0.0;       // rev (position) or kN (force)
  double rate = 0.0;        // per second
  double accel = 0.0;       // per second squared
};

class PositionProfile {
 public:
  explicit PositionProfile(const PositionProfileSpec& spec);  // throws std::invalid_argument
  // Reference at time t (holds the last value after the end). Allocation-free.
  Reference at(double t_s) const;
  double duration_s() const { return duration_s_; }
  double min_rev() const;
  double max_rev() const;

  // One primitive piece of the profile (public for tests and plots).
  enum class Kind { Hold, CosRamp, RaisedCosine, Sine };
  struct Piece {
    Kind kind = Kind::Hold;
    double t0_s = 0.0;
    double duration_s = 0.0;
    double a = 0.0;         // Hold: value; CosRamp: from; RaisedCosine: low; Sine: centre
    double b = 0.0;         // CosRamp: to; RaisedCosine: height; Sine: amplitude
    double period_s = 1.0;  // RaisedCosine, Sine
  };
  const std::vector<Piece>& pieces() const { return pieces_; }

 private:
  void add(Kind kind, double duration_s, double a, double b, double period_s);
  void go_to(double x_rev, double ramp_s);
  double end_value() const;

  std::vector<Piece> pieces_;
  double duration_s_ = 0.0;
};

struct Breakpoint {
  double t_s = 0.0;
  double value = 0.0;
};

// Piecewise linear in time through breakpoints (strictly increasing t); constant before the
// first and after the last.
class BreakpointProfile {
 public:
  explicit BreakpointProfile(std::vector<Breakpoint> points);  // throws std::invalid_argument
  Reference at(double t_s) const;
  double duration_s() const { return points_.back().t_s; }
  const std::vector<Breakpoint>& points() const { return points_; }

 private:
  std::vector<Breakpoint> points_;
};

}  // namespace bbw::scenario
