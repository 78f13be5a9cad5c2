#!/usr/bin/env python3
"""rostest for analyze_bag (scripts/analyze_bag, the package sowing_robot.analyze_bag): metrics on synthetic bags
with analytic errors and equal to the C++ accumulator's, de-duplication of repeated stamps, one-line errors with
the documented exit codes for bad input, and the figures. (test/python has the pytest edge cases.)"""
import copy
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospkg
import rospy
import rostest
from geometry_msgs.msg import Point
from nav_msgs.msg import Odometry
from std_msgs.msg import String
from visualization_msgs.msg import Marker, MarkerArray

from sowing_robot import core
from sowing_robot.analyze_bag import bag as ab
from sowing_robot.analyze_bag import metrics as ab_metrics
from sowing_robot.msg import (DesiredVelocity, ReferenceState, TorqueControllerState, TrackingError,
                              WheelTorque)

SCRIPT = os.path.join(rospkg.RosPack().get_path("sowing_robot"), "scripts", "analyze_bag")

PERIOD_NS = 1000000  # 1 ms, as the simulation


def stamp(k, period_ns=PERIOD_NS):
    return rospy.Time(*divmod(k * period_ns, 10**9))


def bag_time(t):
    return t if t > rospy.Time(0) else rospy.Time(0, 1)  # rosbag rejects a receive time of 0


def error_msg(k, ex, ey, eth):
    m = TrackingError()
    m.header.stamp = stamp(k)
    m.x, m.y, m.theta = ex, ey, eth
    return m


def damped(t):
    """exp(-t) cos(pi t): peak 1 at t = 0, overshoot at t* = 1 - atan(1/pi)/pi."""
    return math.exp(-t) * math.cos(math.pi * t)


def write_error_bag(path, n, fx, fy, fth, duplicate_every=0):
    """/tracking_error samples k = 0..n-1 at k ms; repeats (same stamp, bogus values, later) every duplicate_every."""
    with rosbag.Bag(path, "w") as bag:
        for k in range(n):
            t = k * 1e-3
            msg = error_msg(k, fx(t), fy(t), fth(t))
            bag.write("/tracking_error", msg, bag_time(msg.header.stamp))
            if duplicate_every and k % duplicate_every == 0:
                bogus = error_msg(k, 99.0, -99.0, 9.0)  # a retried state answered again: must be ignored
                bag.write("/tracking_error", bogus, bag_time(msg.header.stamp) + rospy.Duration(0, 500))


def bits(metrics):
    """{axis: {field: float.hex}}: equal when every value is equal to the last bit (NaN == NaN)."""
    return {axis: {k: float(v).hex() for k, v in fields.items()} for axis, fields in metrics.items()}


def run_script(*args):
    proc = subprocess.run([sys.executable, SCRIPT] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          universal_newlines=True, timeout=240)
    return proc.returncode, proc.stdout, proc.stderr


def patch_unindexed(src, dst):
    """What an unclosed recording (.bag.active) looks like: header index_pos = 0, no index at the end."""
    with open(src, "rb") as f:
        data = bytearray(f.read())
    assert data[:13] == b"#ROSBAG V2.0\n"
    (hlen,) = struct.unpack("<I", data[13:17])
    pos, end = 17, 17 + hlen
    while pos < end:
        (flen,) = struct.unpack("<I", data[pos:pos + 4])
        field = bytes(data[pos + 4:pos + 4 + flen])
        if field.startswith(b"index_pos="):
            off = pos + 4 + len(b"index_pos=")
            (index_pos,) = struct.unpack("<Q", data[off:off + 8])
            data[off:off + 8] = struct.pack("<Q", 0)
            break
        pos += 4 + flen
    else:
        raise AssertionError("no index_pos in the bag header")
    with open(dst, "wb") as f:
        f.write(data[:index_pos])


