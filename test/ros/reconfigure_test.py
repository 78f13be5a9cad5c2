#!/usr/bin/env python3
"""rostest: dynamic_reconfigure on both controllers, with the thesis pair and with the baselines (RPP over
the wheel PID, in namespace baseline). A valid change is applied; a change outside the
allowed range is refused and the old value stays in force: a negative gain (which the server clamps to
0, still invalid for the core), NaN (which the server's clamp lets through) and an unknown switching
function."""
import math
import unittest

import rospy
import rostest
from dynamic_reconfigure.client import Client
from rosgraph_msgs.msg import Log


class Reconfigure(unittest.TestCase):
    def setUp(self):
        rospy.init_node("reconfigure_test")
        self.logs = []
        rospy.Subscriber("/rosout", Log, lambda m: self.logs.append((m.name, m.msg)), queue_size=1000)

    def warned(self, node, text):
        deadline = rospy.Time.now() + rospy.Duration(5.0)
        while rospy.Time.now() < deadline:
            if any(n.endswith(node) and text in m for n, m in self.logs):
                return True
            rospy.sleep(0.05)
        return False

    def test_torque_controller(self):
        c = Client("/torque_controller", timeout=30)
        self.assertEqual(c.update_configuration({"k2": 120.0})["k2"], 120.0)
        self.assertEqual(c.update_configuration({"k2": -5.0})["k2"], 120.0)
        self.assertTrue(self.warned("torque_controller", "rejected gain change: k2"))
        self.assertEqual(c.update_configuration({"k1": float("nan")})["k1"], 1.0)
        self.assertEqual(c.update_configuration({"switching": "magic"})["switching"], "sign")
        # The config an update returns is what the node holds after validation.
        cfg = c.update_configuration({"switching": "tanh", "switch_width": 0.05})
        self.assertEqual(cfg["switching"], "tanh")
        self.assertEqual(cfg["k2"], 120.0)
        self.assertEqual(cfg["switch_width"], 0.05)
        self.assertTrue(math.isfinite(cfg["k1"]))

    def test_kinematic_controller(self):
        c = Client("/kinematic_controller", timeout=30)
        self.assertEqual(c.update_configuration({"kx": 2.0})["kx"], 2.0)
        self.assertEqual(c.update_configuration({"ky": 0.0})["ky"], 1.5)
        self.assertTrue(self.warned("kinematic_controller", "rejected gain change: ky"))
        self.assertEqual(c.update_configuration({"ktheta": float("nan")})["ktheta"], 2.2)

    def test_baseline_torque_controller(self):
        c = Client("/baseline/torque_controller", timeout=30)
        self.assertEqual(c.update_configuration({"kp": 7.5})["kp"], 7.5)
        self.assertTrue(self.warned("torque_controller", "gains now kp 7.5"))
        self.assertEqual(c.update_configuration({"max_torque": -1.0})["max_torque"], 100.0)  # clamped to 0: refused
        self.assertEqual(c.update_configuration({"kd": float("nan")})["kd"], 0.0)
        self.assertTrue(self.warned("torque_controller", "rejected gain change: kd"))
        self.assertEqual(c.update_configuration({"feedforward": 0.5})["feedforward"], 0.5)

    def test_baseline_kinematic_controller(self):
        c = Client("/baseline/kinematic_controller", timeout=30)
        self.assertEqual(c.update_configuration({"lookahead_dist": 0.5})["lookahead_dist"], 0.5)
        # outside [min_lookahead_dist, max_lookahead_dist]: refused by PurePursuitParams::validate
        self.assertEqual(c.update_configuration({"lookahead_dist": 2.0})["lookahead_dist"], 0.5)
        self.assertTrue(self.warned("kinematic_controller", "rejected gain change"))
        cfg = c.update_configuration({"regulated_linear_scaling_min_radius": 0.5, "k_along": 1.0})
        self.assertEqual((cfg["regulated_linear_scaling_min_radius"], cfg["k_along"]), (0.5, 1.0))

    def test_reference_generator(self):
        c = Client("/reference_generator/potential", timeout=30)
        self.assertEqual(c.update_configuration({"alpha": 6.0})["alpha"], 6.0)
        self.assertEqual(c.update_configuration({"beta": -1.0})["beta"], 4.0)  # clamped to 0, then refused
        self.assertTrue(self.warned("reference_generator", "rejected gain change"))
        self.assertEqual(c.update_configuration({"gain": float("nan")})["gain"], 5.0)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "reconfigure_test", Reconfigure)
