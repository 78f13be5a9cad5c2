#!/usr/bin/env python3
"""rostest: plant_sim (realtime, started here as a child process so its exit code can be checked) is
driven to divergence by sustained wheel torques from this test. It must stop the run: a FATAL line
saying the state diverged, exit code 2, and no diverged state ever published on odom.
As a nodelet the same divergence must stop that run only: one FATAL line, no more states, and the
manager with its other nodelets (here a second plant_sim) running on.

Protection checked: SimulatedPlant::step() (src/ros/plant_sim/simulated_plant.cpp), the |v| > max_speed /
non-finite check after every step, whose failure run() throws as a NodeFailure (kDiverged) that
plant_sim's main turns into exit 2 and PlantSimNodelet into a stopped run. plant_sim does not clip
incoming torques (max_torque is the torque controller's limit), so a finite torque can drive the state
anywhere.
Verified to fail without it: with the check reduced to `return true;` plant_sim runs on at any speed,
the wait for its exit times out and both process cases fail (and odom carries |v| > max_speed); with
the nodelet ending the process on the failure (as plant_sim did with _Exit before), the nodelet case
fails: the manager is gone."""
import math
import re
import subprocess
import tempfile
import time
import unittest

import roslib.packages
import rospy
import rostest
from nav_msgs.msg import Odometry
from nodelet.srv import NodeletList, NodeletLoad
from sowing_robot.msg import WheelTorque

import node_process

EXIT_LIMIT = 30.0  # [s wall] for start-up plus divergence; a healthy machine needs about 1 s

CASES = [
    # (namespace, plant_sim private params, torque on each wheel [N m], text the FATAL line must hold)
    # 20 N m per wheel accelerates the (20 % heavier) robot at about 19 m/s^2: past 2 m/s in ~0.1 s.
    ("/diverge_overspeed", {"max_speed": 2.0}, 20.0, "max_speed 2 m/s"),
    # A finite but absurd torque: the sum of the two overflows to inf and the state turns NaN within a
    # step (0 * inf in the Coriolis term); the run must stop on the NaN state (default max_speed).
    ("/diverge_overflow", {}, 1e308, "nan"),
]
RUN = {
    "mode": "realtime",
    "control_rate": 200.0,  # light on a busy 2-core machine; the check runs after every step at any rate
}
COMMON = {
    "torque_timeout": 1.0,  # [s sim] generous: our torques are stamped with the last odom we received
    "disturbance/sinusoidal": False,  # the only cause of motion is the test's torque
}


