#!/usr/bin/env python3
"""rostest (realtime pipeline): the reference generator is killed mid-run and started again.
kinematic_controller must command a stop (v = w = 0 and zero derivatives on desired_velocity) once the
reference is older than its input_timeout, keep commanding it, warn on /rosout, and compute again
(non-zero command, tracking_error flowing) once references return.

Protection checked: KinematicController::stopIfStale (src/ros/kinematic_controller.cpp), and the order
of the two input_timeouts (kinematic 0.1 s < torque 0.2 s in fault_overlay.yaml, as in controllers.yaml).
Verified to fail without it: with stopIfStale reduced to `return;` kinematic_controller publishes
nothing while the reference is missing, and the wait for the stop command fails. With its age check
removed (a stop on every odom that has no reference yet) it fails on the stop coming before
input_timeout.

Every verdict is on the messages' stamps (simulated time) or on an event waited for; the wall clock only
bounds a hang (WALL_LIMIT). fault_overlay.yaml runs the plant at a quarter of the wall clock, so that the
controllers keep up with it on a loaded machine (a controller behind the plant sees stale inputs)."""
import time
import unittest

import rosnode
import rospy
import rostest
from rosgraph_msgs.msg import Log
from sowing_robot.msg import DesiredVelocity, ReferenceState, TrackingError

import node_process

WALL_LIMIT = 120.0  # [s wall] bounds a hang only: anything waited for takes a few seconds on an idle machine
STOP_SLACK = 0.1   # [s sim] the last references seen here may have missed their odom in the controller
# [s sim] the stop comes at the first state past input_timeout the controller takes (all of them, in order:
# its queue holds 20,000), one period after it; this allows for references of the killed generator that
# reached the controller but not this test
LATE_SLACK = 0.5


def is_stop(d):
    return d.v == 0.0 and d.omega == 0.0 and d.v_dot == 0.0 and d.omega_dot == 0.0


class SilentReference(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("silent_reference_test")

    def setUp(self):
        self.timeout = rospy.get_param("/kinematic_controller/input_timeout")
        self.desired, self.refs, self.errors, self.logs = [], [], [], []
        self.subs = [
            rospy.Subscriber("desired_velocity", DesiredVelocity, self.desired.append, queue_size=20000),
            rospy.Subscriber("reference", ReferenceState, self.on_reference, queue_size=20000),
            rospy.Subscriber("tracking_error", TrackingError, lambda m: self.errors.append(m.header.stamp.to_sec()),
                             queue_size=20000),
            rospy.Subscriber("/rosout", Log, self.logs.append, queue_size=1000)]
        self.restarted = None

    def tearDown(self):
        if self.restarted is not None:
            node_process.stop(self.restarted)
        for sub in self.subs:
            sub.unregister()

    def wait_for(self, condition, what):
        deadline = time.time() + WALL_LIMIT
        while not condition():
            if time.time() > deadline:
                self.fail("no %s after %.0f s wall" % (what, WALL_LIMIT))
            time.sleep(0.02)

    def on_reference(self, m):
        self.refs.append(m.header.stamp.to_sec())

    @staticmethod
    def generator_gone():
        """The killed generator has left the graph."""
        return "/reference_generator" not in rosnode.get_node_names()

    @staticmethod
    def latest(stamps):
        return stamps[-1] if stamps else -1.0

    def latest_desired(self):
        return self.desired[-1].header.stamp.to_sec() if self.desired else -1.0

    def first_stop_after(self, t):
        return next((d for d in list(self.desired) if d.header.stamp.to_sec() > t and is_stop(d)), None)

    def test_stop_while_the_reference_is_missing(self):
        self.wait_for(lambda: self.latest(self.refs) >= 1.0, "reference up to t = 1 s")
        rosnode.kill_nodes(["/reference_generator"])
        self.wait_for(self.generator_gone, "end of the reference generator")
        self.wait_for(lambda: self.first_stop_after(self.latest(self.refs)) is not None, "stop command")
        self.wait_for(lambda: any(m.name == "/kinematic_controller" and m.level == Log.WARN and
                                  "no reference for" in m.msg and "commanding stop" in m.msg for m in list(self.logs)),
                      "warning from kinematic_controller")

        # Hold the outage for 1 s of simulated time (4 s wall or more), then bring the generator back. The
        # stop is judged once the outage is over, against the killed generator's last reference: by then
        # everything it sent has arrived.
        first_stop = self.first_stop_after(self.latest(self.refs)).header.stamp.to_sec()
        self.wait_for(lambda: self.latest_desired() >= first_stop + 1.0, "1 s of outage")
        last_ref = self.latest(self.refs)
        stop_at = self.first_stop_after(last_ref).header.stamp.to_sec()
        print("silent_reference: last reference t = %.3f s, stop from t = %.3f s (input_timeout %.3f s)" %
              (last_ref, stop_at, self.timeout))
        self.assertGreaterEqual(stop_at - last_ref, self.timeout - STOP_SLACK, "stop before input_timeout")
        self.assertLessEqual(stop_at - last_ref, self.timeout + LATE_SLACK, "stop late")
        self.restarted = node_process.start("reference_generator", "reference_generator")
        self.wait_for(lambda: self.latest(self.refs) > stop_at + 1.0, "reference after the restart")
        back_at = next(t for t in self.refs if t > stop_at + 1.0)
        during = [d for d in list(self.desired) if stop_at <= d.header.stamp.to_sec() < back_at]
        self.assertTrue(during and all(is_stop(d) for d in during), "not a steady stop during the outage")
        # The torque controller's own timeout is longer, and the stop commands keep it fed: the outage is
        # blamed on the reference generator, not on the kinematic controller.
        blamed = [m.msg for m in list(self.logs) if m.name == "/torque_controller" and "no desired_velocity" in m.msg]
        self.assertEqual(blamed, [], "torque_controller took the kinematic controller for dead")

        # Computing again: tracking errors at the new references, and commands that are not a stop.
        self.wait_for(lambda: min(self.latest(self.errors), self.latest_desired()) >= back_at + 0.5,
                      "tracking_error and desired_velocity 0.5 s after the restart")
        # (Mostly, not all: on an overloaded machine a realtime controller may time out now and then.)
        after = [d for d in list(self.desired) if d.header.stamp.to_sec() >= back_at]
        self.assertGreater(sum(not is_stop(d) for d in after), len(after) // 2, "still commanding a stop")


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "silent_reference_test", SilentReference)
