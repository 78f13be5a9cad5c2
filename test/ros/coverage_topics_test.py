#!/usr/bin/env python3
"""rostest (coverage_topics.test): the coverage plan of a field file through the node pipeline.

The plan on its latched topics in the odom frame: coverage/field (the boundary and the L field's two voids),
coverage/headlands (headland_passes rings round the boundary and round each void: the voids lie apart from each
other and the boundary), coverage/swaths (one pair of points per swath), the rows sent to the seed drill on `plan`
(one per swath, one row per pass, then the headland rings' straight sides, each on its ring), coverage/route (a
nav_msgs/Path from the route's start: the first swath's start, where plant_sim places the robot,
plant_sim/start_at_route). The robot, in lockstep, follows the route along the first swath and the seed drill places
seeds on that swath's row."""
import math
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry, Path
from sowing_robot.msg import FieldPlan, Seed
from std_msgs.msg import Float64MultiArray
from visualization_msgs.msg import Marker, MarkerArray

import links

WALL_TIMEOUT = 90.0
ROW_TOLERANCE = 0.05  # [m] seeds on the row's line (seed_drill/tolerance)
MIN_SEEDS = 20        # 2 m of row at seed_drill/spacing 0.1 m
# The L field's headland rows: the straight sides of its rings, per pass the boundary's 6 and the pond's 6 (the
# power pole's ring is a curve, no row; coverage_planner.h, headlandSide).
HEADLAND_ROWS_PER_PASS = 12


def by_ns(msg):
    """{ns: [markers added]} of a MarkerArray (its leading DELETEALL left out)."""
    out = {}
    for m in msg.markers:
        if m.action == Marker.ADD:
            out.setdefault(m.ns, []).append(m)
    return out