class PlantDivergence(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("plant_divergence_test")

    def run_case(self, ns, params, torque, needle):
        node_process.set_private_params(ns + "/run", RUN)  # the run-wide settings of this namespace
        node_process.set_private_params(ns + "/plant_sim", dict(COMMON, **params))
        max_speed = params.get("max_speed", 20.0)
        seen = {"stamp": None, "count": 0, "max_v": 0.0}

        def on_odom(m):
            seen["stamp"] = m.header.stamp
            seen["count"] += 1
            v = m.twist.twist.linear.x
            seen["max_v"] = max(seen["max_v"], abs(v) if math.isfinite(v) else math.inf)

        sub = rospy.Subscriber(ns + "/ground_truth", Odometry, on_odom, queue_size=1000)
        pub = rospy.Publisher(ns + "/wheel_torque", WheelTorque, queue_size=10)
        with tempfile.TemporaryFile(mode="w+") as log:
            proc = node_process.start("plant_sim", "plant_sim", ns=ns, output=log)
            try:
                deadline = time.time() + EXIT_LIMIT
                while proc.poll() is None and time.time() < deadline:
                    if seen["stamp"] is not None:  # stamped like a controller's answer, so it is fresh
                        msg = WheelTorque()
                        msg.header.stamp = seen["stamp"]
                        msg.right = msg.left = torque
                        pub.publish(msg)
                    time.sleep(0.01)
            finally:
                code = node_process.stop(proc)  # no-op when it has exited by itself
                sub.unregister()
                pub.unregister()
            log.seek(0)
            out = log.read()
        where = "%s (torque %g N m)" % (ns, torque)
        self.assertGreater(seen["count"], 0, "%s: plant_sim never published ground_truth\n%s" % (where, out))
        self.assertEqual(code, 2, "%s: exit %s, expected 2 (stopped after %.0f s if it did not exit)\n%s"
                         % (where, code, EXIT_LIMIT, out))
        fatal = [line for line in out.splitlines() if "[FATAL]" in line]
        self.assertEqual(len(fatal), 1, "%s: expected one FATAL line\n%s" % (where, out))
        self.assertIn("state diverged", fatal[0], where)
        self.assertIn(needle, fatal[0], where)
        self.assertLessEqual(seen["max_v"], max_speed, "%s: a diverged state was published" % where)

    def test_overspeed_stops_the_run(self):
        self.run_case(*CASES[0])

    def test_divergence_in_a_nodelet_manager_stops_only_that_run(self):
        manager_ns, diverging, healthy = "/diverge_manager", "/diverge_nodelet", "/healthy_nodelet"
        for ns in (diverging, healthy):
            node_process.set_private_params(ns + "/run", RUN)
        node_process.set_private_params(diverging + "/plant_sim", dict(COMMON, max_speed=2.0))
        node_process.set_private_params(healthy + "/plant_sim", COMMON)  # no torque: it runs at rest
        seen = {diverging: [], healthy: []}  # (stamp [s sim], |v|) received, per plant
        subs = [rospy.Subscriber(ns + "/ground_truth", Odometry,
                                 lambda m, ns=ns: seen[ns].append((m.header.stamp.to_sec(), abs(m.twist.twist.linear.x))),
                                 queue_size=1000) for ns in seen]
        pub = rospy.Publisher(diverging + "/wheel_torque", WheelTorque, queue_size=10)
        stamp = {"last": None}
        subs.append(rospy.Subscriber(diverging + "/ground_truth", Odometry, lambda m: stamp.update(last=m.header.stamp),
                                     queue_size=10))
        nodelet = roslib.packages.find_node("nodelet", "nodelet")[0]
        with tempfile.TemporaryFile(mode="w+") as log:
            manager = subprocess.Popen([nodelet, "manager", "__name:=manager", "__ns:=" + manager_ns], stdout=log,
                                       stderr=subprocess.STDOUT)
            try:
                rospy.wait_for_service(manager_ns + "/manager/load_nodelet", timeout=EXIT_LIMIT)
                load = rospy.ServiceProxy(manager_ns + "/manager/load_nodelet", NodeletLoad)
                for ns in (healthy, diverging):
                    self.assertTrue(load(ns + "/plant_sim", "sowing_robot/plant_sim", [], [], [], "").success, ns)

                def fatal_lines():
                    log.flush()
                    log.seek(0)
                    return [line for line in log.read().splitlines() if "[FATAL]" in line]

                deadline = time.time() + EXIT_LIMIT
                while not fatal_lines() and manager.poll() is None and time.time() < deadline:
                    if stamp["last"] is not None:  # stamped like a controller's answer, so it is fresh
                        msg = WheelTorque()
                        msg.header.stamp = stamp["last"]
                        msg.right = msg.left = 20.0
                        pub.publish(msg)
                    time.sleep(0.01)
                self.assertIsNone(manager.poll(), "the manager ended (exit %s)" % manager.returncode)
                fatal = fatal_lines()
                self.assertEqual(len(fatal), 1, "expected one FATAL line within %.0f s" % EXIT_LIMIT)
                self.assertIn(diverging + "/plant_sim: state diverged", fatal[0])
                self.assertIn("max_speed 2 m/s", fatal[0])
                # The diverged run publishes nothing more; the healthy plant in the same manager goes on.
                # Judged by stamp, not by arrival: a state published just before the FATAL line may still be in
                # transit when the line is read. Every state published before the diverging step is stamped
                # before its time; a run that went on would publish later stamps (40 in the 0.2 s below).
                diverged_at = float(re.search(r"state diverged at t=([0-9.]+) s", fatal[0]).group(1))
                healthy_at = len(seen[healthy])
                time.sleep(0.2)
                try:
                    listed = rospy.ServiceProxy(manager_ns + "/manager/list", NodeletList)().nodelets
                except rospy.ServiceException as e:
                    self.fail("the manager does not answer after the divergence (%s; exit %s)" % (e, manager.poll()))
                self.assertIn(healthy + "/plant_sim", listed)
                self.wait_for_more(seen[healthy], healthy_at + 20, "states from the healthy plant")
                self.assertIsNone(manager.poll(), "the manager ended (exit %s)" % manager.returncode)
                late = [t for t, _ in seen[diverging] if t >= diverged_at - 1e-9]
                self.assertEqual(late, [], "states published after the divergence at t=%.6f s" % diverged_at)
                self.assertLessEqual(max(v for _, v in seen[diverging]), 2.0, "a diverged state was published")
            finally:
                node_process.stop(manager)
                for sub in subs:
                    sub.unregister()
                pub.unregister()

    @staticmethod
    def wait_for_more(items, count, what):
        deadline = time.time() + EXIT_LIMIT
        while len(items) < count:
            if time.time() > deadline:
                raise AssertionError("no %s after %.0f s" % (what, EXIT_LIMIT))
            time.sleep(0.01)

    def test_overflowing_state_stops_the_run(self):
        self.run_case(*CASES[1])


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "plant_divergence_test", PlantDivergence)
