#!/usr/bin/env python3
"""rostest: plant_sim with one bad traction/ or field/patches parameter at a time refuses to start
(exit 1) with a line naming the key. The traction parameters are checked also with traction off."""
import unittest

import rospy
import rostest

import node_process

SQUARE = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]

CASES = [
    # ({private param: value}, text that must appear)
    ({"traction/mu_peak": -0.2}, "traction/mu_peak"),
    ({"traction/mu_peak": float("nan")}, "traction/mu_peak"),
    ({"traction/mu_slide": 0.7}, "traction/mu_slide"),  # above mu_peak 0.6
    ({"traction/draft_force": -5.0}, "traction/draft_force"),
    ({"traction/substeps": 0}, "traction/substeps"),
    ({"traction/enabled": True, "traction/rolling_resistance": float("inf")}, "traction/rolling_resistance"),
    ({"traction/sllip_peak": 0.1}, "traction/sllip_peak"),  # typo: unknown key
    ({"field/patches": [{"polygon": SQUARE[:2], "mu_peak": 0.2, "mu_slide": 0.1}]}, "field/patches[0]/polygon"),
    ({"field/patches": [{"polygon": SQUARE, "mu_peak": 0.2, "mu_slide": 0.3}]}, "field/patches[0]/mu_slide"),
    ({"field/patches": [{"polygon": SQUARE, "mu_peak": -0.2, "mu_slide": 0.0}]}, "field/patches[0]/mu_peak"),
    ({"field/patches": [{"polygon": SQUARE}, {"polygon": SQUARE, "rolling_resistance": -1.0}]},
     "field/patches[1]/rolling_resistance"),
    ({"field/patches": [{"polygon": [[0.0, 0.0], [1.0, float("nan")], [1.0, 1.0]]}]}, "field/patches[0]/polygon[1]"),
    ({"field/patches": [{"polygon": SQUARE, "grip": 0.2}]}, "unknown key 'grip'"),
]


class BadTractionParameters(unittest.TestCase):
    def test_each_bad_parameter_stops_the_plant(self):
        rospy.init_node("bad_traction_param_test")
        for i, (params, needle) in enumerate(CASES):
            name = "bad_traction_%d" % i
            node_process.set_private_params("/" + name, params)
            proc = node_process.run("plant_sim", name)
            out = proc.stdout
            self.assertEqual(proc.returncode, 1, "%s: exit %d\n%s" % (params, proc.returncode, out))
            self.assertIn("refusing to start", out, "%s:\n%s" % (params, out))
            self.assertIn(needle, out, "%s: message does not name '%s':\n%s" % (params, needle, out))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "bad_traction_param_test", BadTractionParameters)
