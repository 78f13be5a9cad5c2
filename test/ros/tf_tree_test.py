#!/usr/bin/env python3
"""rostest: odom->base_link comes from plant_sim and the wheel transforms from robot_state_publisher,
which proves the URDF loaded and joint_states flow."""
import unittest

import rospy
import rostest
from tf2_msgs.msg import TFMessage


class TfTree(unittest.TestCase):
    def test_odom_base_link_and_wheels(self):
        rospy.init_node("tf_tree_test")
        seen = set()

        def on_tf(msg):
            for t in msg.transforms:
                seen.add((t.header.frame_id.lstrip("/"), t.child_frame_id.lstrip("/")))

        rospy.Subscriber("/tf", TFMessage, on_tf)
        rospy.Subscriber("/tf_static", TFMessage, on_tf)
        wanted = {("odom", "base_link"), ("base_link", "right_wheel"), ("base_link", "left_wheel")}
        deadline = rospy.Time.now() + rospy.Duration(30.0)
        while not rospy.is_shutdown() and not wanted <= seen and rospy.Time.now() < deadline:
            rospy.sleep(0.1)
        self.assertTrue(wanted <= seen, "missing transforms: %s (seen %s)" % (wanted - seen, sorted(seen)))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "tf_tree_test", TfTree)
