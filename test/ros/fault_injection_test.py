#!/usr/bin/env python3
"""rostest (realtime pipeline): inject NaN wheel torques and NaN references, then kill the torque
controller for 1 s of simulated time and start it again. Checks: odom stays finite throughout, the
plant, kinematic controller and plant timeout each log their warning, the robot coasts (zero torque
applied) while the controller is away, and it is back on the line (|e_y| < 3 cm) at the end."""
import math
import subprocess
import time
import unittest

import roslib.packages
import rosnode
import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sowing_robot.msg import ReferenceState, TrackingError, WheelTorque


class FaultInjection(unittest.TestCase):
    def setUp(self):
        rospy.init_node("fault_injection_test")
        self.nonfinite_odom = 0
        self.odom_count = 0
        self.last_error = None
        self.logs = []
        rospy.Subscriber("ground_truth", Odometry, self.on_odom, queue_size=1000)
        rospy.Subscriber("tracking_error", TrackingError, self.on_error, queue_size=1000)
        rospy.Subscriber("/rosout", Log, lambda m: self.logs.append((m.name, m.level, m.msg)), queue_size=1000)
        self.torque_pub = rospy.Publisher("wheel_torque", WheelTorque, queue_size=100)
        self.ref_pub = rospy.Publisher("reference", ReferenceState, queue_size=100)
        self.restarted = None

    def tearDown(self):
        if self.restarted is not None and self.restarted.poll() is None:
            self.restarted.terminate()
            self.restarted.wait(10)

    def on_odom(self, m):
        self.odom_count += 1
        p, t = m.pose.pose, m.twist.twist
        if not all(math.isfinite(v) for v in (p.position.x, p.position.y, p.orientation.z, p.orientation.w,
                                               t.linear.x, t.angular.z)):
            self.nonfinite_odom += 1

    def on_error(self, m):
        self.last_error = m

    def wait_until(self, t_sim, wall_limit=120.0):
        """Wait for simulated time t_sim, failing if it stops advancing for wall_limit wall seconds."""
        t0 = time.time()
        while not rospy.is_shutdown() and rospy.get_rostime().to_sec() < t_sim:
            self.assertLess(time.time() - t0, wall_limit, "simulated time stuck at %.3f" %
                            rospy.get_rostime().to_sec())
            time.sleep(0.02)

    def logged(self, node, text):
        return any(n.endswith(node) and text in msg for n, _, msg in self.logs)

    def test_faults(self):
        self.wait_until(6.0)
        # 1. NaN torques and NaN references for 0.5 s.
        nan = float("nan")
        for _ in range(50):
            t = WheelTorque()
            t.header.stamp = rospy.get_rostime()
            t.right, t.left = nan, float("inf")
            self.torque_pub.publish(t)
            r = ReferenceState()
            r.header.stamp = rospy.get_rostime()
            r.x, r.y = nan, 3.0
            self.ref_pub.publish(r)
            rospy.sleep(0.01)
        self.wait_until(8.0)
        self.assertEqual(self.nonfinite_odom, 0)
        self.assertTrue(self.logged("plant_sim", "non-finite wheel torque"), "plant_sim did not warn")
        self.assertTrue(self.logged("kinematic_controller", "non-finite reference"),
                        "kinematic_controller did not warn")

        # 2. Kill the torque controller, wait 1 s of simulated time, start it again.
        self.assertTrue(self.last_error is not None and abs(self.last_error.y) < 0.05,
                        "not on the line before the outage: %s" % self.last_error)
        rosnode.kill_nodes(["/torque_controller"])
        t_kill = rospy.get_rostime().to_sec()
        self.wait_until(t_kill + 1.0)
        self.assertTrue(self.logged("plant_sim", "applying zero torque"), "plant_sim did not report the silence")
        exe = roslib.packages.find_node("sowing_robot", "torque_controller")[0]
        self.restarted = subprocess.Popen([exe, "__name:=torque_controller"])
        self.wait_until(t_kill + 12.0)
        self.assertEqual(self.nonfinite_odom, 0)
        self.assertLess(abs(self.last_error.y), 0.03, "did not re-converge: %s" % self.last_error)
        self.assertLess(abs(self.last_error.theta), 0.05, "did not re-converge: %s" % self.last_error)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "fault_injection_test", FaultInjection)
