#!/usr/bin/env python3
"""rostest (lockstep pipeline, lockstep_timeout 1.5 s wall): a torque controller that dies mid-run, or
that never starts, must not leave plant_sim hanging silently. plant_sim does not exit: it waits, and
every lockstep_timeout wall seconds it says what it is waiting for.

- Killed mid-run: plant_sim stays at the stalled step, re-publishes that state every lockstep_retry, and
  logs an ERROR naming the step's time and the torque topic with its publisher count (0); it resumes
  when a torque controller is started again.
- Kinematic controller killed mid-run and restarted: the reference generator, which sends references
  ahead of the state, replays the ones still ahead to the new subscriber, so the new controller answers
  the stalled state with a real command, not the stop it gives when it has no reference.
- All three loop nodes killed, then restarted one by one, each before the source of its input: in
  lockstep a controller answers a state only with the input paired with its stamp (run/mode; its
  input_timeout is for realtime), so the loop stays at the stalled state until the reference generator
  is back, and then goes on. No zero torque, no stop: the restart race cannot produce a wrong answer.
- Never started (a second plant_sim alone in /lonely): it does not take step 0 and logs a WARN with the
  number of wheel_torque publishers (0); after lockstep_give_up wall seconds it exits 3 with a FATAL line
  naming the missing input (a third plant_sim in /given_up, with a 3 s limit).

Protections checked (PlantSim::runLockstep, src/ros/plant_sim/plant_sim.cpp): the "lockstep stalled" ROS_ERROR in
the wait for a torque, the re-publication of the stalled state, and the "lockstep waiting for the loop"
ROS_WARN before step 0, and the give-up (exit 3); the protocol itself is core::LockstepProtocol.
And ReferenceGenerator::replayTo (src/ros/reference_generator.cpp), and the controllers' lockstep wait
(KinematicController::stopIfStale, TorqueController::holdZeroIfStale: no timeout when run/mode is lockstep).
Verified to fail without them: with the ROS_ERROR removed test_killed_controller... fails waiting for
the report; with the re-publication removed it fails on the repeat count (and the restarted controller
never gets a state to answer, so the run does not resume); with the ROS_WARN removed
test_missing_controller... fails waiting for the report; with replayTo emptied test_restarted_kinematic...
fails waiting for progress (the new controller waits for a reference that never comes); with the
controllers' timeouts active in lockstep test_restarted_controllers... fails: the restarted torque
controller answers the stalled state with zero torque and the loop moves on without its input.

Nothing here depends on who connects first: what the test reads from a restarted node is its own output
(a file, not /rosout, whose link a new node makes only after its first lines), or the ~state of a torque
controller whose messages the test has already been receiving."""
import re
import tempfile
import time
import unittest
import xmlrpc.client

import rosgraph
import rosnode
import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sowing_robot.msg import TorqueControllerState

import node_process

LOCKSTEP_TIMEOUT = 1.5  # [s wall] plant_sim/lockstep_timeout in lockstep_dead_controller.test
WALL_LIMIT = 60.0       # [s wall] for anything that should take a few seconds on an idle machine


