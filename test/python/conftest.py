"""Shared helpers of the Python tests (pytest, no ROS master): bit-exact comparison and synthetic bags."""
import os
import random

import pytest


def bits(metrics):
    """{axis: {field: float.hex}}: equal exactly when every value is equal to the last bit (NaN == NaN)."""
    return {axis: {k: float(v).hex() for k, v in fields.items()} for axis, fields in metrics.items()}


def sec_of_ns(ns):
    """ros::Time(ns).toSec(), as secondsFromNanos in core/common/types.h."""
    return float(ns // 10**9) + 1e-9 * float(ns % 10**9)


def write_error_bag(path, stamps_ns, ex, ey, eth, shuffle_seed=None):
    """/tracking_error messages with these stamps and errors; shuffle_seed: received in a shuffled order."""
    import rosbag
    import rospy
    from sowing_robot.msg import TrackingError
    order = list(range(len(stamps_ns)))
    if shuffle_seed is not None:
        random.Random(shuffle_seed).shuffle(order)
    with rosbag.Bag(path, "w") as bag:
        for i, k in enumerate(order):
            m = TrackingError()
            m.header.stamp = rospy.Time(*divmod(int(stamps_ns[k]), 10**9))
            m.x, m.y, m.theta = float(ex[k]), float(ey[k]), float(eth[k])
            bag.write("/tracking_error", m, rospy.Time(1, 1000 * (i + 1)))


@pytest.fixture
def tmpdir_path(tmp_path):
    return str(tmp_path)


def node(name):
    """Path of one of the package's executables (devel space), as rosrun finds it."""
    import roslib.packages
    found = roslib.packages.find_node("sowing_robot", name)
    assert found, "%s not built (catkin_make)" % name
    return found[0]


assert os  # used by the tests through this module
