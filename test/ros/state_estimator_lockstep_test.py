#!/usr/bin/env python3
"""rostest (state_estimator_lockstep.test): state_estimator in lockstep with fix_source set keeps the plant's
fix schedule (10 Hz from t = 0; estimator/fix/delay 0.15 s) and holds a step until the fixes due by it have
come. Fed by this test, straight along x at 1 kHz:
  * steps 0-160 are sent with no fix: exactly steps 0-149 are answered (the fix measured at 0 s is due by
    step 150), then the fix of 0 s (5 cm to the side) is sent: steps 150-160 are answered, and step 150 holds
    the fix: the step it is due at, not a step after its arrival;
  * steps 161-250 with no fix of 0.1 s: held at 250; the test then sends step 250's odom again (what
    plant_sim does after plant_sim/lockstep_retry): the estimator gives the fix up and answers.
Fails without the wait: step 150 is answered before the fix is sent, without it."""
import time
import unittest

import estimator_feed
import rospy
import rostest

WALL_LIMIT = 60.0
DT = 0.001
V = 0.5


def stamp(k):
    return rospy.Time.from_sec(k * DT) if k else rospy.Time(0)


class StateEstimatorLockstep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("state_estimator_lockstep_test")

    def wait_for(self, condition, what):
        estimator_feed.wait_for(condition, what, WALL_LIMIT)

    def test_waits_for_the_fix_due(self):
        w = estimator_feed.Wiring(WALL_LIMIT)
        out = w.out

        def publish_step(k):
            w.odom.publish(estimator_feed.odom(stamp(k), V * k * DT, V))
            w.imu.publish(estimator_feed.imu(stamp(k)))

        def count(n):
            self.wait_for(lambda: len(out) >= n, lambda: "%d filtered messages (have %d)" % (n, len(out)))

        for k in range(161):
            publish_step(k)
        count(150)
        time.sleep(0.5)  # (only to see an answer that should not come; not a synchronisation)
        self.assertEqual(len(out), 150, "step 150 answered before the fix due by it came")
        w.fix.publish(estimator_feed.fix(stamp(0), 0.0, 0.05))
        count(161)
        self.assertEqual(out[149].pose.pose.position.y, 0.0)
        self.assertGreater(out[150].pose.pose.position.y, 0.01, "the fix is not in the step it is due at")

        for k in range(161, 251):
            publish_step(k)
        count(250)
        time.sleep(0.5)
        self.assertEqual(len(out), 250, "step 250 answered before the fix of 0.1 s came")
        w.odom.publish(estimator_feed.odom(stamp(250), V * 250 * DT, V))  # the plant asks again: the fix is given up
        count(251)
        time.sleep(0.2)  # (only to see a duplicate, were there one)
        w.sub.unregister()
        self.assertEqual([m.header.stamp for m in out], [stamp(k) for k in range(251)])


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "state_estimator_lockstep", StateEstimatorLockstep)
