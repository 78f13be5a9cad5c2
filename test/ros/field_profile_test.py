#!/usr/bin/env python3
"""rostest: `sim profile:=field` (sim.launch through the sim runner, headless, lockstep, the thesis line, 3 s,
recorded) comes up with the field set-up, finishes normally, and publishes the torque the motors applied beside
the one commanded: on applied_torque (every period) and in joint_states' effort, different from the command while
the motors limit it (the sliding-mode controller asks up to its 100 N.m clip at the start; the motors give at most
their 6.4 N.m current limit), with the traction control's verdicts on traction_control/state. And every profile's
feedback (profile/feedback in config/profiles/NAME.yaml) is the one sim.launch profile:=NAME runs with: the launch
must know it before it reads the file (launch/sim.launch), so this is where the two are held together.

Fails without the feature: without plant_sim's motors or its applied_torque the bag has no applied torque below the
command; without the profile in sim.launch the launch refuses profile:= (or runs without the layers)."""
import glob
import os
import subprocess
import tempfile
import unittest

import node_process
import rosbag
import roslib.packages
import rostest
import yaml

PACKAGE = roslib.packages.get_pkg_dir("sowing_robot")
CURRENT_LIMIT = 6.4  # plant_sim motor/current_limit's default [N.m] (core/model/motor.h)


def launch_view(*args):
    """(params, node names) of sim.launch with these args, as roslaunch resolves them (no master needed)."""
    cmd = ["roslaunch", "sowing_robot", "sim.launch", "headless:=true"] + list(args)
    params = yaml.safe_load(subprocess.run(cmd[:1] + ["--dump-params"] + cmd[1:], stdout=subprocess.PIPE,
                                           universal_newlines=True, check=True, timeout=120).stdout)
    nodes = subprocess.run(cmd[:1] + ["--nodes"] + cmd[1:], stdout=subprocess.PIPE, universal_newlines=True,
                           check=True, timeout=120).stdout.split()
    return params, nodes


def launched_feedback(params, nodes):
    """What the controllers close the loop on, from the launch's topology: the EKF (fused), the encoders'
    odom (odometry) or the truth."""
    if "/state_estimator" in nodes:
        return "fused"
    return "odometry" if params["/plant_sim/loop_topic"] == "odom" else "ground_truth"


class FieldProfile(unittest.TestCase):
    def test_every_profiles_feedback_is_the_launchs(self):
        files = sorted(glob.glob(os.path.join(PACKAGE, "config", "profiles", "*.yaml")))
        self.assertTrue(files)
        for path in files:
            name = os.path.basename(path)[:-5]
            with open(path) as f:
                profile = yaml.safe_load(f)["profile"]
            params, nodes = launch_view("profile:=" + name)
            self.assertEqual(params["/profile/name"], name)
            self.assertEqual(launched_feedback(params, nodes), profile.get("feedback", "ground_truth"),
                             "sim.launch profile:=%s runs with another feedback than %s says" % (name, path))
        params, nodes = launch_view()  # the thesis configuration: no profile, the truth fed back
        self.assertNotIn("/profile/name", params)
        self.assertEqual(launched_feedback(params, nodes), "ground_truth")

    def test_field_run_applies_less_torque_than_commanded_and_ends(self):
        bag = os.path.join(tempfile.mkdtemp(prefix="sowing_field_profile_"), "run.bag")
        code, out, _ = node_process.sim(11685, ["profile:=field", "field:=line", "duration:=3.0", "record:=full",
                                                "bag:=" + bag], timeout=300)
        self.assertEqual(code, 0, out[-4000:])
        self.assertEqual(out.rstrip().splitlines()[-1], "sim: the run ended normally")
        for line in ("traction/enabled true", "motor/enabled true", "traction_control/enabled true",
                     "speed_governor/enabled true", "traction control on",
                     "motors: the applied torque differed from the command"):
            self.assertTrue(line in out, "'%s' not in the run's output:\n%s" % (line, out[-3000:]))
        commanded, applied, effort, verdicts = {}, {}, {}, 0
        with rosbag.Bag(bag) as b:
            for topic, m, _ in b.read_messages(["/wheel_torque", "/applied_torque", "/joint_states",
                                                "/traction_control/state"]):
                k = m.header.stamp.to_nsec()
                if topic == "/wheel_torque":
                    commanded[k] = (m.right, m.left)
                elif topic == "/applied_torque":
                    applied[k] = (m.right, m.left)
                elif topic == "/joint_states":
                    effort[k] = tuple(m.effort)
                else:
                    verdicts += 1
        self.assertEqual(len(applied), 3000)  # every step's, stamped with its command (t_0 .. t_2999)
        self.assertEqual(set(applied) - set(commanded), set())
        limited = [k for k in applied if applied[k] != commanded[k]]
        self.assertGreater(len(limited), 0, "the motors never limited the torque")
        self.assertTrue(any(max(map(abs, commanded[k])) > CURRENT_LIMIT for k in limited))
        self.assertTrue(all(max(map(abs, a)) <= CURRENT_LIMIT + 1e-9 for a in applied.values()))
        # joint_states' effort at a state is the torque of the step that led to it
        period = 1000000
        shared = [k for k in effort if k - period in applied]
        self.assertGreater(len(shared), 100)
        self.assertTrue(all(effort[k] == applied[k - period] for k in shared))
        self.assertEqual(verdicts, len(commanded))  # one traction-control verdict per command


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "field_profile", FieldProfile)
