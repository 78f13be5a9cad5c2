#!/usr/bin/env python3
"""rostest: a recorded run ends only when the recorder has every period. `rosrun sowing_robot sim
headless:=true record:=full field:=line duration:=5` with the recorder slowed down on its receiving side
(bag_recorder ~receive_delay: it reads its connections slowly, so the backlog stays with the publishers, as
on a machine that starves it of CPU). (1) The run waits for it (run_monitor says so) and the bag holds
every period: 5001 /ground_truth messages (duration * rate + 1), the last stamped 5.0, and as many of every other
per-period topic. (2) With a recorder_timeout too short for it, the run ends with exit 3 and a last line
saying that the bag lacks the end of the run.

Protection checked: run_monitor's wait for /recorder/recorded_until (src/ros/run_monitor.cpp).
Verified to fail without it: with sim.launch's run_monitor/recorder parameter removed, case (1) left a bag
with 3595 /odom messages ending at t = 3.594 s (the rest died with their publishers)."""
import os
import signal
import subprocess
import tempfile
import unittest

import roslib.packages
import rosbag
import rostest

DURATION, RATE = 5.0, 1000
PERIOD_TOPICS = ["/ground_truth", "/odom", "/desired_velocity", "/wheel_torque", "/torque_controller/state", "/tracking_error"]


def run_sim(port, tmp, overlay, *args):
    config = os.path.join(tmp, "overlay.yaml")
    with open(config, "w") as f:
        f.write(overlay)
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    cmd = [roslib.packages.find_node("sowing_robot", "sim")[0], "headless:=true", "record:=full", "field:=line",
           "duration:=%g" % DURATION, "config:=" + config] + list(args)
    # A session of its own: if the run hangs, the whole launch is killed, not only the runner.
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                            start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=300)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        out += "\n(killed after 300 s)"
    return subprocess.CompletedProcess(cmd, proc.returncode, out)


class RecordSlow(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="sowing_record_slow_")

    def test_slow_recorder_gets_every_period(self):
        bag = os.path.join(self.tmp, "slow.bag")
        proc = run_sim(11661, self.tmp, "recorder: {receive_delay: 0.0002}\n", "bag:=" + bag)
        out = proc.stdout
        self.assertEqual(proc.returncode, 0, out[-4000:])
        self.assertIn("waiting (up to", out, "the recorder was never behind: the test proves nothing\n" + out[-3000:])
        with rosbag.Bag(bag) as b:
            stamps = {t: [m.header.stamp.to_nsec() for _, m, _ in b.read_messages(topics=[t])] for t in PERIOD_TOPICS}
        n = int(DURATION * RATE) + 1
        truth = stamps["/ground_truth"]
        self.assertEqual(len(truth), n, "ground_truth: %d messages, last at %s"
                         % (len(truth), truth[-1] * 1e-9 if truth else None))
        self.assertEqual(truth[-1], int(DURATION * 1e9))
        self.assertEqual(sorted(set(truth)), truth, "ground_truth stamps repeat or go back")
        for topic in PERIOD_TOPICS:
            self.assertEqual(len(set(stamps[topic])), n, "%s: %d distinct stamps" % (topic, len(set(stamps[topic]))))
        self.assertEqual(out.rstrip().splitlines()[-1], "sim: the run ended normally")

    def test_recorder_timeout_ends_the_run_with_a_reason(self):
        bag = os.path.join(self.tmp, "late.bag")
        proc = run_sim(11662, self.tmp, "recorder: {receive_delay: 0.0005}\nrun_monitor: {recorder_timeout: 0.5}\n",
                       "bag:=" + bag)
        last = proc.stdout.rstrip().splitlines()[-1]
        self.assertEqual(proc.returncode, 3, proc.stdout[-4000:])
        self.assertIn("[FATAL]", last)
        self.assertIn("/run_monitor: the recorder (/recorder/recorded_until) wrote the run only up to", last)
        self.assertIn("the bag lacks the end of the run", last)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "record_slow_test", RecordSlow)