def distance_to_segment(p, a, b):
    ax, ay, bx, by = a.x, a.y, b.x, b.y
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((p.x - ax) * dx + (p.y - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(p.x - ax - t * dx, p.y - ay - t * dy)


class CoverageTopics(unittest.TestCase):
    def test_plan_topics_and_sowing(self):
        rospy.init_node("coverage_topics_test")
        duration = rospy.get_param("/run/duration")
        frame = rospy.get_param("/run/odom_frame", "odom")
        passes = rospy.get_param("/reference_generator/coverage/headland_passes")
        lock = threading.Lock()
        got, seeds, truth, reports = {}, [], set(), []

        def keep(name):
            def cb(m):
                with lock:
                    got[name] = m
            return cb

        def on_seed(m):
            with lock:
                seeds.append(m)

        def on_report(m):
            with lock:
                reports.append(m.data[-1])

        def on_truth(m):
            with lock:
                truth.add(m.header.stamp.to_nsec())

        subs = [rospy.Subscriber("coverage/field", MarkerArray, keep("field")),
                rospy.Subscriber("coverage/headlands", MarkerArray, keep("headlands")),
                rospy.Subscriber("coverage/swaths", MarkerArray, keep("swaths")),
                rospy.Subscriber("coverage/route", Path, keep("route")),
                rospy.Subscriber("plan", FieldPlan, keep("plan")),
                rospy.Subscriber("seeds/record", Seed, on_seed, queue_size=100000),
                rospy.Subscriber("seed_report", Float64MultiArray, on_report, queue_size=100)]
        # Linked before the run can start (links.py), then ground_truth, which the plant counts (min_subscribers).
        self.assertIsNone(links.wait_until_linked(["seeds/record", "seed_report"], WALL_TIMEOUT))
        subs.append(rospy.Subscriber("ground_truth", Odometry, on_truth, queue_size=100000))
        end = int(round(duration * 1e9))
        deadline = time.time() + WALL_TIMEOUT

        def complete():  # every plan topic here, and the run's end reached with the drill's final report
            with lock:
                return (len(got) == 5 and end in truth and any(abs(r - duration) < 1e-6 for r in reports))

        while not complete():
            self.assertLess(time.time(), deadline, "the run did not end, or a plan topic or the final report never "
                            "came: %s" % sorted(got))
            time.sleep(0.05)
        for s in subs:
            s.unregister()

        field, headlands, swaths = by_ns(got["field"]), by_ns(got["headlands"]), by_ns(got["swaths"])
        route, plan = got["route"], got["plan"]
        for name in ("field", "headlands", "swaths"):
            for m in got[name].markers:
                self.assertEqual(m.header.frame_id, frame, "coverage/%s in frame %s" % (name, m.header.frame_id))
        self.assertEqual(route.header.frame_id, frame)
        # the field: its boundary and the L field's two voids (the pond, the pole), each ring closed
        self.assertEqual(len(field.get("boundary", [])), 1)
        self.assertEqual(len(field.get("voids", [])), 2)
        for m in field["boundary"] + field["voids"]:
            self.assertEqual(m.type, Marker.LINE_STRIP)
            self.assertEqual((m.points[0].x, m.points[0].y), (m.points[-1].x, m.points[-1].y), "a ring not closed")
        # headlands: each pass round the boundary and round each void
        self.assertEqual(len(headlands.get("headlands", [])), passes * 3)
        # swaths: one LINE_LIST, a pair of points per swath, one tool row each (rows_per_pass 1) on `plan`
        self.assertEqual(len(swaths.get("swaths", [])), 1)
        lines = swaths["swaths"][0]
        self.assertEqual(lines.type, Marker.LINE_LIST)
        n_swaths = len(lines.points) // 2
        self.assertGreater(n_swaths, 100, "the 1 ha field at 1 m is more than 100 swaths")
        self.assertEqual(len(lines.points), 2 * n_swaths)
        # the rows on `plan` (seed drill): the swaths' in route order, then the headland rows, each on a ring
        self.assertEqual(len(plan.row_starts), n_swaths + passes * HEADLAND_ROWS_PER_PASS,
                         "rows on `plan` (seed drill) != swaths + headland sides")
        self.assertEqual(len(plan.row_ends), len(plan.row_starts))
        for i in range(n_swaths):
            self.assertEqual((plan.row_starts[i].x, plan.row_starts[i].y), (lines.points[2 * i].x, lines.points[2 * i].y))
        rings = headlands.get("headlands", [])
        for i in range(n_swaths, len(plan.row_starts)):
            for end in (plan.row_starts[i], plan.row_ends[i]):
                off = min(distance_to_segment(end, m.points[k], m.points[k + 1])
                          for m in rings for k in range(len(m.points) - 1))
                self.assertLess(off, 1e-6, "headland row %d does not lie on a headland ring" % i)
        self.assertEqual(len(plan.obstacle_radii), 0)
        # the route: from its own start, the first swath's start (no approach from run/start)
        p0 = route.poses[0].pose.position
        first = lines.points[0]
        self.assertLess(math.hypot(p0.x - first.x, p0.y - first.y), 1e-6, "the route does not begin on the first swath")
        # the robot followed it: seeds on the first swath's row, within the tolerance
        with lock:
            sown = list(seeds)
        a, b = plan.row_starts[0], plan.row_ends[0]
        worst = max([distance_to_segment(s.position, a, b) for s in sown] or [float("inf")])
        print("coverage_topics: %d swaths, %d headland rings, route of %d poses; %d seeds in %.1f s, worst %.4f m "
              "from row 0" % (n_swaths, len(headlands["headlands"]), len(route.poses), len(sown), duration, worst))
        self.assertGreaterEqual(len(sown), MIN_SEEDS, "too few seeds: the robot did not reach the first swath")
        self.assertEqual(sorted(set(s.row for s in sown)), [0], "seeds on other rows than the first")
        self.assertLess(worst, ROW_TOLERANCE, "a seed off the first row")
        for s in sown:
            self.assertEqual(s.header.frame_id, frame)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "coverage_topics_test", CoverageTopics)
