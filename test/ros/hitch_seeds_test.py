#!/usr/bin/env python3
"""rostest (hitch_seeds.test): the seed drill node follows the hitch. Every seed the node drops (its `seeds`
marker is stamped with the state the seed fell at) must be at a stamp whose wheel_torque did not raise the tool
(WheelTorque/tool_raised); and the run must hold the tool up while the reference sows over at least 0.2 m of
travel (twice the seed spacing), so the check is not empty.

Fails without what it protects: a seed drill that sows on the reference's tool_down alone (seed_drill/follow_hitch
false) drops seeds where the hitch held the tool up."""
import math
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sowing_robot.msg import ReferenceState, WheelTorque
from visualization_msgs.msg import MarkerArray

import links

WALL_TIMEOUT = 240.0


class HitchSeeds(unittest.TestCase):
    def test_no_seed_while_the_hitch_holds_the_tool_up(self):
        rospy.init_node("hitch_seeds_test")
        duration = rospy.get_param("/run/duration")
        lock = threading.Lock()
        truth, raised, sowing, seeds = {}, {}, {}, []

        def on_truth(m):
            with lock:
                truth[m.header.stamp.to_nsec()] = (m.pose.pose.position.x, m.pose.pose.position.y)

        def on_torque(m):
            with lock:
                raised[m.header.stamp.to_nsec()] = m.tool_raised

        def on_reference(m):
            with lock:
                sowing[m.header.stamp.to_nsec()] = m.tool_down

        def on_seeds(m):
            with lock:
                seeds.extend(marker.header.stamp.to_nsec() for marker in m.markers)

        # Linked as their publishers see it before the run can start (links.py), then the plant-counted topics.
        subs = [rospy.Subscriber("wheel_torque", WheelTorque, on_torque, queue_size=100000),
                rospy.Subscriber("seeds", MarkerArray, on_seeds, queue_size=100000),
                rospy.Subscriber("reference", ReferenceState, on_reference, queue_size=100000)]
        self.assertIsNone(links.wait_until_linked(["wheel_torque", "seeds", "reference"], WALL_TIMEOUT))
        subs += [rospy.Subscriber("ground_truth", Odometry, on_truth, queue_size=100000),
                 rospy.Subscriber("odom", Odometry, lambda m: None, queue_size=10)]
        end = int(round(duration * 1e9))
        deadline = time.time() + WALL_TIMEOUT

        def complete():  # the run's end reached, and every seed's hitch command here
            with lock:
                return end in truth and all(s in raised for s in seeds)

        while not complete():
            self.assertLess(time.time(), deadline, "the run did not end, or a seed's wheel_torque never came")
            time.sleep(0.05)
        for s in subs:
            s.unregister()
        with lock:
            held = [k for k in sorted(raised) if raised[k] and sowing.get(k, False) and k in truth]
            travel = 0.0
            for k in held:
                prev = truth.get(k - 1000000)  # 1 kHz: the state one period before
                if prev is not None:
                    travel += math.hypot(truth[k][0] - prev[0], truth[k][1] - prev[1])
            at_raised = [s for s in seeds if raised[s]]
            print("hitch_seeds: %d seeds, %d periods held up where the reference sows (%.3f m of travel), "
                  "%d seeds there" % (len(seeds), len(held), travel, len(at_raised)))
            self.assertGreater(travel, 0.2, "the hitch never held the tool up over a sown stretch: nothing checked")
            self.assertEqual(at_raised, [], "seeds dropped while the hitch held the tool up")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "hitch_seeds", HitchSeeds)
