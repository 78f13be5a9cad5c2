#!/usr/bin/env python3
"""rostest (coverage_edges.test): reference_generator with type coverage refuses a field it cannot plan, as every
node refuses a bad parameter (bad_param_test.py): exit 1, "refusing to start", one FATAL line naming the file (or the
key) and what is wrong with it."""
import os
import unittest

import rospkg
import rospy
import rostest

import node_process

PKG = rospkg.RosPack().get_path("sowing_robot")
FIELDS = os.path.join(PKG, "test", "ros", "fields")
L_FIELD = os.path.join(PKG, "config", "fields", "l_field.geojson")

CASES = [
    # ({private param: value}, texts that must all appear in the FATAL line)
    ({"field_file": os.path.join(FIELDS, "bow_tie.yaml")}, ["bow_tie.yaml: ", "the field boundary", "crosses itself"]),
    ({"field_file": os.path.join(FIELDS, "void_outside.yaml")}, ["void_outside.yaml: ", "lies outside the field"]),
    ({"field_file": os.path.join(FIELDS, "narrow_strip.yaml")},
     ["narrow_strip.yaml: ", "the field is narrower than one swath (1 m) plus its 2 headland"]),
    ({"field_file": os.path.join(FIELDS, "no_origin.geojson")}, ["no_origin.geojson: ", "without an origin"]),
    ({"field_file": L_FIELD, "coverage/row_spacing": 0.0}, ["/bad_%d/coverage/row_spacing = 0", "> 0"]),
    ({"field_file": L_FIELD, "field_origin": "48.4,north"}, ["/bad_%d/field_origin = '48.4,north'"]),
    ({"field_file": os.path.join(FIELDS, "missing.geojson")}, ["missing.geojson"]),
    ({}, ["/bad_%d/field_file is not set"]),
    # the rows' layout is the file's: of field/ only the speeds are read, the rest is refused as unknown
    ({"field_file": L_FIELD, "field/rows": 3}, ["field/rows"]),
    # and the coverage keys with another type
    ({"type": "line", "coverage/row_spacing": 0.5}, ["is set but type is not 'coverage'"]),
]


class CoverageEdges(unittest.TestCase):
    def test_each_unplannable_field_stops_the_node(self):
        rospy.init_node("coverage_edges_test")
        for i, (params, needles) in enumerate(CASES):
            name = "bad_%d" % i
            node_process.set_private_params("/" + name, dict({"type": "coverage"}, **params))
            proc = node_process.run("reference_generator", name)
            out = proc.stdout
            self.assertEqual(proc.returncode, 1, "%s: exit %d\n%s" % (params, proc.returncode, out))
            fatal = [line for line in out.splitlines() if "[FATAL]" in line]
            self.assertEqual(len(fatal), 1, "%s: expected one FATAL line:\n%s" % (params, out))
            self.assertIn("refusing to start", fatal[0], "%s:\n%s" % (params, out))
            for needle in needles:
                if "%d" in needle:
                    needle = needle % i
                self.assertIn(needle, fatal[0], "%s: the FATAL line does not say '%s':\n%s" % (params, needle, out))
            print("coverage_edges: %s" % fatal[0])


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "coverage_edges_test", CoverageEdges)
