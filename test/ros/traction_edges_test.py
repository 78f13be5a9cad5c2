#!/usr/bin/env python3
"""rostest (lockstep, traction on ice with a 500 N draft): the run reaches its end (odom stamped at
~duration, waited for with a bounded timeout), every odom and wheel_slip message is finite, the tool
was down (the draft acted), and the torque controller reported saturation."""
import math
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sowing_robot.msg import TorqueControllerState
from std_msgs.msg import Float64MultiArray

WALL_TIMEOUT = 240.0  # [s wall]


class TractionEdges(unittest.TestCase):
    def test_ice_and_draft_end_finite_and_saturated(self):
        rospy.init_node("traction_edges_test")
        duration = rospy.get_param("~duration")
        done = threading.Event()
        seen = {"odom": 0, "bad_odom": 0, "slip": 0, "bad_slip": 0, "tool_down": 0, "saturated": 0, "last": 0.0}
        lock = threading.Lock()

        def on_odom(m):
            p, t = m.pose.pose.position, m.twist.twist
            with lock:
                seen["odom"] += 1
                if not all(math.isfinite(v) for v in (p.x, p.y, t.linear.x, t.angular.z)):
                    seen["bad_odom"] += 1
                seen["last"] = m.header.stamp.to_sec()
            if m.header.stamp.to_sec() >= duration - 1e-6:
                done.set()

        def on_slip(m):
            with lock:
                seen["slip"] += 1
                if not all(math.isfinite(v) for v in m.data):
                    seen["bad_slip"] += 1
                if len(m.data) >= 6 and m.data[5] > 0.5:
                    seen["tool_down"] += 1

        def on_state(m):
            if m.saturated:
                with lock:
                    seen["saturated"] += 1

        subs = [rospy.Subscriber("ground_truth", Odometry, on_odom, queue_size=20000, tcp_nodelay=True),
                rospy.Subscriber("wheel_slip", Float64MultiArray, on_slip, queue_size=1000),
                rospy.Subscriber("torque_controller/state", TorqueControllerState, on_state, queue_size=20000)]
        self.assertTrue(done.wait(WALL_TIMEOUT), "the run did not reach t = %g s: %s" % (duration, seen))
        for s in subs:
            s.unregister()
        self.assertEqual(seen["bad_odom"], 0, seen)
        self.assertEqual(seen["bad_slip"], 0, seen)
        self.assertGreater(seen["slip"], 10, seen)
        self.assertGreater(seen["tool_down"], 0, "the draft never acted: %s" % seen)
        self.assertGreater(seen["saturated"], 0, "no saturation reported: %s" % seen)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "traction_edges_test", TractionEdges)
