#include "bbw/scenario/profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bbw::scenario {
namespace {

constexpr double kPi = 3.141592653589793;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

void PositionProfile::add(Kind kind, double duration_s, double a, double b, double period_s) {
  if (duration_s <= 0.0) return;
  pieces_.push_back(Piece{kind, duration_s_, duration_s, a, b, period_s});
  duration_s_ += duration_s;
}

double PositionProfile::end_value() const {
  const Piece& p = pieces_.back();
  switch (p.kind) {
    case Kind::Hold: return p.a;
    case Kind::CosRamp: return p.b;
    case Kind::RaisedCosine: return p.a;  // whole cycles end at the low point
    case Kind::Sine: return p.a;          // whole cycles end at the centre
  }
  return p.a;
}

void PositionProfile::go_to(double x_rev, double ramp_s) {
  const double from = end_value();
  if (std::abs(from - x_rev) > 1e-12) add(Kind::CosRamp, ramp_s, from, x_rev, 0.0);
}

PositionProfile::PositionProfile(const PositionProfileSpec& spec) {
  require(std::isfinite(spec.start_rev), "position profile: start_rev must be finite");
  require(spec.ramp_s > 0.0, "position profile: ramp_s must be > 0");
  require(!spec.segments.empty(), "position profile: needs at least one segment");
  pieces_.push_back(Piece{Kind::Hold, 0.0, 0.0, spec.start_rev, 0.0, 1.0});
  for (const auto& seg : spec.segments) {
    if (const auto* s = std::get_if<PaperSweep>(&seg)) {
      require(!s->amplitudes_rev.empty(), "paper_sweep: amplitudes_rev must not be empty");
      require(s->period_s > 0.0 && s->cycles_per_amplitude >= 1, "paper_sweep: period_s > 0, cycles >= 1");
      go_to(s->x_low_rev, spec.ramp_s);
      for (const double a : s->amplitudes_rev) {
        require(a > 0.0, "paper_sweep: amplitudes must be > 0");
        add(Kind::RaisedCosine, s->period_s * s->cycles_per_amplitude, s->x_low_rev, a, s->period_s);
      }
    } else if (const auto* l = std::get_if<LocalLoops>(&seg)) {
      require(!l->levels_rev.empty(), "local_loops: levels_rev must not be empty");
      require(l->period_s > 0.0 && l->cycles_per_level >= 1 && l->ramp_s > 0.0 && l->amplitude_rev > 0.0,
              "local_loops: period_s, ramp_s, amplitude_rev > 0, cycles >= 1");
      for (const double level : l->levels_rev) {
        go_to(level, l->ramp_s);
        add(Kind::Sine, l->period_s * l->cycles_per_level, level, -l->amplitude_rev, l->period_s);
      }
    } else if (const auto* s2 = std::get_if<Sine>(&seg)) {
      require(s2->period_s > 0.0 && s2->cycles >= 1, "sine: period_s > 0, cycles >= 1");
      go_to(s2->offset_rev, spec.ramp_s);
      add(Kind::Sine, s2->period_s * s2->cycles, s2->offset_rev, s2->amplitude_rev, s2->period_s);
    } else if (const auto* st = std::get_if<Steps>(&seg)) {
      require(!st->levels_rev.empty() && st->hold_s > 0.0, "steps: levels_rev non-empty, hold_s > 0");
      for (const double level : st->levels_rev) add(Kind::Hold, st->hold_s, level, 0.0, 1.0);
    } else if (const auto* h = std::get_if<Hold>(&seg)) {
      require(h->duration_s > 0.0, "hold: duration_s must be > 0");
      go_to(h->position_rev, spec.ramp_s);
      add(Kind::Hold, h->duration_s, h->position_rev, 0.0, 1.0);
    }
  }
}

Reference PositionProfile::at(double t_s) const {
  // Binary search for the last piece starting at or before t.
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t_s,
                             [](double t, const Piece& p) { return t < p.t0_s; });
  const Piece& p = it == pieces_.begin() ? pieces_.front() : *(it - 1);
  if (t_s >= duration_s_) {
    return Reference{end_value(), 0.0, 0.0};
  }
  const double tau = std::max(t_s - p.t0_s, 0.0);
  switch (p.kind) {
    case Kind::Hold: return Reference{p.a, 0.0, 0.0};
    case Kind::CosRamp: {
      const double w = kPi / p.duration_s;
      const double h = 0.5 * (p.b - p.a);
      return Reference{p.a + h * (1.0 - std::cos(w * tau)), h * w * std::sin(w * tau),
                       h * w * w * std::cos(w * tau)};
    }
    case Kind::RaisedCosine: {
      const double w = 2.0 * kPi / p.period_s;
      const double h = 0.5 * p.b;
      return Reference{p.a + h * (1.0 - std::cos(w * tau)), h * w * std::sin(w * tau),
                       h * w * w * std::cos(w * tau)};
    }
    case Kind::Sine: {
      const double w = 2.0 * kPi / p.period_s;
      return Reference{p.a + p.b * std::sin(w * tau), p.b * w * std::cos(w * tau),
                       -p.b * w * w * std::sin(w * tau)};
    }
  }
  return Reference{p.a, 0.0, 0.0};
}

double PositionProfile::min_rev() const {
  double m = pieces_.front().a;
  for (const auto& p : pieces_) {
    switch (p.kind) {
      case Kind::Hold: m = std::min(m, p.a); break;
      case Kind::CosRamp: m = std::min({m, p.a, p.b}); break;
      case Kind::RaisedCosine: m = std::min({m, p.a, p.a + p.b}); break;
      case Kind::Sine: m = std::min(m, p.a - std::abs(p.b)); break;
    }
  }
  return m;
}

double PositionProfile::max_rev() const {
  double m = pieces_.front().a;
  for (const auto& p : pieces_) {
    switch (p.kind) {
      case Kind::Hold: m = std::max(m, p.a); break;
      case Kind::CosRamp: m = std::max({m, p.a, p.b}); break;
      case Kind::RaisedCosine: m = std::max({m, p.a, p.a + p.b}); break;
      case Kind::Sine: m = std::max(m, p.a + std::abs(p.b)); break;
    }
  }
  return m;
}

BreakpointProfile::BreakpointProfile(std::vector<Breakpoint> points) : points_(std::move(points)) {
  require(!points_.empty(), "breakpoint profile: needs at least one breakpoint");
  for (std::size_t i = 0; i < points_.size(); ++i) {
    require(std::isfinite(points_[i].t_s) && std::isfinite(points_[i].value),
            "breakpoint profile: values must be finite");
    if (i > 0) {
      require(points_[i].t_s > points_[i - 1].t_s,
              "breakpoint profile: times must increase strictly (breakpoint " + std::to_string(i) + ")");
    }
  }
}

Reference BreakpointProfile::at(double t_s) const {
  if (t_s <= points_.front().t_s) return Reference{points_.front().value, 0.0, 0.0};
  if (t_s >= points_.back().t_s) return Reference{points_.back().value, 0.0, 0.0};
  auto it = std::upper_bound(points_.begin(), points_.end(), t_s,
                             [](double t, const Breakpoint& b) { return t < b.t_s; });
  const Breakpoint& b1 = *it;
  const Breakpoint& b0 = *(it - 1);
  const double rate = (b1.value - b0.value) / (b1.t_s - b0.t_s);
  return Reference{b0.value + rate * (t_s - b0.t_s), rate, 0.0};
}

}  // namespace bbw::scenario
