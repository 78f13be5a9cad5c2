"""Shared by the rostests that run a sowing_robot node as a child process of the test: to check its exit
code and output (a node that must refuse to start, or stop a run), or to restart a node the test killed.
Imported from the test scripts beside it (a module, not a test: not executable)."""
import os
import signal
import subprocess
import time

import roslib.packages
import rospy


def executable(node):
    """Path of a sowing_robot node binary. roslib finds it through catkin; rosrun's `find -L` would crawl
    the workspace's symlink back to the package."""
    return roslib.packages.find_node("sowing_robot", node)[0]


def set_private_params(node_path, params):
    """Put {key: value} under node_path (e.g. "/bad_3") on the parameter server, where the node started
    with that name reads its private parameters."""
    for key, value in params.items():
        rospy.set_param("%s/%s" % (node_path, key), value)


# The launch files' remap of the controllers' `feedback` (sim.launch feedback:=ground_truth, the default):
# a controller the test starts itself closes the loop on the same topic.
FEEDBACK_REMAP = "feedback:=ground_truth"


def command(node, name, ns=None):
    """Command line of `node` started as `name`, in namespace `ns` when given (a controller with its
    feedback remapped as the launch files do)."""
    cmd = [executable(node), "__name:=%s" % name]
    if node in ("kinematic_controller", "torque_controller"):
        cmd.append(FEEDBACK_REMAP)
    if ns:
        cmd.append("__ns:=%s" % ns)
    return cmd


def run(node, name, ns=None, timeout=60):
    """Run a node to its end: subprocess.CompletedProcess with stdout and stderr merged in .stdout."""
    return subprocess.run(command(node, name, ns), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=timeout, universal_newlines=True)


def start(node, name, ns=None, output=None):
    """Start a node in the background. Its stdout and stderr go to the file object `output` when given
    (a file, not a pipe: a pipe nobody reads until the end could fill and block the node), else to ours."""
    return subprocess.Popen(command(node, name, ns), stdout=output, stderr=subprocess.STDOUT if output else None)


def stop(proc, timeout=15):
    """Stop a node started by start(): SIGINT (roscpp's clean shutdown, unregistering from the master),
    SIGKILL if it has not ended after `timeout` s. Returns its exit code."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    return proc.returncode


def run_on_master(port, cmd, timeout=240):
    """(exit code, output, wall seconds) of `cmd` (a launch) on a master of its own at `port`; a launch that
    has not ended after `timeout` s is killed whole and "(killed after N s)" appended to its output."""
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    begin = time.time()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                            start_new_session=True)  # a hung launch is killed whole
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        out += "\n(killed after %d s)" % timeout
    return proc.returncode, out, time.time() - begin


def sim(port, args, timeout=240):
    """run_on_master of `rosrun sowing_robot sim headless:=true ARGS` (what scripts/run calls)."""
    return run_on_master(port, [executable("sim"), "headless:=true"] + list(args), timeout)
