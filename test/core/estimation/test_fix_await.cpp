// FixAwait: the lockstep estimator's list of the plant's fixes still on their way, so that a step never
// runs before the fixes due by it have come, whatever connection delivers first.
#include <gtest/gtest.h>

#include "sowing_robot/core/estimation/fix_await.h"

using sowing_robot::core::FixAwait;
using sowing_robot::core::FixParams;

namespace {
FixParams tenHz() {
  FixParams f;
  f.rate = 10.0;
  f.dropout_start = 0.0;
  f.dropout_duration = 0.0;
  return f;
}
double at(int k) { return 1e-3 * k; }  // step k of a 1 kHz run
}  // namespace

TEST(FixAwait, AStepWaitsForTheFixDueByItAndGoesOnWhenItComes) {
  FixAwait a(tenHz(), 0.15);
  double stamp = -1.0;
  for (int k = 0; k < 150; ++k) {
    a.step(at(k), k == 0);
    ASSERT_FALSE(a.waiting(at(k), stamp)) << k;  // nothing measured at 0 s is due before 0.15 s
  }
  a.step(at(150), false);
  ASSERT_TRUE(a.waiting(at(150), stamp));
  EXPECT_DOUBLE_EQ(stamp, 0.0);
  a.received(0.0);
  EXPECT_FALSE(a.waiting(at(150), stamp));
  for (int k = 151; k < 250; ++k) {
    a.step(at(k), false);
    EXPECT_FALSE(a.waiting(at(k), stamp)) << k;
  }
  a.step(at(250), false);
  ASSERT_TRUE(a.waiting(at(250), stamp));  // the one measured at 0.1 s
  EXPECT_NEAR(stamp, 0.1, 1e-12);
}

TEST(FixAwait, AFixThatCameBeforeItsStepIsNotAwaited) {
  FixAwait a(tenHz(), 0.15);
  double stamp = 0.0;
  a.received(0.0);  // latency 0: the fix overtook the state of its own step
  a.step(at(0), true);
  for (int k = 1; k <= 150; ++k) a.step(at(k), false);
  EXPECT_FALSE(a.waiting(at(150), stamp));
}

TEST(FixAwait, NothingIsAwaitedInTheDropout) {
  FixParams f = tenHz();
  f.dropout_start = 0.05;
  f.dropout_duration = 0.2;  // the fixes of 0.1 and 0.2 s are never sent
  FixAwait a(f, 0.15);
  double stamp = 0.0;
  a.step(at(0), true);
  a.received(0.0);
  for (int k = 1; k <= 449; ++k) {
    a.step(at(k), false);
    ASSERT_FALSE(a.waiting(at(k), stamp)) << k;
  }
  a.step(at(450), false);
  ASSERT_TRUE(a.waiting(at(450), stamp));  // 0.3 s: after the dropout
  EXPECT_NEAR(stamp, 0.3, 1e-12);
}

TEST(FixAwait, ARestartedEstimatorAwaitsNothingFromBeforeItAndGivingUpLetsTheStepGo) {
  FixAwait a(tenHz(), 0.15);
  double stamp = 0.0;
  a.step(at(1234), true);  // first step mid-run: the schedule catches up, the slot passed unseen
  for (int k = 1235; k < 1450; ++k) {
    a.step(at(k), false);
    ASSERT_FALSE(a.waiting(at(k), stamp)) << k;
  }
  a.step(at(1450), false);
  ASSERT_TRUE(a.waiting(at(1450), stamp));  // the fix of 1.3 s, measured after the restart
  EXPECT_EQ(a.giveUp(at(1450)), 1);         // lost: the step goes on without it
  EXPECT_FALSE(a.waiting(at(1450), stamp));
}
