#!/usr/bin/env python3
"""rostest (lockstep field run, stop_hold.test): the plan ends short of an obstacle at the row's end, the
reference comes to rest there; from `settle` after that to the end of the run (at least `min_hold`) the
robot's |v| and |omega| on ground_truth stay within `still`, the reference says stop (ReferenceState.stop)
and torque_controller reports its standstill hold (TorqueControllerState.holding).

Verified to fail without the hold: with the reference's stop flag left false (FieldReference::evaluate) the
robot rocks about the stop point (docs/stops.md)."""
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sowing_robot.msg import ReferenceState, TorqueControllerState


class StopHold(unittest.TestCase):
    def test_stop_holds(self):
        rospy.init_node("stop_hold_test")
        duration = rospy.get_param("~duration")
        settle = rospy.get_param("~settle")
        min_hold = rospy.get_param("~min_hold")
        still = rospy.get_param("~still")
        state = {"stop": None, "flag": False, "moving": False, "last": None, "v": 0.0, "w": 0.0, "holding": 0,
                 "samples": 0}

        def on_reference(m):
            # the plan's stop: the reference at rest after it has moved
            state["moving"] = state["moving"] or m.v > 0.5
            if state["moving"] and m.v < 1e-9 and state["stop"] is None:
                state["stop"] = m.header.stamp.to_sec()
            state["flag"] = state["flag"] or m.stop

        def on_odom(m):
            t = m.header.stamp.to_sec()
            state["last"] = t
            if state["stop"] is not None and t >= state["stop"] + settle:
                state["v"] = max(state["v"], abs(m.twist.twist.linear.x))
                state["w"] = max(state["w"], abs(m.twist.twist.angular.z))
                state["samples"] += 1

        rospy.Subscriber("reference", ReferenceState, on_reference, queue_size=100000)
        rospy.Subscriber("ground_truth", Odometry, on_odom, queue_size=100000)
        rospy.Subscriber("torque_controller/state", TorqueControllerState,
                         lambda m: state.update(holding=state["holding"] + bool(m.holding)), queue_size=100000)
        t0 = time.time()
        while not rospy.is_shutdown():
            if state["last"] is not None and state["last"] >= duration - 1e-6:
                break
            self.assertLess(time.time() - t0, 360.0, "the run did not reach t = %.1f s" % duration)
            time.sleep(0.05)
        print("stop_hold: the reference stopped at t = %s s; from %.1f s later to t = %.3f s: max |v| %.5f m/s, "
              "max |omega| %.5f rad/s over %d states; %d holding periods" %
              (state["stop"], settle, state["last"], state["v"], state["w"], state["samples"], state["holding"]))
        self.assertIsNotNone(state["stop"], "the reference never came to rest")
        self.assertGreaterEqual(state["last"] - state["stop"] - settle, min_hold)
        self.assertLessEqual(state["v"], still)
        self.assertLessEqual(state["w"], still)
        self.assertTrue(state["flag"], "the reference never said stop")
        self.assertGreater(state["holding"], 0, "torque_controller never reported its hold")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "stop_hold_test", StopHold)
