// The clock policies of bbw/runtime/period_clock.hpp: lockstep begins a period when the inputs
// grant it (re-sending on stalls, giving up after its bound), realtime on the wall clock. Only
// lower bounds on time are asserted (the machine is shared): a realtime period never begins
// before its time, and a lockstep period never before its grant.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "bbw/runtime/period_clock.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::dds::Events;
using bbw::runtime::LockstepClock;
using bbw::runtime::PeriodStart;
using bbw::runtime::RealtimeClock;
using Clock = std::chrono::steady_clock;

TEST(PeriodClock, LockstepBeginsWhenTheGrantArrivesFromAnotherThread) {
  Events events;
  LockstepClock clock(events, 10s);
  clock.start(0);
  std::atomic<bool> granted{false};
  int polls = 0;
  std::thread grant([&] {
    granted.store(true);
    events.notify();
  });
  const PeriodStart s = clock.begin(0, [&] {
    ++polls;
    return granted.load();
  });
  grant.join();
  EXPECT_EQ(s, PeriodStart::Go);
  EXPECT_GE(polls, 1);
  EXPECT_EQ(clock.late_s(), 0.0);
}

TEST(PeriodClock, LockstepCallsTheStallHandlerAndGivesUpAfterItsBound) {
  Events events;
  LockstepClock clock(events, 80ms, 10ms);
  clock.start(0);
  int stalls = 0;
  const auto t0 = Clock::now();
  const PeriodStart s = clock.begin(3, [] { return false; }, [&] { ++stalls; });
  EXPECT_EQ(s, PeriodStart::TimedOut);
  EXPECT_GE(Clock::now() - t0, 80ms);
  EXPECT_GE(stalls, 1);  // every 10 ms without progress, until the bound
}

TEST(PeriodClock, LockstepStallHandlerThatGrantsEndsTheWait) {
  // The CCU re-sends its commands on a stall; here the "re-send" is what grants the period.
  Events events;
  LockstepClock clock(events, 10s, 5ms);
  clock.start(0);
  bool granted = false;
  const PeriodStart s = clock.begin(0, [&] { return granted; }, [&] {
    granted = true;
    events.notify();
  });
  EXPECT_EQ(s, PeriodStart::Go);
}

TEST(PeriodClock, AnInterruptEndsEitherWaitEvenWithTheGrantThere) {
  Events events;
  events.interrupt();
  LockstepClock lockstep(events, 10s);
  lockstep.start(0);
  EXPECT_EQ(lockstep.begin(0, [] { return true; }), PeriodStart::Interrupted);
  RealtimeClock realtime(events, 10.0, true);
  realtime.start(0);
  EXPECT_EQ(realtime.begin(1, [] { return false; }), PeriodStart::Interrupted);  // 10 s away
}

TEST(PeriodClock, RealtimeNeverBeginsAPeriodBeforeItsTime) {
  Events events;
  RealtimeClock clock(events, 0.02, false);
  clock.start(4);  // a corner that joins at period 4
  const auto t0 = clock.started_at();
  int polls = 0;
  EXPECT_EQ(clock.begin(4, [&] { return ++polls, false; }), PeriodStart::Go);  // its first period: now
  EXPECT_EQ(polls, 1);
  EXPECT_GE(clock.late_s(), 0.0);
  for (std::uint64_t k = 5; k <= 7; ++k) {
    polls = 0;
    EXPECT_EQ(clock.begin(k, [&] { return ++polls, false; }), PeriodStart::Go);
    EXPECT_GE(Clock::now() - t0, std::chrono::duration<double>(0.02 * static_cast<double>(k - 4)));
    EXPECT_EQ(polls, 1) << "without poll_while_waiting the inputs are drained once, after the wake";
    EXPECT_GE(clock.late_s(), 0.0);
  }
}

TEST(PeriodClock, RealtimeDrainsInputsWhileWaitingWhenAsked) {
  Events events;
  RealtimeClock clock(events, 0.05, true);
  clock.start(0);
  std::atomic<int> arrived{0};
  int seen = 0;
  std::thread sender([&] {
    arrived.store(1);
    events.notify();
  });
  EXPECT_EQ(clock.begin(1, [&] {
    seen = arrived.load();
    return false;
  }),
            PeriodStart::Go);
  sender.join();
  EXPECT_EQ(seen, 1);  // drained at the latest by the poll after the wake
  EXPECT_GE(Clock::now() - clock.started_at(), 50ms);
}

}  // namespace
