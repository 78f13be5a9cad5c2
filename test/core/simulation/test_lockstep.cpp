// The plant's side of the lockstep protocol (core::LockstepProtocol), driven tick by tick with made-up
// wall times: what PlantSim's lockstep driver does with each torque and as wall time passes.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "sowing_robot/core/simulation/lockstep.h"

using sowing_robot::core::LockstepProtocol;
using sowing_robot::core::LockstepTiming;
using sowing_robot::core::WheelTorques;
using Answer = LockstepProtocol::Answer;
using Phase = LockstepProtocol::Phase;

namespace {

constexpr std::int64_t kPeriod = 2000000;  // 500 Hz, as lockstep_dead_controller.test

LockstepTiming timing(double retry = 0.5, double timeout = 5.0, double give_up = 120.0, double startup_delay = 0.5) {
  LockstepTiming t;
  t.retry = retry;
  t.timeout = timeout;
  t.give_up = give_up;
  t.startup_delay = startup_delay;
  return t;
}

/// A protocol that has published state 0 at wall time `at`.
LockstepProtocol started(std::int64_t last_step = -1, const LockstepTiming& t = timing(), double at = 0.0) {
  LockstepProtocol p(kPeriod, last_step, t);
  p.tick(at - t.startup_delay, true);
  const LockstepProtocol::Supervision s = p.tick(at, true);
  EXPECT_TRUE(s.start);
  return p;
}

Answer answer(LockstepProtocol& p, std::int64_t k, double right = 1.0, double left = 2.0) {
  return p.onTorque(k * kPeriod, WheelTorques{right, left});
}

}  // namespace

TEST(Lockstep, WaitsForTheLoopToConnectBeforeStepZero) {
  LockstepProtocol p(kPeriod, -1, timing(0.5, 5.0, 120.0, 0.5));
  EXPECT_FALSE(p.tick(0.0, false).start);
  EXPECT_EQ(answer(p, 0), Answer::kNotRunning);  // nothing has been published: no answer yet
  EXPECT_FALSE(p.tick(3.0, false).start);
  EXPECT_EQ(p.phase(), Phase::kConnecting);
  EXPECT_FALSE(p.tick(3.25, true).start);  // connected: settles for startup_delay first
  EXPECT_EQ(p.phase(), Phase::kSettling);
  EXPECT_FALSE(p.tick(3.7, true).start);
  const LockstepProtocol::Supervision s = p.tick(3.75, true);
  EXPECT_TRUE(s.start);
  EXPECT_EQ(s.step, 0);
  EXPECT_EQ(p.awaited(), 0);
  EXPECT_DOUBLE_EQ(p.startedAt(), 3.75);
  EXPECT_FALSE(p.tick(3.8, true).start);  // once
}

TEST(Lockstep, ReportsTheUnconnectedLoopEveryTimeoutAndGivesUp) {
  LockstepProtocol p(kPeriod, -1, timing(0.5, 1.5, 3.0));
  p.tick(10.0, false);
  EXPECT_FALSE(p.tick(11.49, false).report);
  const LockstepProtocol::Supervision first = p.tick(11.5, false);
  EXPECT_TRUE(first.report);
  EXPECT_DOUBLE_EQ(first.waited, 1.5);
  EXPECT_EQ(first.step, -1);
  EXPECT_FALSE(p.tick(12.0, false).report);
  EXPECT_TRUE(p.tick(13.0, false).report);
  EXPECT_FALSE(p.tick(13.0, false).give_up);  // exactly give_up: not yet
  const LockstepProtocol::Supervision last = p.tick(13.01, false);
  EXPECT_TRUE(last.give_up);
  EXPECT_EQ(p.phase(), Phase::kGaveUp);
  EXPECT_TRUE(p.over());
  EXPECT_FALSE(p.tick(14.0, true).start);  // a loop connecting after the give-up starts nothing
}

TEST(Lockstep, StepsOnTheAnswerForTheAwaitedState) {
  LockstepProtocol p = started();
  EXPECT_EQ(answer(p, 0, 0.25, -0.5), Answer::kStep);
  EXPECT_EQ(p.awaited(), 1);
  EXPECT_EQ(p.torque().right, 0.25);
  EXPECT_EQ(p.torque().left, -0.5);
  EXPECT_EQ(answer(p, 1), Answer::kStep);
  EXPECT_EQ(p.awaited(), 2);
  EXPECT_EQ(p.late() + p.repeats() + p.nonFinite(), 0);
}

