#!/usr/bin/env python3
"""rostest: `roslaunch sowing_robot sim.launch headless:=true` twice, each on a master of its own, with
the same noise seed. Each run must end by itself and the two metric files must be identical."""
import os
import subprocess
import tempfile
import unittest

import rostest


def headless_run(port, out_yaml, overlay):
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    cmd = ["roslaunch", "-p", str(port), "sowing_robot", "sim.launch", "headless:=true", "duration:=8.0",
           "metrics_output:=" + out_yaml, "config:=" + overlay]
    return subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=200,
                          universal_newlines=True)


class RepeatRuns(unittest.TestCase):
    def test_same_seed_same_metrics(self):
        tmp = tempfile.mkdtemp(prefix="sowing_repeat_")
        overlay = os.path.join(tmp, "noise.yaml")
        with open(overlay, "w") as f:
            f.write("plant_sim:\n  noise: {std: 0.2, seed: 11}\n")
        outputs = []
        for i, port in enumerate((11611, 11612)):
            out = os.path.join(tmp, "run%d.yaml" % i)
            proc = headless_run(port, out, overlay)
            self.assertTrue(os.path.exists(out), "run %d wrote no metrics:\n%s" % (i, proc.stdout[-3000:]))
            with open(out) as f:
                outputs.append(f.read())
            self.assertIn("| ITAE | y |", proc.stdout, "run %d printed no metric table" % i)
            # every period scored: a state dropped while its reference was late changes the metrics a
            # little (CI, under load: 7,958 of 8,001), which the comparison below may not catch
            self.assertIn("run_monitor: 8001 samples up to t = 8.000 s", proc.stdout, "run %d" % i)
        self.assertIn("itae", outputs[0])
        self.assertEqual(outputs[0], outputs[1])


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "repeat_runs_test", RepeatRuns)
