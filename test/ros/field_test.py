#!/usr/bin/env python3
"""rostest (lockstep field run): follows the robot to the end of the scenario and checks, on the BODY
(plant_sim's latched `footprint`, the URDF's collision outline, placed at every odom pose; obstacles from
the generator's latched `plan`), its smallest clearance from every obstacle surface and that plant_sim
reported no contact; optionally (~max_yaw_rate, ~max_lateral_accel) that the robot's |omega| and
|v omega| stayed within bounds over the whole run; that it ends near (end_x, end_y); and the seed
drill's cross-track report for seeds away from obstacles: its final report (stamped at the run's end, sent
once the drill has taken the final state), checked to count every seed the drill showed on `seeds` and every
seed of its record on `seeds/record`; each recorded seed in time order, on its row (its nearest row of the plan,
within ~max_row_error unless a detour seed, the farthest at the report's rows_max), at a depth inside the
agronomic band, and believed where it fell (the controllers are fed the true state here)."""
import math
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import PolygonStamped
from nav_msgs.msg import Odometry
from sowing_robot.msg import Contact, FieldPlan, Seed
from std_msgs.msg import Float64MultiArray
from visualization_msgs.msg import MarkerArray

import links

TIMEOUT = 60.0  # [s wall] for the latched footprint and plan
# [s wall] for the drill's final report once the run has ended: only bounds a hang (the drill, which the
# plant does not wait for, catches up in well under a second on an idle machine)
REPORT_TIMEOUT = 120.0


def segment_distance(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy))) if dx or dy else 0.0
    return math.hypot(px - ax - t * dx, py - ay - t * dy)


def body_clearance(polygon, x, y, theta, cx, cy, radius):
    """Signed distance from the polygon (base_link) placed at (x, y, theta) to a disc: < 0 overlaps."""
    c, s = math.cos(theta), math.sin(theta)
    # the disc's centre in base_link
    qx, qy = c * (cx - x) + s * (cy - y), -s * (cx - x) + c * (cy - y)
    n = len(polygon)
    edge = min(segment_distance(qx, qy, *polygon[i], *polygon[(i + 1) % n]) for i in range(n))
    inside = False
    for i in range(n):
        (ax, ay), (bx, by) = polygon[i], polygon[(i + 1) % n]
        if (ay > qy) != (by > qy) and qx < (bx - ax) * (qy - ay) / (by - ay) + ax:
            inside = not inside
    return (-edge if inside else edge) - radius


