#!/usr/bin/env python3
"""rostest: start a node with one bad parameter at a time; it must refuse to start (exit 1) with a line
naming the parameter, and never begin publishing."""
import os
import unittest

import rospy
import rostest
import rospkg

import node_process

URDF = os.path.join(rospkg.RosPack().get_path("sowing_robot"), "urdf", "sowing_robot.urdf")

CASES = [
    # (node type, {private param: value}, text that must appear)
    ("plant_sim", {"mode": "bogus"}, "mode"),
    ("plant_sim", {"duration": -1.0}, "duration"),
    ("plant_sim", {"disturbance/amplitude": float("nan")}, "disturbance/amplitude"),
    ("plant_sim", {"mismatch/mass_scale": 0.0}, "mass_scale"),
    ("plant_sim", {"torque_timout": 0.2}, "torque_timout"),  # typo: unknown key
    ("plant_sim", {"control_rate": "fast"}, "control_rate"),  # wrong type
    ("plant_sim", {"min_subscribers": 2.5}, "min_subscribers"),  # not an integer (roscpp would truncate)
    ("plant_sim", {"robot_description": "ZERO_RADIUS"}, "radius"),
    # the sensors: negative, NaN, out of range, an unknown sensor key, the feedback topic
    ("plant_sim", {"sensors/encoder/ticks_per_turn": 0}, "/bad_%d/sensors/encoder/ticks_per_turn = 0"),
    ("plant_sim", {"sensors/encoder/noise": -0.5}, "/bad_%d/sensors/encoder/noise = -0.5"),
    ("plant_sim", {"sensors/imu/noise": float("nan")}, "/bad_%d/sensors/imu/noise = "),
    ("plant_sim", {"sensors/imu/bias": 2.0}, "/bad_%d/sensors/imu/bias = 2"),
    ("plant_sim", {"sensors/fix/rate": 0.0}, "/bad_%d/sensors/fix/rate = 0"),
    ("plant_sim", {"sensors/fix/sigma": -0.02}, "/bad_%d/sensors/fix/sigma = -0.02"),
    ("plant_sim", {"sensors/fix/latency": float("nan")}, "/bad_%d/sensors/fix/latency = "),
    ("plant_sim", {"sensors/fix/dropout_duration": -1.0}, "/bad_%d/sensors/fix/dropout_duration = -1"),
    ("plant_sim", {"sensors/fix/ratee": 5.0}, "sensors/fix/ratee"),  # typo: unknown key
    ("plant_sim", {"loop_topic": "fused"}, "loop_topic"),
    ("plant_sim", {"robot_description": "<robot name='x'>"}, "robot_description"),
    ("torque_controller", {"p": 4}, "p/q"),
    ("torque_controller", {"m0_min": 40.0}, "m0_min"),
    ("torque_controller", {"m0_initial": 50.0}, "m0_initial"),
    ("torque_controller", {"switching": "magic"}, "switching"),
    ("torque_controller", {"mode": "pid"}, "mode"),
    ("kinematic_controller", {"kx": -1.0}, "kx"),
    # the controller pair: an unknown name, a typo of a baseline's key, and a bad value of a
    # parameter of a controller not selected (checked although inert)
    ("kinematic_controller", {"outer": "stanley"}, "outer"),
    ("torque_controller", {"inner": "lqr"}, "inner"),
    ("torque_controller", {"inner": "atsmc"}, "one of sliding_mode, pid"),  # atsmc is a mode, not an inner
    ("kinematic_controller", {"lookahead_distance": 0.6}, "lookahead_distance"),  # typo: unknown key
    ("torque_controller", {"kpp": 1.0}, "kpp"),  # typo: unknown key
    ("kinematic_controller", {"lookahead_dist": 2.0}, "lookahead_dist"),  # above max_lookahead_dist, outer kanayama
    ("torque_controller", {"inner": "pid", "kp": -1.0}, "kp"),
    ("torque_controller", {"inner": "pid", "feedforward": 3.0}, "feedforward"),
    ("kinematic_controller", {"ky": float("inf")}, "ky"),
    ("reference_generator", {"line/v_r": -1.0}, "v_r"),
    # a key the configuration does not read is refused like an unknown one: field keys with type line
    ("reference_generator", {"field/rows": 0}, "is set but type is not 'field'"),
    # the path follower: path keys with another type, a bad value, a malformed point, a typo
    ("reference_generator", {"path/v_max": 0.5}, "is set but type is not 'path'"),
    ("reference_generator", {"type": "path", "path/v_max": -1.0}, "/bad_%d/path/v_max = -1"),
    ("reference_generator", {"type": "path", "path/points": [[0, 0], [1]]}, "/bad_%d/path/points[1] must be a pair"),
    ("reference_generator", {"type": "path", "path/points": []}, "is an empty list"),
    ("reference_generator", {"type": "path", "path/v_maxx": 1.0}, "path/v_maxx"),
    # a run-wide setting is set once (run/): a node's own copy that disagrees names both values
    ("torque_controller", {"control_rate": 500.0}, "disagrees with /run/control_rate = 1000.0"),
    ("plant_sim", {"duration": 60.0}, "disagrees with /run/duration = 25.0"),
    # the drive train: a bad value or a typo of each layer, motors that cannot move the robot, and
    # the speed governor without the traction control whose verdicts it needs
    ("plant_sim", {"motor/stall_torque": -1.0}, "/bad_%d/motor/stall_torque = -1"),
    ("plant_sim", {"motor/enabld": True}, "motor/enabld"),
    ("plant_sim", {"traction/enabled": True, "traction/rolling_resistance": 0.15, "motor/enabled": True,
                   "motor/current_limit": 0.5}, "motor/current_limit 0.5 N"),
    ("torque_controller", {"traction_control/cut_rate": 0.0}, "/bad_%d/traction_control/cut_rate = 0"),
    ("torque_controller", {"traction_control/min_torque": 5.0, "traction_control/max_torque": 2.0},
     "must not exceed traction_control/max_torque 2 N"),
    ("reference_generator", {"speed_governor/min_rate": 1.5}, "/bad_%d/speed_governor/min_rate = 1.5"),
    ("reference_generator", {"speed_governor/enabled": True},
     "/bad_%d/speed_governor/enabled needs /torque_controller/traction_control/enabled"),
]


def zero_radius_urdf():
    with open(URDF) as f:
        text = f.read()
    return text.replace('radius="0.095"', 'radius="0.0"')


class BadParameters(unittest.TestCase):
    def test_each_bad_parameter_stops_the_node(self):
        rospy.init_node("bad_param_test")
        for i, (node, params, needle) in enumerate(CASES):
            name = "bad_%d" % i
            node_process.set_private_params(
                "/" + name, {k: zero_radius_urdf() if v == "ZERO_RADIUS" else v for k, v in params.items()})
            proc = node_process.run(node, name)
            out = proc.stdout
            self.assertEqual(proc.returncode, 1, "%s %s: exit %d\n%s" % (node, params, proc.returncode, out))
            self.assertIn("refusing to start", out, "%s %s:\n%s" % (node, params, out))
            if "%d" in needle:
                needle = needle % i  # the key's full name, in this case's namespace
            self.assertIn(needle, out, "%s %s: message does not name '%s':\n%s" % (node, params, needle, out))
            fatal = [line for line in out.splitlines() if "[FATAL]" in line]
            self.assertEqual(len(fatal), 1, "%s %s: expected one FATAL line:\n%s" % (node, params, out))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "bad_param_test", BadParameters)
