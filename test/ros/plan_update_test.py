#!/usr/bin/env python3
"""rostest: an obstacles message at run time is re-published on the latched `plan` (rows, obstacles,
status) and reaches seed_drill, which logs the plan it now scores against."""
import threading
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Log
from sowing_robot.msg import FieldPlan
from visualization_msgs.msg import Marker, MarkerArray

TIMEOUT = 30.0  # [s wall] for each message to arrive; every wait ends as soon as its condition holds


def cylinder(i, x, y, radius):
    m = Marker()
    m.header.frame_id = "odom"
    m.ns, m.id, m.type, m.action = "test", i, Marker.CYLINDER, Marker.ADD
    m.pose.position.x, m.pose.position.y = x, y
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = 2.0 * radius
    m.scale.z = 0.5
    return m


class PlanUpdate(unittest.TestCase):
    def setUp(self):
        rospy.init_node("plan_update_test")
        self.cond = threading.Condition()
        self.plans, self.drill_logs = [], []
        self.subs = [rospy.Subscriber("/plan", FieldPlan, self.on_plan, queue_size=10),
                     rospy.Subscriber("/rosout", Log, self.on_log, queue_size=100)]

    def on_plan(self, msg):
        with self.cond:
            self.plans.append(msg)
            self.cond.notify_all()

    def on_log(self, msg):
        if msg.name == "/seed_drill":
            with self.cond:
                self.drill_logs.append(msg.msg)
                self.cond.notify_all()

    def wait_for(self, what, condition):
        with self.cond:
            self.assertTrue(self.cond.wait_for(condition, TIMEOUT), "no %s within %.0f s" % (what, TIMEOUT))

    def test_an_obstacle_added_at_run_time_reaches_the_plan_and_the_drill(self):
        self.wait_for("first plan", lambda: self.plans)
        # The drill's log reaches us only over our own link to its /rosout: have it before the drill logs.
        rosout = self.subs[1].impl
        deadline = time.time() + TIMEOUT
        while not any((getattr(c, "header", None) or {}).get("callerid") == "/seed_drill" for c in rosout.connections):
            self.assertLess(time.time(), deadline, "no /rosout link to /seed_drill within %.0f s" % TIMEOUT)
            time.sleep(0.02)
        first = self.plans[0]
        self.assertEqual(len(first.obstacle_radii), 3)  # config/field_thesis.yaml
        self.assertEqual(first.status, "ok")
        pub = rospy.Publisher("/obstacles", MarkerArray, queue_size=1, latch=True)
        obstacles = [(20.0, 3.0, 0.3), (50.0, 3.0, 0.3), (80.0, 3.0, 0.3), (65.0, 3.2, 0.4)]
        pub.publish(MarkerArray(markers=[cylinder(i, *o) for i, o in enumerate(obstacles)]))
        self.wait_for("plan with the added obstacle", lambda: any(len(p.obstacle_radii) == 4 for p in self.plans))
        plan = [p for p in self.plans if len(p.obstacle_radii) == 4][0]
        self.assertAlmostEqual(plan.obstacle_centres[3].x, 65.0)
        self.assertAlmostEqual(plan.obstacle_radii[3], 0.4)
        self.assertGreaterEqual(plan.detours, 4)
        # "plan changed: ..." when the drill had the first plan; "plan of ...: sowing" if it connected only now
        # (the plan is latched): either way it scores against the four obstacles.
        self.wait_for("seed_drill taking the new plan", lambda: any("4 obstacle(s)" in m for m in self.drill_logs))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "plan_update_test", PlanUpdate)
