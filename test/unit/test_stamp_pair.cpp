// StampPair: the pairing by stamp that makes lockstep exact, including a reference that arrives one
// period ahead of the state (the reference generator's lookahead).
#include <gtest/gtest.h>

#include "sowing_robot/ros/stamp_pair.h"

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
    ASSERT_TRUE(p.setFirst(at(0.001 * k, k))) << k;            // the state for t_k pairs with ref t_k
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
