// The clock policy of a bbw process, behind one small interface: how period k begins.
//
//   Lockstep: period k begins when the process's inputs grant it (a corner: the CCU's command
//   for k; the CCU: every live corner's block k). `begin` drains the inputs through `poll`
//   until it returns true, calling `on_stall` every `stall_every` without progress (the CCU
//   re-sends its commands then), and gives up after `give_up_after` (TimedOut).
//   Realtime: period k begins on the wall clock, at start + (k - first) * period. `begin`
//   sleeps until then, calling `poll` on every wake-up in between (inputs are drained as they
//   come) and once after the wake; `late_s()` says how late the period began.
//
// Both wait on the process's one wake-up point (bbw::dds::Events) and return Interrupted at
// once on SIGINT/SIGTERM; neither ever sleeps unconditionally. The adapters (bbw_corner,
// bbw_ccu, and any process that joins a run) own one, made by `make_period_clock`.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>

#include "bbw/dds/events.hpp"
#include "bbw/runtime/process_cli.hpp"

namespace bbw::runtime {

enum class PeriodStart { Go, Interrupted, TimedOut };

class PeriodClock {
 public:
  using Clock = std::chrono::steady_clock;
  using Poll = std::function<bool()>;
  using Stall = std::function<void()>;

  virtual ~PeriodClock() = default;
  virtual ClockMode mode() const = 0;
  // The run starts now; `first` is the first period this process simulates (a restarted corner
  // joins later than 0).
  virtual void start(std::uint64_t first) = 0;
  virtual PeriodStart begin(std::uint64_t k, const Poll& poll, const Stall& on_stall = {}) = 0;
  // How late the last period began on the wall clock (realtime; 0 in lockstep).
  virtual double late_s() const = 0;
  // When the run started (start()).
  virtual Clock::time_point started_at() const = 0;
};

class LockstepClock final : public PeriodClock {
 public:
  LockstepClock(dds::Events& events, Clock::duration give_up_after,
                Clock::duration stall_every = std::chrono::milliseconds(200))
      : events_(events), give_up_after_(give_up_after), stall_every_(stall_every) {}
  ClockMode mode() const override { return ClockMode::Lockstep; }
  void start(std::uint64_t) override { t0_ = Clock::now(); }
  PeriodStart begin(std::uint64_t, const Poll& poll, const Stall& on_stall = {}) override {
    const auto give_up = Clock::now() + give_up_after_;
    for (;;) {
      const bool ok = events_.wait_until(std::min(give_up, Clock::now() + stall_every_), poll);
      if (events_.interrupted()) return PeriodStart::Interrupted;
      if (ok) return PeriodStart::Go;
      if (Clock::now() >= give_up) return PeriodStart::TimedOut;
      if (on_stall) on_stall();
    }
  }
  double late_s() const override { return 0.0; }
  Clock::time_point started_at() const override { return t0_; }

 private:
  dds::Events& events_;
  Clock::duration give_up_after_, stall_every_;
  Clock::time_point t0_{};
};

class RealtimeClock final : public PeriodClock {
 public:
  // `poll_while_waiting`: drain inputs as they come (the CCU), or only once the period has
  // begun (a corner applies the newest command at the start of its period).
  RealtimeClock(dds::Events& events, double period_s, bool poll_while_waiting)
      : events_(events),
        period_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s))),
        poll_while_waiting_(poll_while_waiting) {}
  ClockMode mode() const override { return ClockMode::Realtime; }
  void start(std::uint64_t first) override {
    first_ = first;
    t0_ = Clock::now();
  }
  PeriodStart begin(std::uint64_t k, const Poll& poll, const Stall& = {}) override {
    const auto wake = t0_ + period_ * static_cast<long long>(k - first_);
    // Events::wait_until evaluates its predicate once more after the deadline has passed, so
    // with poll_while_waiting the inputs are drained after the wake too.
    events_.wait_until(wake, [&] {
      if (poll_while_waiting_ && poll) poll();
      return events_.interrupted();
    });
    if (events_.interrupted()) return PeriodStart::Interrupted;
    late_s_ = std::chrono::duration<double>(Clock::now() - wake).count();
    if (!poll_while_waiting_ && poll) poll();
    return PeriodStart::Go;
  }
  double late_s() const override { return late_s_; }
  Clock::time_point started_at() const override { return t0_; }

 private:
  dds::Events& events_;
  Clock::duration period_;
  bool poll_while_waiting_;
  std::uint64_t first_ = 0;
  Clock::time_point t0_{};
  double late_s_ = 0.0;
};

// The policy for `mode`: lockstep gives up after `lockstep_give_up_after` without a grant and
// calls the stall handler every `lockstep_stall_every`;
// realtime paces on `period_s` (see RealtimeClock for `poll_while_waiting`).
inline std::unique_ptr<PeriodClock> make_period_clock(
    ClockMode mode, dds::Events& events, double period_s, PeriodClock::Clock::duration lockstep_give_up_after,
    bool poll_while_waiting, PeriodClock::Clock::duration lockstep_stall_every = std::chrono::milliseconds(200)) {
  if (mode == ClockMode::Lockstep) {
    return std::make_unique<LockstepClock>(events, lockstep_give_up_after, lockstep_stall_every);
  }
  return std::make_unique<RealtimeClock>(events, period_s, poll_while_waiting);
}

}  // namespace bbw::runtime
