#!/usr/bin/env python3
"""rostest: recording. (1) `sim.launch headless:=true record:=full field:=line duration:=10` leaves a bag
whose analyze_bag metrics (full precision, --yaml) equal run_monitor's metrics_output and the in-process
runner's (run_scenario --yaml) exactly, with no missing period, and whose seed record (`seeds/record`) seed_map
reads into a CSV of seeds on the line. (2) SIGINT in the middle of a recorded
run leaves a closed bag (no .active file) that analyze_bag reads."""
import os
import signal
import subprocess
import tempfile
import time
import unittest

import roslib.packages
import rostest
import yaml


def node(name):
    return roslib.packages.find_node("sowing_robot", name)[0]


def launch(port, *args):
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    return subprocess.Popen(["roslaunch", "-p", str(port), "sowing_robot", "sim.launch", "headless:=true",
                             "record:=full", "field:=line"] + list(args), env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, universal_newlines=True)


def metrics(path):
    with open(path) as f:
        (label, axes), = yaml.safe_load(f).items()
    return axes


class Record(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="sowing_record_")

    def test_bag_equals_run_monitor_and_in_process(self):
        bag, monitor, from_bag, in_process = (os.path.join(self.tmp, n) for n in
                                              ("run.bag", "monitor.yaml", "bag.yaml", "in_process.yaml"))
        proc = launch(11651, "bag:=" + bag, "duration:=10.0", "metrics_output:=" + monitor)
        out, _ = proc.communicate(timeout=300)
        self.assertTrue(os.path.exists(bag), "no bag:\n" + out[-3000:])
        a = subprocess.run([node("analyze_bag"), bag, "--no-plots", "--yaml", from_bag], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
        self.assertEqual(a.returncode, 0, a.stderr)
        self.assertNotIn("missing", a.stderr, "the recorder lost messages: " + a.stderr)
        r = subprocess.run([node("run_scenario"), "--atsmc", "--disturbance", "--mismatch", "1.2", "--duration", "10",
                            "--yaml", in_process], stdout=subprocess.PIPE, universal_newlines=True, timeout=120)
        self.assertEqual(r.returncode, 0)
        m, b, i = metrics(monitor), metrics(from_bag), metrics(in_process)
        print("bag:", b["y"], "\nrun_monitor:", m["y"], "\nin-process:", i["y"])
        self.assertEqual(b, m)
        self.assertEqual(m, i)
        csv = os.path.join(self.tmp, "seeds.csv")
        s = subprocess.run([node("seed_map"), bag, "--csv", csv], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=120)
        self.assertEqual(s.returncode, 0, s.stderr)
        with open(csv) as f:
            lines = f.read().splitlines()
        print(s.stdout.strip())
        self.assertEqual(lines[0], "t,x,y,believed_x,believed_y,row,depth,detour")
        self.assertGreater(len(lines), 10, "hardly a seed recorded")
        for line in lines[1:]:
            t, x, y, bx, by, row, depth, detour = line.split(",")
            self.assertEqual(row, "0")
            self.assertLess(abs(float(y) - float(by)) + abs(float(x) - float(bx)), 1e-12)  # fed the truth

    def test_sigint_leaves_a_readable_bag(self):
        bag = os.path.join(self.tmp, "interrupted.bag")
        proc = launch(11652, "bag:=" + bag, "duration:=60.0")
        deadline = time.time() + 120
        while not os.path.exists(bag + ".active") and time.time() < deadline:
            time.sleep(0.2)
        time.sleep(8.0)  # let it record for a while
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=120)
        self.assertFalse(os.path.exists(bag + ".active"), "the bag was not closed:\n" + out[-2000:])
        self.assertTrue(os.path.exists(bag), out[-2000:])
        a = subprocess.run([node("analyze_bag"), bag, "--no-plots"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        self.assertEqual(a.returncode, 0, a.stderr)
        self.assertIn("| ITAE | y |", a.stdout)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "record_test", Record)
