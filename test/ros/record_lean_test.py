#!/usr/bin/env python3
"""rostest: the lean recording (sim.launch record:=lean, docs/recording.md). A short headless lockstep run on the
line leaves an LZ4-compressed bag holding the plan, the seed record and the events as published and the state
throttled by its stamps to record_rate (10 Hz: exactly one message per 100 ms of stamps), no 1 kHz topic, the log
at warnings and above only; analyze_bag reads it with a one-line note of what a lean bag lacks. With the loop fed
from the encoders (feedback:=odometry) or the estimator (fused) the fed pose is recorded at the same rate, and the
run starts (the plant's subscriber count agrees with the recorder's links) and ends normally."""
import os
import subprocess
import tempfile
import unittest

import rosbag
import rostest

import node_process

RATE_NS = 100000000  # record_rate 10 Hz
STATE = ("/ground_truth", "/reference", "/tracking_error")
FULL_ONLY = ("/odom", "/imu", "/fix", "/wheel_torque", "/desired_velocity", "/torque_controller/state",
             "/joint_states", "/tf", "/seeds", "/applied_torque", "/wheel_slip")


def stamps_ns(bag, topic):
    return [m.header.stamp.to_nsec() for _, m, _ in bag.read_messages(topics=[topic])]


class RecordLean(unittest.TestCase):
    def run_lean(self, port, duration, *args):
        bag = os.path.join(tempfile.mkdtemp(prefix="sowing_record_lean_"), "run.bag")
        code, out, _ = node_process.sim(port, ["record:=lean", "field:=line", "duration:=%g" % duration,
                                               "bag:=" + bag] + list(args), timeout=300)
        self.assertEqual(code, 0, out[-4000:])
        self.assertEqual(out.rstrip().splitlines()[-1], "sim: the run ended normally")
        self.assertTrue(os.path.exists(bag), out[-3000:])
        return bag

    def assertThrottled(self, bag, topic, duration):
        s = stamps_ns(bag, topic)
        self.assertGreaterEqual(len(s), int(duration * 10), "%s: %d messages" % (topic, len(s)))
        self.assertEqual(s[0] % RATE_NS, 0, topic)
        self.assertEqual(sorted(set(b - a for a, b in zip(s, s[1:]))), [RATE_NS], "%s not at 10 Hz of stamps" % topic)

    def test_lean_bag(self):
        duration = 10.0
        path = self.run_lean(11691, duration)
        with rosbag.Bag(path) as bag:
            self.assertEqual(bag.get_compression_info().compression, "lz4")
            counts = {t: i.message_count for t, i in bag.get_type_and_topic_info().topics.items()}
            print("lean bag: %d bytes, %s" % (os.path.getsize(path), counts))
            for topic in STATE:
                self.assertThrottled(bag, topic, duration)
            self.assertLessEqual(len(stamps_ns(bag, "/tracking_error")), int(duration * 10) + 2)
            for topic in ("/plan", "/run_monitor/status"):
                self.assertGreaterEqual(counts.get(topic, 0), 1, topic)
            self.assertGreater(counts.get("/seeds/record", 0), 10, "hardly a seed recorded")
            for topic in FULL_ONLY:
                self.assertNotIn(topic, counts, "%s is in a lean bag" % topic)
            for _, m, _ in bag.read_messages(topics=["/rosout_agg"]):
                self.assertGreaterEqual(m.level, 4, "a log line below warnings: %s" % m.msg)
            (_, status, _), = bag.read_messages(topics=["/run_monitor/status"])
            self.assertTrue(status.data.startswith("completed at"), status.data)
        a = subprocess.run([node_process.executable("analyze_bag"), path, "--no-plots"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
        print(a.stdout, a.stderr)
        self.assertEqual(a.returncode, 0, a.stderr)
        self.assertIn("| ITAE | y |", a.stdout)
        self.assertIn("- seeds: ", a.stdout)
        self.assertIn("not recorded (lean bag): torque", a.stderr)
        self.assertNotIn("missing", a.stderr)

    def test_fed_pose_recorded(self):
        for port, feedback, topic in ((11692, "odometry", "/odom"), (11693, "fused", "/odometry/filtered")):
            with self.subTest(feedback=feedback):
                path = self.run_lean(port, 3.0, "feedback:=" + feedback)
                with rosbag.Bag(path) as bag:
                    self.assertThrottled(bag, topic, 3.0)
                    self.assertThrottled(bag, "/ground_truth", 3.0)

    def test_nodelet_recorder(self):
        """nodelets:=true loads the recorder into the pipeline's manager (sim.launch): in stamp order its lean bag
        holds the same messages, bit for bit, as the recorder process's of the same run as processes, and two such
        runs hold the same messages."""
        def messages(path):
            with rosbag.Bag(path) as bag:
                return [(topic, t.to_nsec(), bytes(raw[1])) for topic, raw, t in bag.read_messages(raw=True)]
        # record_log:=false: a log line names its node (the manager or the process) and reaches the recorder
        # through rosout, whenever it comes
        runs = [self.run_lean(port, 3.0, "record_deterministic:=true", "record_log:=false", "nodelets:=" + form)
                for port, form in ((11694, "false"), (11695, "true"), (11696, "true"))]
        processes, nodelets = messages(runs[0]), messages(runs[1])
        # 3 s of the line at 10 Hz of stamps: ground_truth, reference and tracking_error 31 each, and the plan,
        # footprint, seed reports and status
        self.assertGreaterEqual(len(nodelets), 3 * 31)
        self.assertEqual(nodelets, processes)
        # Two nodelet runs hold the same messages at the same stamps. (Their files are not compared byte for byte:
        # under load two such files have differed; the recorder process's files do repeat, fleet.test.)
        self.assertEqual(messages(runs[2]), nodelets, "two nodelet runs' lean bags hold different messages")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "record_lean_test", RecordLean)