class LockstepDeadController(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("lockstep_dead_controller_test")

    def setUp(self):
        self.logs = []  # (wall time received, Log)
        self.odom_stamps = []
        self.odom_v = {}  # stamp -> v of every odom received
        self.torque_states = []
        self.subs = [rospy.Subscriber("/rosout", Log, lambda m: self.logs.append((time.time(), m)), queue_size=1000),
                     rospy.Subscriber("ground_truth", Odometry, self.on_odom, queue_size=20000),
                     rospy.Subscriber("torque_controller/state", TorqueControllerState, self.torque_states.append,
                                      queue_size=20000)]
        self.children = []
        self.outputs = []  # files holding the output of the nodes this test started

    def tearDown(self):
        for proc in self.children:
            node_process.stop(proc)
        for sub in self.subs:
            sub.unregister()
        for out in self.outputs:
            out.close()

    def on_odom(self, m):
        t = m.header.stamp.to_sec()
        self.odom_stamps.append(t)
        self.odom_v[t] = m.twist.twist.linear.x

    def start(self, name):
        """Start the pipeline node `name` (killed earlier) as a child; returns the file its output goes to."""
        out = tempfile.TemporaryFile(mode="w+")
        self.outputs.append(out)
        self.children.append(node_process.start(name, name, output=out))
        return out

    def ensure(self, *names):
        """Start each of the pipeline's nodes `names` that is not running (an earlier test may have stopped it)."""
        running = rosnode.get_node_names()
        for name in names:
            if "/" + name not in running:
                self.start(name)

    def kill(self, *names):
        """Kill pipeline nodes and wait until the master has forgotten them (a later ensure() must see them gone)."""
        rosnode.kill_nodes(["/" + n for n in names])
        self.wait_for(lambda: not set("/" + n for n in names) & set(rosnode.get_node_names()),
                      "%s unregistered" % ", ".join(names))

    @staticmethod
    def output(out):
        out.flush()
        out.seek(0)
        return out.read()

    @staticmethod
    def subscribed(node, topic):
        """`node` holds a live connection from a publisher of `topic` (its bus info, as `rosnode info` shows)."""
        try:
            uri = rosgraph.Master(rospy.get_name()).lookupNode(node)
            code, _, bus = xmlrpc.client.ServerProxy(uri).getBusInfo(rospy.get_name())
        except (rosgraph.MasterError, OSError, xmlrpc.client.Error):  # not up (or not registered) yet
            return False
        return code == 1 and any(row[2] == "i" and row[4] == topic and row[5] for row in bus)

    def wait_for(self, condition, what, limit=WALL_LIMIT):
        deadline = time.time() + limit
        while not condition():
            if time.time() > deadline:
                self.fail("no %s after %.0f s wall" % (what, limit))
            time.sleep(0.05)

    def reports(self, node, level, text):
        """(wall time, message) of every log line of `node` at `level` holding `text`, in arrival order."""
        return [(t, m.msg) for t, m in list(self.logs) if m.name == node and m.level == level and text in m.msg]

    def last_odom(self):
        return self.odom_stamps[-1] if self.odom_stamps else -1.0

    def test_killed_controller_is_reported_and_replaced(self):
        self.wait_for(lambda: self.last_odom() >= 0.5, "odom up to t = 0.5 s")
        killed_at = time.time()
        rosnode.kill_nodes(["/torque_controller"])

        stall = lambda: self.reports("/plant_sim", Log.ERROR, "lockstep stalled")
        self.wait_for(lambda: len(stall()) >= 2, "two stall reports from plant_sim",
                      limit=2 * LOCKSTEP_TIMEOUT + WALL_LIMIT)
        (first_at, first), (_, second) = stall()[:2]
        stalled = self.last_odom()
        # Not before lockstep_timeout: the stall cannot have begun before the kill.
        self.assertGreaterEqual(first_at - killed_at, 0.9 * LOCKSTEP_TIMEOUT, first)
        # It names the step it is stuck at (the last state published) and the missing input.
        t = float(re.search(r"stalled at t=([0-9.]+) s", first).group(1))
        self.assertAlmostEqual(t, stalled, places=5, msg="%s (last odom at t=%.6f)" % (first, stalled))
        self.assertIn("0 publisher(s) on /wheel_torque: is torque_controller running?", first)
        step = lambda m: re.search(r"stalled at t=([0-9.]+) s", m).group(1)
        waited = lambda m: float(re.search(r"after ([0-9.]+) s wall", m).group(1))
        self.assertEqual(step(first), step(second), "a second report should be about the same step")
        self.assertGreater(waited(second), waited(first), "the report should say how long it has waited")
        # Meanwhile the stalled state is re-published (lockstep_retry 0.5 s) for a late or new controller.
        self.assertGreaterEqual(self.odom_stamps.count(stalled), 2, "stalled state not re-published")

        self.children.append(node_process.start("torque_controller", "torque_controller"))
        self.wait_for(lambda: self.last_odom() >= stalled + 0.5, "progress after the torque controller restarted")

    def test_restarted_kinematic_controller_gets_the_references_already_sent(self):
        self.ensure("reference_generator", "kinematic_controller", "torque_controller")
        # The loop must be running with the torque controller whose ~state this test receives: that is
        # where the command for the stalled state is read (the new kinematic controller's own topic could
        # carry it before this test's link to it exists).
        self.wait_for(lambda: self.odom_stamps, "a state")
        start = self.last_odom()
        self.wait_for(lambda: self.torque_states and self.torque_states[-1].header.stamp.to_sec() >= start + 0.5,
                      "the loop running, and torque_controller/state received")
        self.kill("kinematic_controller")
        self.wait_for(lambda: self.odom_stamps.count(self.last_odom()) >= 2, "the stalled state re-published")
        stalled = self.last_odom()
        out = self.start("kinematic_controller")
        self.wait_for(lambda: self.last_odom() >= stalled + 0.5, "progress after the kinematic controller restarted")
        # The torque controller computed the stalled state from the new controller's command: a real one
        # (v_r = 1 m/s), not the stop (v = omega = 0) it commands without a reference.
        state = [m for m in list(self.torque_states) if abs(m.header.stamp.to_sec() - stalled) < 1e-9]
        self.assertEqual(len(state), 1, "torque_controller/state for the stalled state t=%.6f" % stalled)
        v_desired = state[0].e_v + self.odom_v[stalled]  # e_v = v_d - v
        self.assertGreater(v_desired, 0.5, "command for the stalled state t=%.6f: v_d %.4f" % (stalled, v_desired))
        self.assertNotIn("no reference", self.output(out))

    def test_restarted_controllers_wait_for_their_inputs(self):
        # Each controller is restarted before the source of its input, so it certainly gets the re-sent
        # state first: the race a restart may run into, made certain. In lockstep it must wait.
        self.ensure("reference_generator", "kinematic_controller", "torque_controller")
        self.wait_for(lambda: self.odom_stamps, "a state")
        start = self.last_odom()
        self.wait_for(lambda: self.last_odom() >= start + 0.5, "the loop running")
        self.kill("reference_generator", "kinematic_controller", "torque_controller")
        self.wait_for(lambda: self.odom_stamps.count(self.last_odom()) >= 2, "the stalled state re-published")
        stalled = self.last_odom()
        outs = {}
        for name in ("torque_controller", "kinematic_controller"):  # each without its input
            outs[name] = self.start(name)
            self.wait_for(lambda: self.subscribed("/" + name, "/ground_truth"), "%s subscribed to /ground_truth" % name)
            resent = self.odom_stamps.count(stalled)
            self.wait_for(lambda: self.odom_stamps.count(stalled) >= resent + 2 or self.last_odom() != stalled,
                          "the stalled state re-sent to the new %s" % name)
            self.assertEqual(self.last_odom(), stalled, "the loop moved on without an input of %s" % name)
        self.start("reference_generator")
        self.wait_for(lambda: self.last_odom() >= stalled + 0.5, "progress once the reference generator is back")
        for name, needle in (("torque_controller", "no desired_velocity"), ("kinematic_controller", "no reference")):
            self.assertNotIn(needle, self.output(outs[name]), name)

    def test_missing_controller_is_reported_before_the_start(self):
        ns = "/lonely"  # its own topics: the pipeline's torque_controller must not count as its publisher
        node_process.set_private_params(ns + "/run", {"mode": "lockstep"})
        node_process.set_private_params(ns + "/plant_sim", {"min_subscribers": 0,
                                                            "lockstep_timeout": LOCKSTEP_TIMEOUT})
        lonely_odom = []
        self.subs.append(rospy.Subscriber(ns + "/ground_truth", Odometry, lonely_odom.append, queue_size=10))
        with tempfile.TemporaryFile(mode="w+") as log:
            started_at = time.time()
            proc = node_process.start("plant_sim", "plant_sim", ns=ns, output=log)
            self.children.append(proc)
            waiting = lambda: self.reports(ns + "/plant_sim", Log.WARN, "lockstep waiting for the loop")
            self.wait_for(lambda: len(waiting()) >= 2 or proc.poll() is not None, "waiting reports from plant_sim")
            log.seek(0)
            out = log.read()
        self.assertIsNone(proc.poll(), "plant_sim exited (%s) instead of waiting\n%s" % (proc.returncode, out))
        first_at, first = waiting()[0]
        self.assertGreaterEqual(first_at - started_at, LOCKSTEP_TIMEOUT, first)
        self.assertIn("0 wheel_torque publishers", first)
        self.assertEqual(lonely_odom, [], "plant_sim published a state with no controller to answer it")

    def test_missing_controller_ends_the_run_after_lockstep_give_up(self):
        # A headless run whose controller never answers must end: exit 3 and one FATAL line naming what
        # is missing, once lockstep_give_up wall seconds have passed (here 3 s; the default is 120 s).
        ns = "/given_up"
        node_process.set_private_params(ns + "/run", {"mode": "lockstep"})
        node_process.set_private_params(ns + "/plant_sim", {"min_subscribers": 0,
                                                            "lockstep_timeout": LOCKSTEP_TIMEOUT,
                                                            "lockstep_give_up": 3.0})
        started_at = time.time()
        done = node_process.run("plant_sim", "plant_sim", ns=ns, timeout=60)
        self.assertEqual(done.returncode, 3, done.stdout)
        self.assertGreaterEqual(time.time() - started_at, 3.0)
        self.assertRegex(done.stdout, r"lockstep gave up .*wheel_torque", done.stdout)


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "lockstep_dead_controller_test", LockstepDeadController)
