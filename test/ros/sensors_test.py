#!/usr/bin/env python3
"""rostest (sensors.test): a lockstep run with the controllers fed by the wheel encoders' odom.
Checks, per stamp: the run reaches its end; odom differs from ground_truth (tick quantisation), but by no
more than the quantisation bound of core/model/sensors.h (heading R res / L, position R res + distance R res / L);
imu comes every step with its bias; every fix is stamped on the 1/rate grid with the true position AT ITS
STAMP (not at its arrival, latency later), the last one sent is the one stamped duration - latency (the later
ones are still in flight when the run ends), and none is stamped in the dropout window.

Verified to fail: with the fix stamped at its arrival (plant_sensors.cpp) the test fails (a fix stamped
2.0 s, in the dropout window, since it arrived then; the position-at-stamp check would follow: the robot moves
~0.3 m in the latency, sigma is 5 mm). By construction, not run: odom published from the true state fails the
"differs" check."""
import math
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

R, L = 0.095, 0.24  # the URDF's wheel radius and half track (the encoders' nominal geometry)
WALL_TIMEOUT = 240.0


def yaw(q):
    return math.atan2(2.0 * q.w * q.z, 1.0 - 2.0 * q.z * q.z)


class Sensors(unittest.TestCase):
    def test_odometry_feedback_run(self):
        rospy.init_node("sensors_test")
        duration = rospy.get_param("/run/duration")
        rate = rospy.get_param("/run/control_rate")
        ticks = rospy.get_param("/plant_sim/sensors/encoder/ticks_per_turn")
        bias = rospy.get_param("/plant_sim/sensors/imu/bias")
        noise = rospy.get_param("/plant_sim/sensors/imu/noise")
        fix_rate = rospy.get_param("/plant_sim/sensors/fix/rate")
        latency = rospy.get_param("/plant_sim/sensors/fix/latency")
        sigma = rospy.get_param("/plant_sim/sensors/fix/sigma")
        drop_start = rospy.get_param("/plant_sim/sensors/fix/dropout_start")
        drop_len = rospy.get_param("/plant_sim/sensors/fix/dropout_duration")
        n_steps = int(round(duration * rate)) + 1
        n_fix_expected = int(math.floor((duration - latency) * fix_rate + 1e-9)) + 1 - int(round(drop_len * fix_rate))

        lock = threading.Lock()
        truth, odom, imu, fixes = {}, {}, {}, []
        done = threading.Event()

        def on_truth(m):
            with lock:
                truth[m.header.stamp.to_nsec()] = m
                if m.header.stamp.to_sec() >= duration - 1e-9:
                    done.set()

        def keep(store):
            def cb(m):
                with lock:
                    store[m.header.stamp.to_nsec()] = m
            return cb

        subs = [rospy.Subscriber("ground_truth", Odometry, on_truth, queue_size=100000),
                rospy.Subscriber("odom", Odometry, keep(odom), queue_size=100000),
                rospy.Subscriber("imu", Imu, keep(imu), queue_size=100000),
                rospy.Subscriber("fix", PoseWithCovarianceStamped, lambda m: fixes.append(m), queue_size=1000)]
        self.assertTrue(done.wait(WALL_TIMEOUT), "the run did not reach t = %g s (last ground_truth %s)"
                        % (duration, max(truth) * 1e-9 if truth else None))
        # The last messages of the final step are on their way on other connections: wait for them.
        deadline = time.time() + 30.0
        while time.time() < deadline and (len(odom) < n_steps or len(imu) < n_steps or len(fixes) < n_fix_expected):
            time.sleep(0.05)
        for s in subs:
            s.unregister()

        self.assertEqual(len(truth), n_steps)
        self.assertEqual(len(odom), n_steps, "odom: a period is missing")
        self.assertEqual(len(imu), n_steps, "imu: not one per step")

        # odom against the truth, stamp by stamp.
        res = 2.0 * math.pi / ticks
        travel = R * res
        distance, max_pos, max_head, prev = 0.0, 0.0, 0.0, None
        for k in sorted(truth):
            t, o = truth[k].pose.pose, odom[k].pose.pose
            if prev is not None:
                distance += math.hypot(t.position.x - prev.position.x, t.position.y - prev.position.y)
            prev = t
            max_pos = max(max_pos, math.hypot(o.position.x - t.position.x, o.position.y - t.position.y))
            d = yaw(o.orientation) - yaw(t.orientation)
            max_head = max(max_head, abs(math.atan2(math.sin(d), math.cos(d))))
        print("odom vs ground_truth: max position %.6f m, max heading %.6f rad over %.2f m (tick %.6f m)"
              % (max_pos, max_head, distance, travel))
        self.assertGreater(distance, 3.0, "the robot hardly moved: the loop on odom did not track")
        self.assertGreater(max_pos, 0.0, "odom equals the truth: it is not the encoders' dead reckoning")
        bound = "max position %.6f m, heading %.6f rad over %.2f m" % (max_pos, max_head, distance)
        self.assertLessEqual(max_head, travel / L + 1e-9, bound)
        self.assertLessEqual(max_pos, travel + distance * travel / L + 1e-6, bound)
        last = odom[max(odom)]
        self.assertGreater(last.pose.covariance[0] + last.pose.covariance[7], 0.0, "odom's covariance does not grow")

        # imu: the true yaw rate + bias + noise.
        errs = [imu[k].angular_velocity.z - truth[k].twist.twist.angular.z for k in truth]
        mean = sum(errs) / len(errs)
        self.assertLess(abs(mean - bias), 5.0 * noise / math.sqrt(len(errs)) + 1e-12, "imu bias: mean error %g" % mean)
        self.assertAlmostEqual(imu[max(imu)].angular_velocity_covariance[8], noise * noise)
        self.assertEqual(imu[max(imu)].orientation_covariance[0], -1.0)

        # fix: grid, count, dropout, position at its stamp.
        stamps = [f.header.stamp.to_nsec() for f in fixes]
        self.assertEqual(stamps, sorted(set(stamps)), "fix stamps repeat or go back")
        period_ns = int(round(1e9 / fix_rate))
        for s in stamps:
            self.assertEqual(s % period_ns, 0, "fix stamped %d ns: not on its 1/rate grid" % s)
            self.assertFalse(drop_start - 1e-9 <= s * 1e-9 < drop_start + drop_len - 1e-9, "a fix in the dropout: %d" % s)
        self.assertEqual(len(fixes), n_fix_expected)
        self.assertEqual(stamps[-1], int(round((duration - latency) * 1e9)),
                         "the last fix sent is not the one stamped duration - latency")
        at_stamp, at_arrival = [], []
        for f in fixes:
            k = f.header.stamp.to_nsec()
            t = truth[k].pose.pose.position
            a = truth[k + int(round(latency * 1e9))].pose.pose.position
            x, y = f.pose.pose.position.x, f.pose.pose.position.y
            at_stamp.append(math.hypot(x - t.x, y - t.y))
            at_arrival.append(math.hypot(x - a.x, y - a.y))
            self.assertAlmostEqual(f.pose.covariance[0], sigma * sigma)
        rms = math.sqrt(sum(e * e for e in at_stamp) / len(at_stamp))
        print("fix: %d messages, rms error %.4f m at the stamp, %.4f m at the arrival"
              % (len(fixes), rms, sum(at_arrival) / len(at_arrival)))
        self.assertLess(rms, 2.0 * math.sqrt(2.0) * sigma, "the fix is not the position at its stamp (rms %.4f m)" % rms)
        moving = [e for f, e in zip(fixes, at_arrival) if f.header.stamp.to_sec() >= 1.0]  # past the start-up
        self.assertGreater(sum(moving) / len(moving), 10.0 * sigma,
                           "the fix is the position at its arrival (rms at the stamp %.4f m)" % rms)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "sensors_test", Sensors)