TEST(Lockstep, LostMessageIsReSentAfterRetry) {
  LockstepProtocol p = started(-1, timing(0.5), 0.0);  // state 0 (or its answer) is lost on the way
  EXPECT_FALSE(p.tick(0.49, true).resend);
  LockstepProtocol::Supervision s = p.tick(0.5, true);
  EXPECT_TRUE(s.resend);
  EXPECT_EQ(s.step, 0);
  EXPECT_FALSE(s.report);
  EXPECT_FALSE(p.tick(0.99, true).resend);  // every retry, not every tick
  EXPECT_TRUE(p.tick(1.0, true).resend);
  EXPECT_EQ(answer(p, 0), Answer::kStep);   // the re-sent state is answered
  EXPECT_FALSE(p.tick(1.01, true).resend);  // a new state: its own wait begins
  EXPECT_FALSE(p.tick(1.5, true).resend);
  const LockstepProtocol::Supervision again = p.tick(1.52, true);
  EXPECT_TRUE(again.resend);
  EXPECT_EQ(again.step, 1);
}

TEST(Lockstep, RepeatedStampIsAnsweredOnceNotSteppedTwice) {
  LockstepProtocol p = started();
  EXPECT_EQ(answer(p, 0, 1.0, 1.0), Answer::kStep);
  // The state was re-sent and the controller answered both: the second answer is no new step.
  EXPECT_EQ(answer(p, 0, 1.0, 1.0), Answer::kRepeat);
  EXPECT_EQ(p.awaited(), 1);
  EXPECT_EQ(p.repeats(), 1);
  EXPECT_EQ(p.late(), 0);
  EXPECT_EQ(answer(p, 1), Answer::kStep);
  EXPECT_EQ(p.awaited(), 2);
}

TEST(Lockstep, LateAndEarlyTorquesAreIgnored) {
  LockstepProtocol p = started();
  for (int k = 0; k < 5; ++k) ASSERT_EQ(answer(p, k), Answer::kStep);
  EXPECT_EQ(answer(p, 2, 9.0, 9.0), Answer::kLate);  // an old answer (a stray or restarted source)
  EXPECT_EQ(p.late(), 1);
  EXPECT_EQ(answer(p, 6), Answer::kAhead);                                 // for a state never published
  EXPECT_EQ(p.onTorque(5 * kPeriod + 1, WheelTorques{}), Answer::kAhead);  // off the grid
  EXPECT_EQ(p.onTorque(5 * kPeriod - 1, WheelTorques{}), Answer::kLate);
  EXPECT_EQ(p.awaited(), 5);
  EXPECT_EQ(p.torque().right, 1.0);  // the torque of the last step, not the ignored ones
  EXPECT_EQ(answer(p, 5), Answer::kStep);
}

TEST(Lockstep, NonFiniteTorqueNeverSteps) {
  LockstepProtocol p = started();
  EXPECT_EQ(answer(p, 0, std::numeric_limits<double>::quiet_NaN(), 0.0), Answer::kNonFinite);
  EXPECT_EQ(answer(p, 0, 0.0, std::numeric_limits<double>::infinity()), Answer::kNonFinite);
  EXPECT_EQ(p.nonFinite(), 2);
  EXPECT_EQ(p.awaited(), 0);
  EXPECT_EQ(answer(p, 0), Answer::kStep);  // a finite answer still steps
}

TEST(Lockstep, LateSubscriberIsSentTheStateAgainAndTheRunGoesOn) {
  // The restart race: the controller dies after answering state 2; its successor subscribes late and
  // has missed state 3. The plant must neither skip nor give up: it re-sends state 3 until answered.
  LockstepProtocol p = started(-1, timing(0.5, 1.5, 120.0), 0.0);
  for (int k = 0; k < 3; ++k) ASSERT_EQ(answer(p, k), Answer::kStep);
  p.tick(0.01, true);  // the supervisor sees the step to state 3
  int resent = 0;
  for (double t = 0.02; t < 4.0; t += 0.01) {
    const LockstepProtocol::Supervision s = p.tick(t, true);
    if (s.resend) {
      EXPECT_EQ(s.step, 3);
      ++resent;
    }
    EXPECT_FALSE(s.give_up);
  }
  EXPECT_GE(resent, 7);
  EXPECT_LE(resent, 8);
  EXPECT_EQ(answer(p, 3), Answer::kStep);  // the successor answers the re-sent state
  EXPECT_EQ(p.phase(), Phase::kRunning);
  EXPECT_EQ(p.tick(4.0, true).step, -1);  // the supervisor sees the progress: a new wait begins
  EXPECT_FALSE(p.tick(4.4, true).resend);
  EXPECT_FALSE(p.tick(5.4, true).report);
  EXPECT_EQ(answer(p, 4), Answer::kStep);
  EXPECT_EQ(p.awaited(), 5);
}

