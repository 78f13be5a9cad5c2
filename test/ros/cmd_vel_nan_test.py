#!/usr/bin/env python3
"""rostest: velocity mode (sim.launch input:=cmd_vel) in lockstep, run twice on masters of their own with
the same step schedule (cmd_vel_drive.py); the second run also gets twists that must be dropped (NaN or
infinite v, omega or linear.y, |v| or |omega| beyond the limits, a NaN after the last good twist, which
must not keep that command fresh, and a plain Twist, which lockstep ignores). The two runs must record
the same ground_truth and desired_velocity, bit for bit, and the second must warn about the drops.
Verified to fail with the feature broken: docs/cmd_vel.md, "Tests"."""
import os
import subprocess
import tempfile
import unittest

import rostest

PORTS = (11711, 11712)


def run(port, output, inject_bad):
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    cmd = ["roslaunch", "-p", str(port), "sowing_robot", "cmd_vel_run.launch", "output:=" + output,
           "inject_bad:=" + ("true" if inject_bad else "false")]
    return subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=280,
                          universal_newlines=True)


class CmdVelNaN(unittest.TestCase):
    def test_bad_twists_change_nothing(self):
        tmp = tempfile.mkdtemp(prefix="sowing_cmd_vel_nan_")
        traces, logs = [], []
        for inject, port in zip((False, True), PORTS):
            out = os.path.join(tmp, "bad.txt" if inject else "clean.txt")
            proc = run(port, out, inject)
            logs.append(proc.stdout)
            self.assertTrue(os.path.exists(out),
                            "run (inject_bad %s) wrote no trace:\n%s" % (inject, proc.stdout[-3000:]))
            with open(out) as f:
                traces.append(f.read())
        for trace, log in zip(traces, logs):
            self.assertTrue(trace.startswith("truth 0.0 "), "not recorded from t = 0:\n" + log[-3000:])
            self.assertEqual(trace.count("truth "), 8001, "not every state recorded:\n" + log[-3000:])
        self.assertEqual(traces[0], traces[1], "the bad twists changed the run")
        self.assertIn("cmd_vel_limiter: dropped a twist", logs[1])
        self.assertIn("is ignored; publish geometry_msgs/TwistStamped", logs[1])
        self.assertNotIn("cmd_vel_limiter: dropped a twist", logs[0])


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "cmd_vel_nan_test", CmdVelNaN)
