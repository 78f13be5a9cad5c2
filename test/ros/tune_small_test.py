#!/usr/bin/env python3
"""rostest: `roslaunch sowing_robot tune.launch` with a small swarm must improve on its initial best and
write a gains YAML that `roslaunch sowing_robot sim.launch headless:=true gains:=FILE duration:=3` loads
and runs to the end. Each launch runs on a master of its own (roslaunch -p PORT)."""
import math
import os
import re
import subprocess
import tempfile
import unittest

import rostest
import yaml

TUNE_PORT, SIM_PORT = 11621, 11622
KNOWN = {"kinematic_controller": {"kx", "ky", "ktheta"},
         "torque_controller": {"k1", "k2", "eta1", "eta2", "beta_v", "beta_omega", "rate_m", "rate_i"}}


def launch(port, args, timeout):
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    cmd = ["roslaunch", "-p", str(port), "sowing_robot"] + args
    return subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout,
                          universal_newlines=True)


def header_value(text, key):
    m = re.search(r"^# %s: (\S+)" % key, text, re.M)
    return float(m.group(1)) if m else None


class TuneSmall(unittest.TestCase):
    def test_small_tuning_improves_and_its_gains_run(self):
        tmp = tempfile.mkdtemp(prefix="sowing_tune_")
        gains = os.path.join(tmp, "tuned_gains.yaml")
        tune = launch(TUNE_PORT, ["tune.launch", "output:=" + gains, "particles:=6", "iterations:=4",
                                  "duration:=5", "control_rate:=200", "seed:=3", "threads:=2"], 200)
        self.assertTrue(os.path.exists(gains), "pso_tuner wrote no gains file:\n" + tune.stdout[-4000:])
        self.assertIn("iteration 4/4", tune.stdout, "no progress line for the last iteration")
        with open(gains) as f:
            text = f.read()
        initial, best = header_value(text, "initial_best_cost"), header_value(text, "best_cost")
        print("tune_small: initial best cost %r, final best cost %r" % (initial, best))
        self.assertIsNotNone(initial, "no '# initial_best_cost:' in the header:\n" + text)
        self.assertIsNotNone(best, "no '# best_cost:' in the header:\n" + text)
        self.assertTrue(math.isfinite(best))
        self.assertLess(best, initial, "PSO did not improve on its initial swarm")

        data = yaml.safe_load(text)
        self.assertEqual(set(data), set(KNOWN), "unexpected top-level keys: %s" % sorted(data))
        for node, keys in KNOWN.items():
            self.assertEqual(set(data[node]), keys, node)
            for k, v in data[node].items():
                self.assertIsInstance(v, float, "%s/%s = %r is not a float" % (node, k, v))

        sim = launch(SIM_PORT, ["sim.launch", "headless:=true", "gains:=" + gains, "duration:=3"], 200)
        self.assertEqual(sim.returncode, 0, "sim.launch with the tuned gains failed:\n" + sim.stdout[-4000:])
        self.assertIn("| ITAE | y |", sim.stdout, "run_monitor printed no metric table:\n" + sim.stdout[-4000:])
        self.assertNotIn("refusing to start", sim.stdout)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "tune_small_test", TuneSmall)