TEST(Lockstep, StallIsReportedEveryTimeoutWithTheTimeWaited) {
  LockstepProtocol p = started(-1, timing(0.5, 5.0, 120.0), 100.0);
  ASSERT_EQ(answer(p, 0), Answer::kStep);
  p.tick(100.0, true);  // state 1 out at 100 s; its answer never comes
  std::vector<double> reports;
  for (int i = 1; i <= 1600; ++i) {  // 16 s in 10 ms ticks
    const LockstepProtocol::Supervision s = p.tick(100.0 + 0.01 * i, true);
    if (s.report) {
      EXPECT_EQ(s.step, 1);
      reports.push_back(s.waited);
    }
  }
  ASSERT_EQ(reports.size(), 3u);
  EXPECT_NEAR(reports[0], 5.0, 0.011);
  EXPECT_NEAR(reports[1], 10.0, 0.021);
  EXPECT_NEAR(reports[2], 15.0, 0.031);
}

TEST(Lockstep, GivesUpAfterGiveUp) {
  LockstepProtocol p = started(-1, timing(0.5, 1.5, 3.0), 0.0);
  ASSERT_EQ(answer(p, 0), Answer::kStep);
  ASSERT_EQ(answer(p, 1), Answer::kStep);
  p.tick(1.0, true);  // state 2 awaited from 1 s
  EXPECT_FALSE(p.tick(4.0, true).give_up);
  const LockstepProtocol::Supervision s = p.tick(4.01, true);
  EXPECT_TRUE(s.give_up);
  EXPECT_EQ(s.step, 2);
  EXPECT_NEAR(s.waited, 3.01, 1e-9);
  EXPECT_TRUE(p.over());
  EXPECT_EQ(answer(p, 2), Answer::kNotRunning);  // an answer after the give-up steps nothing
  const LockstepProtocol::Supervision after = p.tick(5.0, true);
  EXPECT_FALSE(after.resend || after.report || after.give_up || after.start);
}

TEST(Lockstep, ZeroGiveUpWaitsForever) {
  LockstepProtocol p = started(-1, timing(0.5, 5.0, 0.0), 0.0);
  EXPECT_FALSE(p.tick(1e6, true).give_up);
  EXPECT_TRUE(p.tick(2e6, true).report);
  EXPECT_EQ(p.phase(), Phase::kRunning);
  EXPECT_EQ(answer(p, 0), Answer::kStep);
  LockstepProtocol q(kPeriod, -1, timing(0.5, 5.0, 0.0));  // nor before step 0
  q.tick(0.0, false);
  EXPECT_FALSE(q.tick(1e6, false).give_up);
  EXPECT_EQ(q.phase(), Phase::kConnecting);
}

TEST(Lockstep, EndsWithTheAnswerForTheFinalState) {
  LockstepProtocol p = started(2);
  EXPECT_EQ(answer(p, 0), Answer::kStep);
  EXPECT_EQ(answer(p, 1), Answer::kStep);
  EXPECT_EQ(p.awaited(), 2);
  EXPECT_EQ(answer(p, 2, 7.0, 7.0), Answer::kFinish);  // not stepped: state 2 is the last one
  EXPECT_EQ(p.phase(), Phase::kFinished);
  EXPECT_TRUE(p.over());
  EXPECT_EQ(p.torque().right, 1.0);
  EXPECT_EQ(answer(p, 2), Answer::kRepeat);
  EXPECT_EQ(answer(p, 3), Answer::kNotRunning);
  const LockstepProtocol::Supervision s = p.tick(1000.0, true);
  EXPECT_FALSE(s.resend || s.report || s.give_up);
}

TEST(Lockstep, ADivergedRunStepsNothingMore) {
  LockstepProtocol p = started();
  ASSERT_EQ(answer(p, 0), Answer::kStep);
  p.diverged();  // the caller stepped and found the state bad
  EXPECT_TRUE(p.over());
  EXPECT_EQ(answer(p, 1), Answer::kNotRunning);
  const LockstepProtocol::Supervision s = p.tick(1000.0, true);
  EXPECT_FALSE(s.resend || s.report || s.give_up);  // the diverged state is never re-sent
}