class FieldRun(unittest.TestCase):
    def test_field(self):
        rospy.init_node("field_test")
        duration = rospy.get_param("~duration")
        margin = rospy.get_param("~safety_margin")
        max_yaw_rate = rospy.get_param("~max_yaw_rate", float("inf"))
        max_lateral = rospy.get_param("~max_lateral_accel", float("inf"))
        footprint = rospy.wait_for_message("footprint", PolygonStamped, timeout=TIMEOUT)
        plan = rospy.wait_for_message("plan", FieldPlan, timeout=TIMEOUT)
        polygon = [(q.x, q.y) for q in footprint.polygon.points]
        obstacles = [(c.x, c.y, r) for c, r in zip(plan.obstacle_centres, plan.obstacle_radii)]
        self.assertGreater(len(polygon), 2, "no footprint from plant_sim")
        state = {"min_clear": float("inf"), "last": None, "report": None, "yaw": 0.0, "lateral": 0.0, "contacts": [],
                 "chunks": {}, "records": []}

        def on_seeds(m):  # each message: the chunk of seeds that grew by one; seeds = the chunks' sizes added up
            for marker in m.markers:
                state["chunks"][marker.id] = max(state["chunks"].get(marker.id, 0), len(marker.points))

        def on_report(m):
            if state["report"] is None or m.data[-1] >= state["report"][-1]:  # latched: the newest stamp holds
                state["report"] = m.data

        def seeds_shown():
            return sum(state["chunks"].values())

        def final_report():
            r = state["report"]
            return r if r is not None and r[-1] >= duration - 1e-6 else None

        def on_odom(m):
            p, q = m.pose.pose.position, m.pose.pose.orientation
            theta = 2.0 * math.atan2(q.z, q.w)
            for cx, cy, r in obstacles:
                state["min_clear"] = min(state["min_clear"], body_clearance(polygon, p.x, p.y, theta, cx, cy, r))
            v, w = m.twist.twist.linear.x, m.twist.twist.angular.z
            state["yaw"] = max(state["yaw"], abs(w))
            state["lateral"] = max(state["lateral"], abs(v * w))
            state["last"] = m

        # One message per seed, from the first: linked before the tester's ground_truth lets the plant start.
        rospy.Subscriber("seeds/record", Seed, state["records"].append, queue_size=100000)
        self.assertIsNone(links.wait_until_linked(["seeds/record"], TIMEOUT), "seeds/record not linked")
        rospy.Subscriber("ground_truth", Odometry, on_odom, queue_size=100000)
        rospy.Subscriber("contacts", Contact, lambda m: state["contacts"].append(m), queue_size=100)
        rospy.Subscriber("seed_report", Float64MultiArray, on_report, queue_size=100)
        rospy.Subscriber("seeds", MarkerArray, on_seeds, queue_size=100000)
        t0 = time.time()
        while not rospy.is_shutdown():
            last = state["last"]
            if last is not None and last.header.stamp.to_sec() >= duration - 1e-6:
                break
            self.assertLess(time.time() - t0, 360.0, "the run did not reach t = %.1f s" % duration)
            time.sleep(0.05)
        # The drill's final report, and every seed it showed and recorded counted in it (the report, the seeds
        # and the record come on three topics: wait for all).
        t1 = time.time()
        while not rospy.is_shutdown():
            r = final_report()
            if r is not None and r[0] + r[4] == seeds_shown() == len(state["records"]):
                break
            self.assertLess(time.time() - t1, REPORT_TIMEOUT,
                            "no final seed report counting all %d seeds shown and %d recorded (latest report: %s)" %
                            (seeds_shown(), len(state["records"]), state["report"]))
            time.sleep(0.05)
        p = state["last"].pose.pose.position
        rows_count, rows_max, rows_rms, rows_over, det_count, det_max, det_rms, _stamp = final_report()
        print("field: min body clearance %.3f m, %d contact message(s), peak |omega| %.3f rad/s, peak |v omega| "
              "%.3f m/s^2, end (%.3f, %.3f), seeds on rows %d (max %.4f m, RMS %.4f m, %.1f %% over tolerance), "
              "detour seeds %d (max %.3f m); final report at t = %.3f s" %
              (state["min_clear"], len(state["contacts"]), state["yaw"], state["lateral"], p.x, p.y, rows_count,
               rows_max, rows_rms, 100 * rows_over, det_count, det_max, _stamp))
        if obstacles:
            self.assertGreaterEqual(state["min_clear"], margin, "body clearance below the safety margin")
        self.assertEqual(state["contacts"], [], "plant_sim reported a contact")
        self.assertLessEqual(state["yaw"], max_yaw_rate, "peak yaw rate over its bound")
        self.assertLessEqual(state["lateral"], max_lateral, "peak lateral acceleration over its bound")
        self.assertLess(math.hypot(p.x - rospy.get_param("~end_x"), p.y - rospy.get_param("~end_y")), 1.0)
        self.assertGreaterEqual(rows_count, rospy.get_param("~min_row_seeds"))
        self.assertLess(rows_max, rospy.get_param("~max_row_error"))
        self.check_record(state["records"], plan, rows_count, rows_max, det_count)

    def check_record(self, records, plan, rows_count, rows_max, det_count):
        rows = [(a.x, a.y, b.x, b.y) for a, b in zip(plan.row_starts, plan.row_ends)]
        depth_min = rospy.get_param("/seed_drill/depth_min", 0.03)
        depth_max = rospy.get_param("/seed_drill/depth_max", 0.05)
        stamps = [m.header.stamp for m in records]
        self.assertEqual(stamps, sorted(stamps), "seed record out of time order")
        self.assertEqual(sum(1 for m in records if m.detour), det_count)
        farthest = 0.0
        for m in records:
            p = m.position
            self.assertTrue(0 <= m.row < len(rows), "seed at (%.3f, %.3f) on row %d of %d" % (p.x, p.y, m.row, len(rows)))
            self.assertEqual(m.header.frame_id, rospy.get_param("/run/odom_frame", "odom"))
            self.assertTrue(depth_min <= m.depth <= depth_max, "depth %.4f m outside the band" % m.depth)
            self.assertEqual((m.believed.x, m.believed.y), (p.x, p.y), "believed elsewhere than the truth")
            d = segment_distance(p.x, p.y, *rows[m.row])
            self.assertAlmostEqual(d, min(segment_distance(p.x, p.y, *r) for r in rows), delta=1e-12)
            if not m.detour:
                farthest = max(farthest, d)
        self.assertEqual(len(records) - det_count, rows_count)
        self.assertAlmostEqual(farthest, rows_max, delta=1e-9)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "field_test", FieldRun)