class AnalyzeBag(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="analyze_bag_test_")
        # e = exp(-t) (x), -2 exp(-t) (y), exp(-t) cos(pi t) (theta), every 1 ms for 20 s
        cls.n = 20001
        cls.exp_bag = os.path.join(cls.tmp, "exp.bag")
        write_error_bag(cls.exp_bag, cls.n, lambda t: math.exp(-t), lambda t: -2.0 * math.exp(-t), damped)
        cls.dup_bag = os.path.join(cls.tmp, "dup.bag")
        write_error_bag(cls.dup_bag, cls.n, lambda t: math.exp(-t), lambda t: -2.0 * math.exp(-t), damped,
                        duplicate_every=7)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.tmp, name)

    # --- metrics -----------------------------------------------------------------------------------------
    def test_stamps_are_ros_time_to_sec(self):
        path = self.path("stamps.bag")
        stamps = ((0, 3000000), (7, 123000000), (24, 999000000), (1, 1), (1700000000, 123456789))
        with rosbag.Bag(path, "w") as bag:
            for i, (sec, nsec) in enumerate(stamps):
                m = TrackingError()
                m.header.stamp = rospy.Time(sec, nsec)
                bag.write("/tracking_error", m, rospy.Time(1, i + 1))
        s = ab.load_bag(path).get("/tracking_error")
        expected = sorted((sec * 10**9 + nsec, float(sec) + 1e-9 * float(nsec)) for sec, nsec in stamps)
        self.assertEqual(list(s.stamp_ns), [ns for ns, _ in expected])
        self.assertEqual([t.hex() for t in s.stamps], [t.hex() for _, t in expected])

    def test_exponential_error_analytic(self):
        m = ab.load_bag(self.exp_bag).metrics()
        x, y, th = m["x"], m["y"], m["theta"]
        tail = math.exp(-20.0)
        tol = 2e-7  # trapezoid error ~ h^2/12 relative, h = 1 ms
        self.assertAlmostEqual(x["iae"], 1.0 - tail, delta=tol)
        self.assertAlmostEqual(x["itae"], 1.0 - 21.0 * tail, delta=tol)
        self.assertAlmostEqual(x["ise"], 0.5 * (1.0 - tail ** 2), delta=tol)
        self.assertAlmostEqual(x["itse"], 0.25, delta=tol)
        self.assertAlmostEqual(y["iae"], 2.0, delta=2 * tol)
        self.assertAlmostEqual(y["ise"], 2.0, delta=4 * tol)
        self.assertAlmostEqual(y["itse"], 1.0, delta=4 * tol)
        for a in (x, y):  # time-domain figures are sampled: within one period
            self.assertAlmostEqual(a["rise_time"], math.log(9.0), delta=1.001e-3)
            self.assertAlmostEqual(a["settling_time"], math.log(50.0), delta=1.001e-3)
            self.assertEqual(a["overshoot"], 0.0)
        self.assertEqual(x["peak"], 1.0)
        self.assertEqual(y["peak"], 2.0)
        # exp(-t) cos(pi t): overshoot 100 exp(-t*) |cos(pi t*)| at t* = 1 - atan(1/pi)/pi
        ts = 1.0 - math.atan(1.0 / math.pi) / math.pi
        self.assertAlmostEqual(th["overshoot"], -100.0 * damped(ts), delta=1e-4)
        self.assertEqual(th["peak"], 1.0)

    def test_metrics_equal_cpp_accumulator(self):
        """The bag's metrics are the C++ MetricsAccumulator's, fed sample by sample with the messages' stamps."""
        data = ab.load_bag(self.exp_bag)
        t, ex, ey, eth, skipped = data.error_samples()
        self.assertEqual(skipped, 0)
        self.assertEqual(len(t), self.n)
        self.assertEqual(t[1234], 1.0 + 1e-9 * 234000000.0)
        acc = core.MetricsAccumulator(True)
        with rosbag.Bag(self.exp_bag) as bag:
            for _, msg, _ in bag.read_messages(topics=["/tracking_error"]):
                self.assertTrue(acc.add(msg.header.stamp.secs + 1e-9 * msg.header.stamp.nsecs, msg.x, msg.y,
                                        msg.theta))
        self.assertEqual(bits(data.metrics()), bits(acc.result()))
        self.assertEqual(bits(data.metrics(until=7.5)), bits(core.metrics(t[:7501], ex[:7501], ey[:7501],
                                                                          eth[:7501])))

    def test_time_domain_definitions(self):
        m = core.time_domain_metrics([0.0, 1.0, 2.0, 3.0, 4.0, 5.0], [0.5, -2.0, -1.0, 0.1, 0.05, -0.01])
        self.assertEqual(m["peak"], 2.0)
        self.assertEqual(m["rise_time"], 3.0 - 2.0)          # 0.9 E first at t = 2, 0.1 E first at t = 3
        self.assertEqual(m["settling_time"], 5.0)            # last |e| > 0.02 E at t = 4: the next sample
        self.assertAlmostEqual(m["overshoot"], 5.0, delta=1e-12)  # +0.1 against a negative peak of 2
        z = core.time_domain_metrics([0.0, 1.0], [0.0, 0.0])
        self.assertEqual((z["rise_time"], z["settling_time"], z["peak"]), (0.0, 0.0, 0.0))
        never = core.time_domain_metrics([0.0, 1.0], [1.0, 0.95])
        self.assertTrue(math.isnan(never["rise_time"]))

    def test_table_layout(self):
        names, runs = ab_metrics.thesis_runs()
        table = ab_metrics.metrics_table(names, runs)
        lines = table.splitlines()
        self.assertEqual(lines[0], "| metric | axis | PSO-ATSMC (thesis) | TSMC (thesis) |")
        self.assertEqual(lines[1], "|---|---|---:|---:|")
        self.assertEqual(len(lines), 2 + 21)
        self.assertIn("| ISE | x | 2.139 | 3.123 |", lines)
        self.assertIn("| ITAE | y | 21.34 | 42.95 |", lines)
        self.assertIn("| settling time [s] | theta | 4.21 | 6.337 |", lines)
        self.assertIn("| overshoot [%] | y | 8 | 9 |", lines)

    def test_duplicated_stamps_dropped(self):
        clean = ab.load_bag(self.exp_bag)
        dup = ab.load_bag(self.dup_bag)
        s = dup.get("/tracking_error")
        self.assertEqual(len(s), self.n)
        self.assertEqual(s.duplicates, len(range(0, self.n, 7)))
        self.assertEqual(bits(clean.metrics()), bits(dup.metrics()))

    def test_unsorted_stamps_are_sorted(self):
        path = self.path("unsorted.bag")
        order = list(range(0, 2001))
        order[100:200] = reversed(order[100:200])
        with rosbag.Bag(path, "w") as bag:
            for i, k in enumerate(order):
                msg = error_msg(k, math.exp(-k * 1e-3), 0.0, 0.0)
                bag.write("/tracking_error", msg, rospy.Time(1, i * 1000))  # received out of stamp order
        t = ab.load_bag(path).error_samples()[0]
        self.assertEqual(list(t), sorted(t))
        self.assertEqual(len(t), 2001)

    # --- command line: the good case and the figures -----------------------------------------------------
    def test_full_bag_table_summary_and_plots(self):
        path = self.path("full.bag")
        with rosbag.Bag(path, "w") as bag:
            for k in range(0, 3001):
                t = k * 1e-3
                st = stamp(k)
                bt = bag_time(st)
                ref = ReferenceState()
                ref.header.stamp = st
                ref.x, ref.y, ref.v = t, 3.0, 1.0
                bag.write("/reference", ref, bt)
                odom = Odometry()
                odom.header.stamp = st
                odom.pose.pose.position.x = t - math.exp(-t)
                odom.pose.pose.position.y = 3.0 - 3.0 * math.exp(-t)
                odom.pose.pose.orientation.z = math.sin(0.05 * math.exp(-t))
                odom.pose.pose.orientation.w = math.cos(0.05 * math.exp(-t))
                odom.twist.twist.linear.x = 1.0 + math.exp(-t)
                bag.write("/ground_truth", odom, bt)  # the true state
                encoders = copy.deepcopy(odom)
                encoders.pose.pose.position.x += 0.5  # the encoders' dead reckoning, off by 0.5 m
                bag.write("/odom", encoders, bt)
                des = DesiredVelocity()
                des.header.stamp = st
                des.v, des.omega = 1.0 + 1.2 * math.exp(-t), -0.1 * math.exp(-t)
                bag.write("/desired_velocity", des, bt)
                tq = WheelTorque()
                tq.header.stamp = st
                tq.right, tq.left = 10.0 * math.exp(-t), -12.0 * math.exp(-t)
                bag.write("/wheel_torque", tq, bt)
                cs = TorqueControllerState()
                cs.header.stamp = st
                cs.mode = "atsmc"
                cs.e_v, cs.e_omega = 0.2 * math.exp(-t), -0.1 * math.exp(-t)
                cs.s_v, cs.s_omega = 0.3 * math.exp(-t), 0.0
                cs.m0_hat, cs.i0_hat = 18.5 + 0.1 * t, 0.67
                cs.saturated = k < 5
                bag.write("/torque_controller/state", cs, bt)
                bag.write("/tracking_error", error_msg(k, math.exp(-t), 3.0 * math.exp(-t), damped(t)), bt)
            markers = MarkerArray()
            mk = Marker(type=Marker.CYLINDER, action=Marker.ADD)
            mk.pose.position = Point(1.5, 2.0, 0.0)
            mk.scale.x = mk.scale.y = 0.3
            markers.markers.append(mk)
            bag.write("/field_markers", markers, rospy.Time(0, 1))
        plots = self.path("plots")
        md = self.path("table.md")
        code, out, err = run_script(path, "--plots", plots, "--markdown", md, "--thesis")
        self.assertEqual(code, 0, err)
        self.assertEqual(err, "")
        data = ab.load_bag(path)
        self.assertFalse(data.truth_from_odom())
        self.assertEqual(data.truth()["pose.pose.position.x"][0], -1.0, "the robot's state is not /ground_truth")
        self.assertIn("| metric | axis | atsmc | PSO-ATSMC (thesis) | TSMC (thesis) |", out)
        self.assertIn("saturated: 5 control periods (1 episodes)", out)
        self.assertIn("max |torque|: right 10 N·m, left 12 N·m", out)
        with open(md) as f:
            self.assertIn("| ISE | x |", f.read())
        names = ("path", "tracking", "errors", "velocity", "torques", "sliding", "adaptive")
        for name in names:
            png = os.path.join(plots, "full_%s.png" % name)
            self.assertTrue(os.path.isfile(png), png)
            with open(png, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", png)
            self.assertGreater(os.path.getsize(png), 10000, png)
        # two bags, explicit labels, default plot directory (next to the first bag)
        code, out, err = run_script(path, self.exp_bag, "--labels", "A,B")
        self.assertEqual(code, 0, err)
        self.assertIn("| metric | axis | A | B |", out)
        self.assertTrue(os.path.isfile(self.path("full_vs_exp_errors.png")))

    # --- command line: bad input --------------------------------------------------------------------------
    def assertOneLineError(self, args, code, needle):
        rc, out, err = run_script(*args)
        self.assertEqual(rc, code, "%s: exit %d, stderr:\n%s" % (args, rc, err))
        self.assertNotIn("Traceback", err + out)
        lines = err.strip().splitlines()
        self.assertEqual(len(lines), 1, "%s: expected one line on stderr:\n%s" % (args, err))
        self.assertIn(needle, lines[0])
        self.assertTrue(lines[0].startswith("analyze_bag: "), lines[0])
        return lines[0]

    def test_old_bag_falls_back_to_odom_and_says_so(self):
        # Bags recorded before plant_sim had sensors have no /ground_truth: their /odom was the true state.
        path = self.path("old.bag")
        with rosbag.Bag(path, "w") as bag:
            for k in range(0, 200):
                st = stamp(k)
                odom = Odometry()
                odom.header.stamp = st
                odom.pose.pose.position.x = 2.0 + k * 1e-3
                odom.pose.pose.orientation.w = 1.0
                bag.write("/odom", odom, bag_time(st))
                bag.write("/tracking_error", error_msg(k, 0.1, 0.2, 0.01), bag_time(st))
        data = ab.load_bag(path)
        self.assertTrue(data.truth_from_odom())
        self.assertEqual(data.truth()["pose.pose.position.x"][0], 2.0)
        code, out, err = run_script(path, "--no-plots")
        self.assertEqual(code, 0, err)
        self.assertIn("no /ground_truth", err)
        self.assertIn("read from /odom", err)

    def test_missing_file(self):
        self.assertOneLineError([self.path("nope.bag")], 3, "no such file")

    def test_directory(self):
        self.assertOneLineError([self.tmp], 3, "directory")

    def test_empty_file(self):
        p = self.path("empty.bag")
        open(p, "w").close()
        self.assertOneLineError([p], 3, "empty file")

    def test_not_a_bag(self):
        p = self.path("text.bag")
        with open(p, "w") as f:
            f.write("hello\n")
        self.assertOneLineError([p], 3, "not a readable bag")

    def test_truncated_bag(self):
        p = self.path("half.bag")
        with open(self.exp_bag, "rb") as f:
            data = f.read()
        with open(p, "wb") as f:
            f.write(data[:len(data) // 2])
        self.assertOneLineError([p], 3, "truncated bag")

    def test_unindexed_bag(self):
        p = self.path("unindexed.bag")
        patch_unindexed(self.exp_bag, p)
        with self.assertRaises(rosbag.ROSBagUnindexedException):
            rosbag.Bag(p)
        line = self.assertOneLineError([p], 3, "unindexed bag")
        self.assertIn("rosbag reindex", line)
        # and the advice works
        fixed = self.path("reindexed.bag")
        shutil.copy(p, fixed)
        subprocess.run(["rosbag", "reindex", "-q", fixed], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, timeout=120)
        self.assertEqual(bits(ab.load_bag(fixed).metrics()), bits(ab.load_bag(self.exp_bag).metrics()))

    def test_foreign_bag(self):
        p = self.path("foreign.bag")
        with rosbag.Bag(p, "w") as bag:
            for i in range(10):
                bag.write("/chatter", String(data="hi %d" % i), rospy.Time(1, i))
        line = self.assertOneLineError([p], 3, "foreign bag")
        self.assertIn("/chatter", line)

    def test_too_few_samples(self):
        p = self.path("one.bag")
        with rosbag.Bag(p, "w") as bag:
            bag.write("/tracking_error", error_msg(5, 1.0, 1.0, 1.0), rospy.Time(1))
            bag.write("/tracking_error", error_msg(5, 2.0, 2.0, 2.0), rospy.Time(2))  # a repeat: still 1
        self.assertOneLineError([p, "--no-plots"], 3, "at least 2")

    def test_usage_errors(self):
        self.assertOneLineError([], 2, "see analyze_bag --help")
        self.assertOneLineError([self.exp_bag, "--labels", "a,b"], 2, "--labels")
        self.assertOneLineError([self.exp_bag, "--bogus"], 2, "--bogus")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "analyze_bag_test", AnalyzeBag)
