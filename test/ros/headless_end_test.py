#!/usr/bin/env python3
"""rostest: the end of a headless run. Through `rosrun sowing_robot sim` (what scripts/run calls):
  * a normal end prints the metric table once, no "REQUIRED process ... has died!" banner, exits 0;
  * `controller:=foo` (as processes and as nodelets) ends at once with exit 1 and torque_controller's FATAL
    line as the last line;
  * a lockstep give-up (plant_sim waiting for 50 odom subscribers, lockstep_give_up 3 s) exits 3 with
    plant_sim's FATAL line last;
  * a run that does not complete its field: one that ends on "no traction" exits 5, one whose plan stops short
    of the field (a row end inside an obstacle) exits 6, each with run_monitor's FATAL line (where and why) last,
    as processes and as nodelets. (Before, both exited 0 like a completed run.)
Through plain `roslaunch sim.launch headless:=true controller:=foo`: the launch ends at once (every node
is required when headless), not after lockstep_give_up (120 s).

Verified to fail without the fix: with scripts/run's old `roslaunch` call the codes are 0 and the last
lines roslaunch's; without sim.launch's `required` on every headless node the plain-roslaunch refusal
runs into the 60 s bound (the plant waits 120 s for torques)."""
import os
import tempfile
import unittest

import node_process
import rostest

BOUND = 60.0  # [s wall] for a run that must end "at once": start-up of every node plus shutdown


def sim(port, *args, timeout=240):
    return node_process.sim(port, args, timeout)


def last_line(out):
    return out.rstrip().splitlines()[-1]


class HeadlessEnd(unittest.TestCase):
    def check_normal_end(self, port, *args):
        code, out, _ = sim(port, "field:=line", "duration:=2.0", *args)
        self.assertEqual(code, 0, out[-4000:])
        self.assertEqual(out.count("| ITAE | y |"), 1, "the metric table is not printed exactly once:\n" + out[-4000:])
        self.assertNotIn("REQUIRED process", out)
        self.assertEqual(last_line(out), "sim: the run ended normally")

    def test_normal_end(self):
        self.check_normal_end(11671)

    # Hung 1 in ~10 under load before plant_sim waited for every node by name (ros/common/ready_roster.h): a
    # 25 s line run could end before run_monitor had loaded into the manager.
    def test_normal_end_nodelets(self):
        self.check_normal_end(11672, "nodelets:=true")

    def check_refusal(self, port, *args):
        code, out, seconds = sim(port, "controller:=foo", *args, timeout=BOUND)
        self.assertEqual(code, 1, out[-4000:])
        self.assertLess(seconds, BOUND)
        last = last_line(out)
        self.assertIn("[FATAL]", last)
        self.assertIn("/torque_controller: refusing to start: /torque_controller/inner = 'foo'", last)

    def test_refusal_ends_the_run_at_once(self):
        self.check_refusal(11673)

    def test_refusal_of_a_nodelet_ends_the_run_at_once(self):
        self.check_refusal(11674, "nodelets:=true")

    def check_give_up(self, port, *args):
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            # odom subscribers that never come: the plant waits for the loop to connect, then gives up
            f.write("plant_sim: {lockstep_give_up: 3.0, min_subscribers: 50}\n")
        code, out, _ = sim(port, "field:=line", "duration:=3.0", "config:=" + f.name, *args)
        os.unlink(f.name)
        self.assertEqual(code, 3, out[-4000:])
        last = last_line(out)
        self.assertIn("[FATAL]", last)
        self.assertIn("plant_sim: lockstep gave up", last)

    def test_give_up(self):
        self.check_give_up(11675)

    def test_give_up_of_a_plant_nodelet_ends_the_run(self):
        # The plant nodelet stops only its run (the manager lives on); the runner ends the run with 3.
        self.check_give_up(11677, "nodelets:=true")

    def check_end_code(self, port, overlay, duration, code, words, *args):
        ros_dir = os.path.dirname(os.path.abspath(__file__))
        got, out, _ = sim(port, "field:=line", "config:=" + os.path.join(ros_dir, overlay), "duration:=%g" % duration,
                          *args)
        self.assertEqual(got, code, out[-4000:])
        self.assertNotIn("REQUIRED process", out)
        last = last_line(out)
        self.assertIn("[FATAL]", last)
        for w in words:
            self.assertIn(w, last)

    def test_no_traction_exits_5(self):
        # no_traction.test's field: the verdict at t = 19.6 s, the run ends 3 s later, before its duration.
        self.check_end_code(11678, "no_traction_overlay.yaml", 40.0, 5,
                            ["run_monitor: the run ended on no traction: no traction at (", "ended at t = 22."])

    def test_stopped_short_exits_6(self):
        # stop_hold.test's field: a 20 m row whose end lies inside an obstacle. The code comes from the plan's status
        # (run_monitor has it from the latched plan at the start), not from where the robot is when the run ends, so
        # 10 s do (the reference stops at t = 23 s; stop_hold.test checks the hold there).
        self.check_end_code(11679, "stop_hold_field.yaml", 10.0, 6,
                            ["run_monitor: the run stopped short of its field: stopped_short", "ended at t = 10.000 s"])

    def test_stopped_short_exits_6_nodelets(self):
        self.check_end_code(11680, "stop_hold_field.yaml", 10.0, 6,
                            ["run_monitor: the run stopped short of its field: stopped_short"], "nodelets:=true")

    def test_plain_roslaunch_refusal_ends_at_once(self):
        cmd = ["roslaunch", "-p", "11676", "sowing_robot", "sim.launch", "headless:=true", "controller:=foo"]
        code, out, seconds = node_process.run_on_master(11676, cmd, timeout=BOUND)
        self.assertLess(seconds, BOUND, out[-3000:])
        self.assertIn("/torque_controller: refusing to start: /torque_controller/inner = 'foo'", out)
        self.assertIn("REQUIRED process [torque_controller", out)  # as well as plain roslaunch can say it


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "headless_end_test", HeadlessEnd)
