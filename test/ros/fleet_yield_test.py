#!/usr/bin/env python3
"""rostest of the run-time yield of a fleet sharing a field (fleet.launch field_file:= headless:=true robots:=2,
lockstep, each run on a ROS master of its own at a free port). The field (test/ros/fields/fleet_yield.yaml) and
the start poses (fleet_yield_overlay.yaml) are such that the plan without its start waits (keep_apart:=false)
brings the two robots closer than the safety distance:
  * run A (yield on, the default with a field file, record:=lean): ends by itself (exit 0); fleet_monitor reports
    no encounter closer than SAFETY and a robot that yielded; that robot's ground_truth shows it standing
    (|v| < 0.02 m/s) for a while, then driving again, and at the end at rest at its path's end (coverage/route);
  * run B (the same): each robot's bag the same file, byte for byte (the verdicts depend on the robots' states at
    the decision stamps only, not on which loop runs ahead);
  * run C (yield:=false): the same plan without the yield: fleet_monitor counts an encounter closer than SAFETY
    (the scenario needs the yield: with it switched off the assertions of run A fail)."""
import math
import os
import re
import socket
import tempfile
import unittest

import rosbag
import rostest

import node_process

HERE = os.path.dirname(os.path.abspath(__file__))
FIELD = os.path.join(HERE, "fields", "fleet_yield.yaml")
OVERLAY = os.path.join(HERE, "fleet_yield_overlay.yaml")
DURATION = 70.0
SAFETY = 0.5          # [m] fleet_monitor's encounter distance
YIELD_DISTANCE = 2.5  # [m] the later robot holds within this


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def fleet(out_dir, *args):
    port = free_port()
    cmd = ["roslaunch", "-p", str(port), "sowing_robot", "fleet.launch", "headless:=true", "robots:=2",
           "field_file:=" + FIELD, "config:=" + OVERLAY, "keep_apart:=false", "duration:=%g" % DURATION,
           "safety_distance:=%g" % SAFETY, "yield_distance:=%g" % YIELD_DISTANCE, "record:=lean",
           "bag_dir:=" + out_dir, "metrics_dir:=" + out_dir] + list(args)
    return node_process.run_on_master(port, cmd, timeout=480)


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def encounters(out):
    m = re.search(r"; (\d+) encounter\(s\) closer than ([\d.]+) m", out)
    return None if m is None else int(m.group(1))


class FleetYield(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="sowing_fleet_yield_")
        cls.runs = {}
        for name, args in (("a", ()), ("b", ()), ("c", ("yield:=false",))):
            d = os.path.join(cls.tmp, name)
            os.makedirs(d)
            cls.runs[name] = (d,) + fleet(d, *args)

    def test_a_the_yield_keeps_the_robots_apart(self):
        d, code, out, _ = self.runs["a"]
        self.assertEqual(code, 0, out[-4000:])
        self.assertEqual(encounters(out), 0, out[-4000:])
        summary = re.search(r"fleet_monitor: yield: decided to t = [\d.]+ s; robot_0 (\d+) yield\(s\), held ([\d.]+) s; "
                            r"robot_1 (\d+) yield\(s\), held ([\d.]+) s;", out)
        self.assertIsNotNone(summary, out[-4000:])
        yields = [int(summary.group(1)), int(summary.group(3))]
        self.assertGreater(sum(yields), 0, summary.group(0))
        self.assertEqual(min(yields), 0, "only the later robot yields: " + summary.group(0))
        print("fleet yield A: " + summary.group(0))

    def test_a_the_yielding_robot_stood_then_finished_its_share(self):
        d, code, out, _ = self.runs["a"]
        self.assertEqual(code, 0, out[-4000:])
        m = re.search(r"fleet_monitor: (robot_\d) yields at t = ([\d.]+) s", out)
        self.assertIsNotNone(m, out[-4000:])
        robot, t_yield = m.group(1), float(m.group(2))
        speeds, poses = [], []
        route_end = None
        with rosbag.Bag(os.path.join(d, robot + ".bag")) as bag:
            for topic, msg, _ in bag.read_messages(topics=["/%s/ground_truth" % robot, "/%s/coverage/route" % robot]):
                if topic.endswith("coverage/route"):
                    route_end = msg.poses[-1].pose.position
                    continue
                t = msg.header.stamp.to_sec()
                speeds.append((t, abs(msg.twist.twist.linear.x)))
                poses.append((msg.pose.pose.position.x, msg.pose.pose.position.y))
        self.assertIsNotNone(route_end, "no coverage/route in the bag")
        # it stood: a second of |v| < 0.02 m/s after the yield began, with the path still ahead of it
        still = [t for t, v in speeds if t > t_yield and v < 0.02]
        self.assertTrue(any(all(v < 0.02 for tt, v in speeds if s <= tt <= s + 1.0) for s in still),
                        "%s never stood after t = %.1f s" % (robot, t_yield))
        stood_at = next(s for s in still if all(v < 0.02 for tt, v in speeds if s <= tt <= s + 1.0))
        # then went on
        self.assertTrue(any(v > 0.3 for t, v in speeds if t > stood_at + 1.0), "%s never drove again" % robot)
        # and finished its share: at rest at its path's end
        end = poses[-1]
        self.assertLess(math.hypot(end[0] - route_end.x, end[1] - route_end.y), 0.3,
                        "%s ended at %s, its path at (%.2f, %.2f)" % (robot, end, route_end.x, route_end.y))
        self.assertLess(speeds[-1][1], 0.02)

    def test_b_a_repeat_gives_the_same_bags(self):
        da, code_a, _, _ = self.runs["a"]
        db, code_b, out_b, _ = self.runs["b"]
        self.assertEqual((code_a, code_b), (0, 0), out_b[-3000:])
        for robot in ("robot_0", "robot_1"):
            self.assertTrue(read_bytes(os.path.join(da, robot + ".bag")) == read_bytes(os.path.join(db, robot + ".bag")),
                            "%s's bag files differ" % robot)

    def test_c_without_the_yield_the_robots_meet(self):
        _, code, out, _ = self.runs["c"]
        self.assertEqual(code, 0, out[-4000:])
        n = encounters(out)
        self.assertIsNotNone(n, out[-4000:])
        self.assertGreater(n, 0, "the plan must bring the robots closer than %.1f m without the yield" % SAFETY)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "fleet_yield_test", FleetYield)
