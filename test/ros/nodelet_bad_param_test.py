#!/usr/bin/env python3
"""rostest: a sowing_robot nodelet that refuses to start must stay inside its unit. The test starts a
nodelet manager (a child process, so that its output and life can be checked), loads a good
kinematic_controller into it, then a torque_controller with mode 'foo'. The bad load must fail (`nodelet
load` exits non-zero), the manager must log exactly one FATAL line for it ("/bad_torque: refusing to start:
... mode ..."), the manager must list only the good nodelet, and the good nodelet must still answer
(a reference and an odom stamped t give a desired_velocity stamped t).

Protection checked: WrapperNodelet::onInit (src/nodelets/nodelets.cpp) with refuseToStart throwing.
Verified to fail without it: with refuseToStart ending the process (ROS_FATAL + exitProcess(1), as before)
the manager dies with the bad nodelet and the liveness checks fail."""
import subprocess
import tempfile
import time
import unittest

import roslib.packages
import rospy
import rostest
from nav_msgs.msg import Odometry
from nodelet.srv import NodeletList
from sowing_robot.msg import DesiredVelocity, ReferenceState

import node_process

MANAGER = "/test_manager"
WAIT = 60.0  # [s wall] bound for each step; a healthy machine needs well under a second


def nodelet_cmd(*args):
    return [roslib.packages.find_node("nodelet", "nodelet")[0]] + list(args)


def wait_for(predicate, timeout=WAIT):
    deadline = time.time() + timeout
    while time.time() < deadline and not rospy.is_shutdown():
        if predicate():
            return True
        time.sleep(0.05)
    return predicate()


class NodeletBadParam(unittest.TestCase):
    def test_bad_nodelet_is_not_loaded_and_the_manager_runs_on(self):
        rospy.init_node("nodelet_bad_param_test")
        node_process.set_private_params("/bad_torque", {"mode": "foo"})
        with tempfile.TemporaryFile(mode="w+") as log:
            manager = subprocess.Popen(nodelet_cmd("manager", "__name:=test_manager"), stdout=log,
                                       stderr=subprocess.STDOUT)
            good = subprocess.Popen(nodelet_cmd("load", "sowing_robot/kinematic_controller", MANAGER,
                                                "__name:=good_kinematic", "--no-bond"))
            try:
                rospy.wait_for_service(MANAGER + "/list", WAIT)
                listed = rospy.ServiceProxy(MANAGER + "/list", NodeletList)
                self.assertTrue(wait_for(lambda: "/good_kinematic" in listed().nodelets), "the good nodelet never loaded")

                bad = subprocess.run(nodelet_cmd("load", "sowing_robot/torque_controller", MANAGER,
                                                 "__name:=bad_torque", "--no-bond"),
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                     timeout=WAIT)
                self.assertNotEqual(bad.returncode, 0, "nodelet load of the bad nodelet succeeded:\n" + bad.stdout)

                self.assertIsNone(manager.poll(), "the manager died with the bad nodelet")
                self.assertEqual(listed().nodelets, ["/good_kinematic"])
                self.assert_answers()
                self.assertIsNone(manager.poll(), "the manager died")
                self.assertIsNone(good.poll(), "the good nodelet's loader ended")
            finally:
                node_process.stop(good)
                node_process.stop(manager)
            log.seek(0)
            out = log.read()
        fatal = [line for line in out.splitlines() if "[FATAL]" in line]
        self.assertEqual(len(fatal), 1, "expected one FATAL line from the manager:\n" + out)
        self.assertIn("/bad_torque: refusing to start: /bad_torque/mode = 'foo'", fatal[0])

    def assert_answers(self):
        """The good kinematic_controller answers a state with a desired velocity of the same stamp."""
        got = []
        sub = rospy.Subscriber("/desired_velocity", DesiredVelocity, lambda m: got.append(m.header.stamp))
        ref_pub = rospy.Publisher("/reference", ReferenceState, queue_size=10)
        odom_pub = rospy.Publisher("/feedback", Odometry, queue_size=10)  # the controller's, not remapped here
        stamp = rospy.Time(1, 0)
        ref = ReferenceState()
        ref.header.stamp = stamp
        ref.y, ref.v = 3.0, 1.0
        odom = Odometry()
        odom.header.stamp = stamp
        odom.pose.pose.orientation.w = 1.0

        def answered():
            ref_pub.publish(ref)  # repeated until the links are up; a repeat is answered from the cache
            odom_pub.publish(odom)
            return stamp in got

        try:
            self.assertTrue(wait_for(answered), "the good nodelet no longer answers")
        finally:
            sub.unregister()


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "nodelet_bad_param_test", NodeletBadParam)
