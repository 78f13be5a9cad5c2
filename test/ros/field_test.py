#!/usr/bin/env python3
"""rostest (lockstep field run): follows the robot to the end of the scenario and checks its smallest
clearance from every obstacle surface (axle midpoint; obstacles from /reference_generator/obstacles),
that it ends near (end_x, end_y), and the seed drill's cross-track report for seeds away from obstacles."""
import math
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64MultiArray


class FieldRun(unittest.TestCase):
    def test_field(self):
        rospy.init_node("field_test")
        duration = rospy.get_param("~duration")
        margin = rospy.get_param("~safety_margin")
        obstacles = rospy.get_param("/reference_generator/obstacles", [])
        state = {"min_clear": float("inf"), "last": None, "report": None}

        def on_odom(m):
            p = m.pose.pose.position
            for o in obstacles:
                c = math.hypot(p.x - o["x"], p.y - o["y"]) - o.get("radius", 0.3)
                state["min_clear"] = min(state["min_clear"], c)
            state["last"] = m

        rospy.Subscriber("odom", Odometry, on_odom, queue_size=100000)
        rospy.Subscriber("seed_report", Float64MultiArray, lambda m: state.update(report=m.data), queue_size=10)
        t0 = time.time()
        while not rospy.is_shutdown():
            last = state["last"]
            if last is not None and last.header.stamp.to_sec() >= duration - 1e-6:
                break
            self.assertLess(time.time() - t0, 360.0, "the run did not reach t = %.1f s" % duration)
            time.sleep(0.05)
        time.sleep(1.0)  # the drill's last report
        p = state["last"].pose.pose.position
        rows_count, rows_max, rows_rms, rows_over, det_count, det_max, det_rms = state["report"]
        print("field: min clearance %.3f m, end (%.3f, %.3f), seeds on rows %d (max %.4f m, RMS %.4f m, "
              "%.1f %% over tolerance), detour seeds %d (max %.3f m)" %
              (state["min_clear"], p.x, p.y, rows_count, rows_max, rows_rms, 100 * rows_over, det_count, det_max))
        if obstacles:
            self.assertGreater(state["min_clear"], margin)
        self.assertLess(math.hypot(p.x - rospy.get_param("~end_x"), p.y - rospy.get_param("~end_y")), 1.0)
        self.assertGreaterEqual(rows_count, rospy.get_param("~min_row_seeds"))
        self.assertLess(rows_max, rospy.get_param("~max_row_error"))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "field_test", FieldRun)
