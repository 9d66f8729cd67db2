// Redistribution of the demanded total clamp force.
#include <gtest/gtest.h>

#include "bbw/faults/redistributor.hpp"

using namespace bbw::faults;

namespace {
std::array<CornerCapacity, kCorners> all(double limit) {
  std::array<CornerCapacity, kCorners> c;
  for (auto& x : c) x = {true, limit};
  return c;
}
}  // namespace

TEST(Redistributor, NominalSplitFollowsTheFrontShare) {
  const Redistributor r(0.6);
  const auto a = r.allocate(100.0, all(40.0));
  EXPECT_DOUBLE_EQ(a.force_kN[0], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[1], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 20.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 20.0);
  EXPECT_DOUBLE_EQ(a.total_kN, 100.0);
  EXPECT_DOUBLE_EQ(a.shortfall_kN, 0.0);
  EXPECT_DOUBLE_EQ(r.nominal_kN(2, 100.0), 20.0);
  EXPECT_THROW(Redistributor(0.4), std::invalid_argument);
}

TEST(Redistributor, ALostFrontCornerGoesToItsPartnerThenToTheRear) {
  const Redistributor r(0.6);
  auto c = all(40.0);
  c[0].available = false;
  auto a = r.allocate(100.0, c);  // front wants 60: FR takes 40, 20 spills to the rear
  EXPECT_DOUBLE_EQ(a.force_kN[0], 0.0);
  EXPECT_DOUBLE_EQ(a.force_kN[1], 40.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 30.0);
  EXPECT_DOUBLE_EQ(a.total_kN, 100.0);
  a = r.allocate(60.0, c);  // within FR's limit: the rear keeps its nominal share
  EXPECT_DOUBLE_EQ(a.force_kN[1], 36.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 12.0);
}

// A corner that does not release still brakes: its held force counts on its own axle, and
// what it holds beyond its axle's part is not taken off the other axle.
TEST(Redistributor, AHeldForceCountsOnItsAxleOnly) {
  const Redistributor r(0.6);
  auto c = all(40.0);
  c[0] = {false, 40.0, 20.0};     // FL holds 20 kN
  auto a = r.allocate(100.0, c);  // front wants 60: FR 40
  EXPECT_DOUBLE_EQ(a.force_kN[0], 0.0);
  EXPECT_DOUBLE_EQ(a.force_kN[1], 40.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 20.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 20.0);
  EXPECT_DOUBLE_EQ(a.held_kN, 20.0);
  EXPECT_DOUBLE_EQ(a.total_kN + a.held_kN, 100.0);
  a = r.allocate(20.0, c);        // front wants 12 < 20 held: FR 0, the rear keeps its 8
  EXPECT_DOUBLE_EQ(a.force_kN[1], 0.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 4.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 4.0);
  c[3] = {false, 40.0, 10.0};     // RR holds 10 kN too: RL gets the rear's 40 - 10
  a = r.allocate(100.0, c);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 0.0);
  c[3] = {true, 40.0, 10.0};      // held_kN of an available corner is ignored
  a = r.allocate(100.0, c);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 20.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 20.0);
  EXPECT_DOUBLE_EQ(a.held_kN, 20.0);
}

TEST(Redistributor, LimitsAndShortfall) {
  const Redistributor r(0.6);
  auto c = all(30.0);
  c[2].available = false;
  c[3].limit_kN = 10.0;
  const auto a = r.allocate(200.0, c);
  EXPECT_DOUBLE_EQ(a.force_kN[0], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[1], 30.0);
  EXPECT_DOUBLE_EQ(a.force_kN[2], 0.0);
  EXPECT_DOUBLE_EQ(a.force_kN[3], 10.0);
  EXPECT_DOUBLE_EQ(a.shortfall_kN, 130.0);
  EXPECT_DOUBLE_EQ(a.total_kN + a.shortfall_kN, 200.0);
  std::array<CornerCapacity, kCorners> none{};
  for (auto& x : none) x.available = false;
  EXPECT_DOUBLE_EQ(r.allocate(50.0, none).shortfall_kN, 50.0);
  EXPECT_DOUBLE_EQ(r.allocate(-5.0, all(40.0)).total_kN, 0.0);
}
