// StampPair: the pairing by stamp that makes lockstep exact, including references that arrive up to
// the reference generator's lookahead ahead of the state.
#include <gtest/gtest.h>

#include "sowing_robot/ros/common/stamp_pair.h"

using sowing_robot::StampPair;

namespace {
struct Msg {
  struct {
    ros::Time stamp;
  } header;
  int tag = 0;
};
Msg at(double t, int tag = 0) {
  Msg m;
  m.header.stamp = ros::Time(t);
  m.tag = tag;
  return m;
}
}  // namespace

TEST(StampPair, PairsEqualStampsInEitherOrder) {
  StampPair<Msg, Msg> p;
  EXPECT_FALSE(p.any());
  EXPECT_FALSE(p.setFirst(at(1.0, 1)));
  EXPECT_TRUE(p.setSecond(at(1.0, 2)));
  EXPECT_EQ(p.first().tag, 1);
  EXPECT_EQ(p.second().tag, 2);
  EXPECT_EQ(p.lastStamp(), ros::Time(1.0));
  EXPECT_FALSE(p.setSecond(at(2.0, 3)));
  EXPECT_TRUE(p.setFirst(at(2.0, 4)));
  EXPECT_EQ(p.first().tag, 4);
  EXPECT_EQ(p.second().tag, 3);
}

TEST(StampPair, NeverHandsOutAStampTwiceOrGoesBack) {
  StampPair<Msg, Msg> p;
  p.setFirst(at(2.0));
  ASSERT_TRUE(p.setSecond(at(2.0)));
  EXPECT_TRUE(p.isRepeat(ros::Time(2.0)));
  EXPECT_FALSE(p.setFirst(at(2.0)));   // a repeat of the same state
  EXPECT_FALSE(p.setSecond(at(1.0)));  // an old message
  EXPECT_FALSE(p.setFirst(at(1.0)));
  EXPECT_EQ(p.lastStamp(), ros::Time(2.0));
}

TEST(StampPair, FindsTheStateStampAmongAReferenceAheadOfIt) {
  // Lookahead: references for t_k and t_{k+1} are both in when the state for t_k arrives.
  StampPair<Msg, Msg> p;
  for (int k = 0; k < 5; ++k) {
    if (k == 0) EXPECT_FALSE(p.setSecond(at(0.0, 100)));
    EXPECT_FALSE(p.setSecond(at(0.001 * (k + 1), 101 + k)));  // the one ahead: no state yet
    ASSERT_TRUE(p.setFirst(at(0.001 * k, k))) << k;           // the state for t_k pairs with ref t_k
    EXPECT_EQ(p.first().tag, k);
    EXPECT_EQ(p.second().tag, 100 + k);
  }
}

TEST(StampPair, PairsTheNewestCommonStamp) {
  StampPair<Msg, Msg> p;
  p.setFirst(at(1.0, 1));
  p.setFirst(at(2.0, 2));
  p.setSecond(at(3.0, 3));
  EXPECT_TRUE(p.setSecond(at(2.0, 4)));
  EXPECT_EQ(p.first().tag, 2);
  EXPECT_EQ(p.second().tag, 4);
  EXPECT_FALSE(p.setSecond(at(1.0, 5)));  // 1.0 is older than the pair handed out
}

TEST(StampPair, HoldsAWholeLookaheadWindowAndPairsEveryStateInTurn) {
  // The generator sends references in bursts, up to 60 periods ahead of the state: every state must
  // find its own reference, and the references it has passed must not pile up.
  StampPair<Msg, Msg> p;
  int next_ref = 0;
  for (int k = 0; k < 1000; ++k) {
    if (k % 10 == 0)
      for (; next_ref <= k + 60; ++next_ref) EXPECT_FALSE(p.setSecond(at(0.001 * next_ref, next_ref)));
    ASSERT_TRUE(p.setFirst(at(0.001 * k, -k))) << k;
    EXPECT_EQ(p.first().tag, -k);
    EXPECT_EQ(p.second().tag, k);
    EXPECT_LE(p.heldSeconds(), 62u);
  }
}

TEST(StampPair, CapsEachStreamDroppingTheOldest) {
  // No reference ever comes (generator dead): states are kept only up to the first stream's cap.
  StampPair<Msg, Msg, 4, 16> p;
  for (int k = 0; k < 100; ++k) EXPECT_FALSE(p.setFirst(at(0.001 * k, k)));
  EXPECT_EQ(p.heldFirsts(), 4u);
  EXPECT_TRUE(p.setSecond(at(0.099, 1)));   // the newest state is still there
  EXPECT_FALSE(p.setSecond(at(0.050, 2)));  // an old one is not
  for (int k = 0; k < 100; ++k) p.setSecond(at(1.0 + 0.001 * k, k));
  EXPECT_EQ(p.heldSeconds(), 16u);
}

TEST(StampPair, TellsAGridMismatchFromAReferenceOnItsWay) {
  StampPair<Msg, Msg> p;
  p.setSecond(at(0.002));
  EXPECT_FALSE(p.setFirst(at(0.001)));
  EXPECT_TRUE(p.secondsPassed(ros::Time(0.001)));   // a newer reference, none for 0.001: off grid
  EXPECT_FALSE(p.secondsPassed(ros::Time(0.002)));  // nothing newer: still on its way
}

TEST(StampPair, HoldsStatesThatRunAheadOfTheirReferences) {
  // A listener the plant does not wait for (run_monitor, seed_drill): the states of many periods can
  // come before the first of their references. Every one must still pair, in turn, and none be lost.
  sowing_robot::ListenerPair<Msg, Msg> p;
  for (int k = 0; k < 500; ++k) EXPECT_FALSE(p.setFirst(at(0.001 * k, k)));
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(p.setSecond(at(0.001 * k, -k))) << k;
    EXPECT_EQ(p.first().tag, k);
    EXPECT_EQ(p.second().tag, -k);
  }
  EXPECT_EQ(p.dropped(), 0u);
  EXPECT_EQ(p.heldFirsts(), 1u);  // the last pair's, until the next call
}

TEST(StampPair, CountsWhatAFullStreamDrops) {
  StampPair<Msg, Msg, 4, 16> p;
  for (int k = 0; k < 10; ++k) p.setFirst(at(0.001 * k, k));
  EXPECT_EQ(p.dropped(), 6u);
  EXPECT_TRUE(p.setSecond(at(0.009)));
  for (int k = 10; k < 13; ++k) p.setFirst(at(0.001 * k, k));  // room again after the pair: none dropped
  EXPECT_EQ(p.dropped(), 6u);
}
