#!/usr/bin/env python3
"""rostest of no traction in the node pipeline (no_traction.test): torque_controller's traction_control/state brings
the verdict with a report "no traction at (x y): ..." while the robot is on the no-grip patch (x in [10, 20] m);
from then on the robot is held: from 3 s after the verdict to the plant's duration (the run ended on the verdict, the
plant goes on: exit_at_end false, the hold with it) |v| and |omega| stay within 0.01 (m/s, rad/s) and it moves less
than 2 cm ("a stop is a stop"); the plant never diverges (it did 5.2 s after the verdict, the draft's
damper at speeds near 1e-164 m/s: test_traction); run_monitor's ~status says the run ended on no traction, no_traction_hold (3 s) after
the verdict, to the period; plant_sim says why on no_traction_diagnosis: the patch's grip budget at the verdict's place, its
peak traction below what driving there needs."""
import math
import re
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from sowing_robot.msg import TractionControlState

TIMEOUT = 240.0  # [s wall]
HOLD = 3.0       # traction_control/no_traction_hold (the default)
STILL = 0.01     # [m/s], [rad/s]
DRIFT = 0.02     # [m]


class NoTraction(unittest.TestCase):
    def test_no_traction(self):
        rospy.init_node("no_traction_test")
        lock = threading.Lock()
        verdicts, truth, status, diagnosis = [], [], [], []

        def on_state(m):
            if m.no_traction:
                with lock:
                    verdicts.append(m)

        def on_truth(m):
            with lock:
                truth.append((m.header.stamp.to_sec(), m.pose.pose.position.x, m.pose.pose.position.y,
                              m.twist.twist.linear.x, m.twist.twist.angular.z))

        rospy.Subscriber("traction_control/state", TractionControlState, on_state, queue_size=100000)
        rospy.Subscriber("ground_truth", Odometry, on_truth, queue_size=100000)
        rospy.Subscriber("run_monitor/status", String, lambda m: status.append(m.data), queue_size=1)
        rospy.Subscriber("no_traction_diagnosis", String, lambda m: diagnosis.append(m.data), queue_size=1)
        duration = rospy.get_param("/run/duration")
        stop = time.time() + TIMEOUT
        while time.time() < stop and not rospy.is_shutdown():
            with lock:
                if status and diagnosis and truth and truth[-1][0] >= duration - 1e-6:
                    break
            time.sleep(0.05)
        with lock:
            self.assertTrue(verdicts, "no no-traction verdict on traction_control/state")
            first = min(verdicts, key=lambda m: m.header.stamp)
            samples = list(truth)
        t_v = first.header.stamp.to_sec()
        report = first.no_traction_report
        self.assertTrue(report.startswith("no traction at ("), report)
        x_v = next(x for t, x, y, v, w in samples if t >= t_v)
        self.assertGreater(x_v, 10.0 - 0.5, "the verdict came before the patch")
        self.assertLess(x_v, 20.0, "the verdict came after the patch")
        held = [(t, x, y, v, w) for t, x, y, v, w in samples if t >= t_v + HOLD]
        self.assertTrue(held, "no state after the hold began")
        self.assertGreaterEqual(held[-1][0], duration - 1e-6, "the plant stopped before its duration (diverged?)")
        worst_v = max(abs(v) for _, _, _, v, _ in held)
        worst_w = max(abs(w) for _, _, _, _, w in held)
        drift = max(math.hypot(x - held[0][1], y - held[0][2]) for _, x, y, _, _ in held)
        self.assertLessEqual(worst_v, STILL)
        self.assertLessEqual(worst_w, STILL)
        self.assertLess(drift, DRIFT)
        self.assertTrue(status, "run_monitor said nothing on ~status")
        self.assertTrue(status[0].startswith(report), status[0])
        ended = float(status[0].rsplit("t = ", 1)[1].split(" ")[0])
        self.assertAlmostEqual(ended, t_v + HOLD, delta=0.0015)
        self.assertTrue(diagnosis, "plant_sim said nothing on no_traction_diagnosis")
        budget = re.match(r"soil patch 0 grip budget: peak traction ([0-9.]+) N \(sliding ([0-9.]+) N\) against "
                          r"([0-9.]+) N needed$", diagnosis[0])
        self.assertTrue(budget, diagnosis[0])
        peak, slide, needed = map(float, budget.groups())
        self.assertLess(slide, peak)
        self.assertLess(peak, needed, "no grip to be had on the patch, but the budget says there is")
        self.assertAlmostEqual(first.no_traction_where.x, x_v, delta=0.05)
        print("plant_sim: %s" % diagnosis[0])
        print("no traction: verdict at t = %.3f s, x = %.3f m: %s; held from %.3f s to %.3f s: |v| <= %.4f m/s, "
              "|omega| <= %.4f rad/s, moved %.4f m; run_monitor: %s"
              % (t_v, x_v, report, held[0][0], held[-1][0], worst_v, worst_w, drift, status[0]))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "no_traction", NoTraction)
