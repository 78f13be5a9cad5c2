#!/usr/bin/env python3
"""rostest (plant_topics.test: plant_sim alone, realtime): every topic comes at its rate in simulated time,
judged on the messages' own stamps, not on when they arrive. Each topic's stamps over a window of
simulated time must step by exactly its period, none missing and none repeated: ground_truth, odom and
imu at the control rate (run/control_rate), fix at sensors/fix/rate, joint_states at publish_rate.

Arrival times (rostest's hztest) move with the machine's load: a loaded 2-core machine delivers the
states in bursts, and hztest's rate over them missed its band; the stamps do not depend on it. The wall
clock only bounds a hang (WALL_LIMIT)."""
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState

WINDOW = 3.0       # [s sim] of stamps checked per topic (hztest's test_duration)
WALL_LIMIT = 300.0  # [s wall] only bounds a hang: the window comes in ~5 s on an idle machine
TOL = 1e-6         # [s] stamps are on the nanosecond grid; rounding of rate -> period only


class PlantTopics(unittest.TestCase):
    def test_rates_from_stamps(self):
        rospy.init_node("plant_topics_test")
        control = rospy.get_param("/run/control_rate")
        topics = {"ground_truth": (Odometry, control), "odom": (Odometry, control), "imu": (Imu, control),
                  "fix": (PoseWithCovarianceStamped, rospy.get_param("/plant_sim/sensors/fix/rate")),
                  "joint_states": (JointState, rospy.get_param("/plant_sim/publish_rate"))}
        stamps = {name: [] for name in topics}
        subs = [rospy.Subscriber(name, cls, lambda m, n=name: stamps[n].append(m.header.stamp.to_nsec()),
                                 queue_size=100000, tcp_nodelay=True) for name, (cls, _) in topics.items()]

        def covered(name):
            s = stamps[name]
            return len(s) > 1 and s[-1] - s[0] >= WINDOW * 1e9

        deadline = time.time() + WALL_LIMIT
        while not all(covered(n) for n in topics):
            self.assertFalse(rospy.is_shutdown())
            self.assertLess(time.time(), deadline, "not %.1f s of simulated time on every topic after %.0f s wall: "
                            "%s" % (WINDOW, WALL_LIMIT, {n: len(s) for n, s in stamps.items()}))
            time.sleep(0.05)
        for sub in subs:
            sub.unregister()
        for name, (_, rate) in topics.items():
            s = stamps[name][:]
            period = 1.0 / rate
            window = [t for t in s if t <= s[0] + WINDOW * 1e9]
            gaps = [(b - a) * 1e-9 for a, b in zip(window, window[1:])]
            bad = [(i, g) for i, g in enumerate(gaps) if abs(g - period) > TOL]
            print("plant_topics: %s %d stamps over %.3f s, period %.6f s (%.1f Hz), %d off it" %
                  (name, len(window), (window[-1] - window[0]) * 1e-9, period, rate, len(bad)))
            self.assertEqual(bad, [], "%s: stamps not %.6f s apart (index, gap [s]): %s" % (name, period, bad[:10]))
            self.assertEqual(len(window), int(round(WINDOW * rate)) + 1, name)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "plant_topics_test", PlantTopics)
