#!/usr/bin/env python3
"""rostest: plant_sim takes step 0 only when every node of its wait_for list has announced itself on the
latched topic /ready (ros/common/ready_roster.h), however long that takes, and says whom it waits for.

The fixture's plant_sim waits for the three loop nodes and for "ghost", a name only this test announces.
While ghost is missing the loop is complete by subscriber counts, so without the roster the plant would
start at once: the test would see /clock move past 0 in its first seconds (verified: with roster_.complete()
removed from LockstepDriver::loopConnected test_waits_for_every_name fails on the first assertion).
With the roster nothing can move, so the quiet window is not a race: it only bounds how long we look."""
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock, Log
from std_msgs.msg import String

QUIET = 3.0         # [s wall] watched for a step that must not come
WALL_LIMIT = 60.0   # [s wall] for anything that takes a second on an idle machine


class ReadyHandshake(unittest.TestCase):
    def test_waits_for_every_name(self):
        rospy.init_node("ready_handshake_test")
        latest = {"clock": 0.0, "warned": ""}
        rospy.Subscriber("/clock", Clock, lambda m: latest.__setitem__("clock", max(latest["clock"], m.clock.to_sec())))

        def on_log(m):
            if m.name.endswith("plant_sim") and "not announced on ready" in m.msg:
                latest["warned"] = m.msg
        rospy.Subscriber("/rosout", Log, on_log)

        deadline = time.time() + WALL_LIMIT
        while not latest["warned"] and time.time() < deadline:
            time.sleep(0.05)
        self.assertIn("not announced on ready: ghost", latest["warned"])
        # The loop nodes have announced (only ghost is named as missing), yet nothing is stepped.
        end = time.time() + QUIET
        while time.time() < end:
            self.assertEqual(latest["clock"], 0.0, "plant_sim stepped before ghost announced")
            time.sleep(0.05)

        ghost = rospy.Publisher("/ready", String, queue_size=1, latch=True)
        ghost.publish(String(data="ghost"))
        deadline = time.time() + WALL_LIMIT
        while latest["clock"] < 1.0 and time.time() < deadline:
            time.sleep(0.05)
        self.assertGreaterEqual(latest["clock"], 1.0, "plant_sim did not start once ghost announced")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "ready_handshake", ReadyHandshake)
