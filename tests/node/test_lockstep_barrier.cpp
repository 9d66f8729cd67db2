#include "bbw/node/lockstep_barrier.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace bbw::node {

TEST(LockstepBarrier, CompleteOnlyWhenEveryLiveParticipantIsDone) {
  LockstepBarrier b;
  const auto fl = b.add("FL");
  const auto vehicle = b.add("vehicle");
  const auto pedal = b.add("pedal");
  EXPECT_FALSE(b.complete(0));
  b.done(fl, 0);
  b.done(vehicle, 0);
  EXPECT_FALSE(b.complete(0));
  EXPECT_EQ(b.lagging(0), "pedal");
  b.done(pedal, 0);
  EXPECT_TRUE(b.complete(0));
  EXPECT_FALSE(b.complete(1));
  EXPECT_EQ(b.lagging(1), "FL, vehicle, pedal");
}

TEST(LockstepBarrier, AnOldOrRepeatedStepNeverMovesBack) {
  LockstepBarrier b;
  const auto p = b.add("FL");
  b.done(p, 5);
  b.done(p, 2);  // a replayed or forged block number
  EXPECT_EQ(b.next(p), 6u);
  EXPECT_TRUE(b.complete(5));
}

TEST(LockstepBarrier, ADeadParticipantNoLongerHoldsItAndARejoinStartsAtItsStep) {
  LockstepBarrier b;
  const auto a = b.add("FL");
  const auto c = b.add("FR");
  b.done(a, 3);
  b.done(c, 2);
  EXPECT_FALSE(b.complete(3));
  b.set_alive(c, false);
  EXPECT_TRUE(b.complete(3));
  b.set_alive(c, true);
  b.rejoin(c, 10);
  EXPECT_EQ(b.next(c), 10u);
  EXPECT_FALSE(b.complete(10));
}

TEST(LockstepBarrier, AFailureEndsTheWait) {
  LockstepBarrier b;
  const auto a = b.add("FL");
  b.add("FR");
  b.set_failed(a, true);
  EXPECT_TRUE(b.complete(0));
  EXPECT_TRUE(b.any_failed());
  b.set_failed(a, false);
  EXPECT_FALSE(b.complete(0));
}

TEST(LockstepBarrier, NamesAreUnique) {
  LockstepBarrier b;
  b.add("FL");
  EXPECT_THROW(b.add("FL"), std::invalid_argument);
}

}  // namespace bbw::node
