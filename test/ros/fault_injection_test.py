#!/usr/bin/env python3
"""rostest (realtime pipeline): inject NaN wheel torques and NaN references, then kill the torque
controller for 1 s of simulated time and start it again. Checks: the state (ground_truth) stays finite throughout, the
plant, kinematic controller and plant timeout each log their warning, the robot coasts (zero torque
applied) while the controller is away, and it is back on the line (|e_y| < 3 cm) 6 s of simulated time
after the restarted controller's first torque.

Every verdict is on simulated time or on an event waited for: the wall clock only bounds a hang
(WALL_LIMIT). The restart's start-up takes wall time, which passes as simulated time in realtime, so the
re-convergence is timed from the controller's return (its first wheel_torque), not from the kill.
fault_overlay.yaml runs the plant at a quarter of the wall clock so that the loop keeps up on a loaded
machine."""
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

WALL_LIMIT = 120.0  # [s wall] bounds a hang only: anything waited for comes in a few seconds on an idle machine
# [s sim] from the restarted controller's first torque to the check that it is back on the line. The outage leaves
# |e_y| ~0.5 m and |e_theta| ~0.3 rad; 0.5, 1, 2, 3, 5 s after the return e_y was -0.49, -0.50, -0.31, -0.16,
# -0.010 m and e_theta 0.021 rad at 5 s (10 s: 3 mm), so 6 s leaves the checks' bounds (3 cm, 0.05 rad) their margin.
SETTLE = 6.0
# [s sim] the NaNs; the torque controller is killed 2 s later. The robot starts on the line (fault_injection.test),
# so it is there from the start: waiting 6 s, as for the thesis's approach from 3 m beside it, judged nothing more.
FAULTS_AT = 2.0


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
        self.torques = []  # stamps of wheel_torque from the launch's and the restarted torque controller
        rospy.Subscriber("wheel_torque", WheelTorque, self.on_torque, queue_size=1000)

    def on_torque(self, m):
        if m.header.stamp.to_sec() > 0.0 and math.isfinite(m.right) and math.isfinite(m.left):
            self.torques.append(m.header.stamp.to_sec())

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

    def wait_until(self, t_sim, wall_limit=WALL_LIMIT):
        """Wait for simulated time t_sim, failing if it has not come after wall_limit wall seconds (a hang)."""
        t0 = time.time()
        while not rospy.is_shutdown() and rospy.get_rostime().to_sec() < t_sim:
            self.assertLess(time.time() - t0, wall_limit, "simulated time stuck at %.3f" %
                            rospy.get_rostime().to_sec())
            time.sleep(0.02)

    def wait_for(self, condition, what):
        """Wait for an event; the wall limit only bounds a hang."""
        deadline = time.time() + WALL_LIMIT
        while not condition():
            self.assertFalse(rospy.is_shutdown())
            self.assertLess(time.time(), deadline, "no %s after %.0f s wall" % (what, WALL_LIMIT))
            time.sleep(0.02)

    def logged(self, node, text):
        return any(n.endswith(node) and text in msg for n, _, msg in list(self.logs))

    def error_since(self, t_sim):
        """The newest tracking error if it is stamped t_sim or later."""
        e = self.last_error
        return e if e is not None and e.header.stamp.to_sec() >= t_sim else None

    def test_faults(self):
        outage = FAULTS_AT + 2.0  # the torque controller's kill
        self.wait_until(FAULTS_AT)
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
        self.wait_until(outage)
        # the warnings travel through /rosout: waited for, not read at a moment
        self.wait_for(lambda: self.logged("plant_sim", "non-finite wheel torque"), "warning from plant_sim")
        self.wait_for(lambda: self.logged("kinematic_controller", "non-finite reference"),
                      "warning from kinematic_controller")
        self.assertEqual(self.nonfinite_odom, 0)

        # 2. Kill the torque controller, wait 1 s of simulated time, start it again.
        self.wait_for(lambda: self.error_since(outage) is not None, "tracking_error at t = %g s" % outage)
        self.assertLess(abs(self.error_since(outage).y), 0.05, "not on the line before the outage: %s" % self.last_error)
        rosnode.kill_nodes(["/torque_controller"])
        t_kill = rospy.get_rostime().to_sec()
        self.wait_until(t_kill + 1.0)
        self.wait_for(lambda: self.logged("plant_sim", "applying zero torque"), "report of the silence from plant_sim")
        t_restart = rospy.get_rostime().to_sec()
        exe = roslib.packages.find_node("sowing_robot", "torque_controller")[0]
        # with the launch's remap of its feedback (pipeline.launch feedback:=ground_truth)
        self.restarted = subprocess.Popen([exe, "__name:=torque_controller", "feedback:=ground_truth"])
        self.wait_for(lambda: any(t > t_restart for t in list(self.torques)), "wheel_torque from the restarted "
                      "torque_controller")
        t_back = next(t for t in list(self.torques) if t > t_restart)
        self.wait_for(lambda: self.error_since(t_back + SETTLE) is not None,
                      "tracking_error %.0f s after the controller's return" % SETTLE)
        e = self.error_since(t_back + SETTLE)
        print("fault_injection: killed at t = %.3f s, restarted at %.3f s, first torque at %.3f s; at %.3f s e_y "
              "%.4f m, e_theta %.4f rad" % (t_kill, t_restart, t_back, e.header.stamp.to_sec(), e.y, e.theta))
        self.assertEqual(self.nonfinite_odom, 0)
        self.assertLess(abs(e.y), 0.03, "did not re-converge: %s" % e)
        self.assertLess(abs(e.theta), 0.05, "did not re-converge: %s" % e)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "fault_injection_test", FaultInjection)
