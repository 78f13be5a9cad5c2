"""Shared by the rostests that feed state_estimator themselves (state_estimator.test,
state_estimator_lockstep.test): the messages of a straight drive along x, and the topics wired up.
Imported from the test scripts beside it (a module, not a test: not executable)."""
import time

import rospy
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu


def odom(stamp, x, v):
    o = Odometry()
    o.header.stamp = stamp
    o.header.frame_id = "odom"
    o.child_frame_id = "base_link"
    o.pose.pose.position.x = x
    o.pose.pose.orientation.w = 1.0
    o.twist.twist.linear.x = v
    return o


def imu(stamp, rate=0.0):
    i = Imu()
    i.header.stamp = stamp
    i.angular_velocity.z = rate
    i.angular_velocity_covariance[8] = 0.005 ** 2
    i.orientation_covariance[0] = -1.0  # no orientation, no acceleration: a yaw-rate sensor
    i.linear_acceleration_covariance[0] = -1.0
    return i


def fix(stamp, x, y, sigma=0.02):
    f = PoseWithCovarianceStamped()
    f.header.stamp = stamp
    f.header.frame_id = "odom"
    f.pose.pose.position.x = x
    f.pose.pose.position.y = y
    f.pose.covariance[0] = f.pose.covariance[7] = sigma ** 2
    for j in (14, 21, 28, 35):
        f.pose.covariance[j] = 1e6
    return f


def wait_for(condition, what, wall_limit):
    """Poll `condition` until it holds; AssertionError ("no WHAT after N s wall") after `wall_limit` s. `what`
    may be a callable, for a message that says how far it got."""
    deadline = time.time() + wall_limit
    while not condition():
        if time.time() > deadline:
            raise AssertionError("no %s after %.0f s wall" % (what() if callable(what) else what, wall_limit))
        time.sleep(0.01)


class Wiring:
    """Publishers of odom, imu and fix, a subscriber collecting odometry/filtered in `out`, connected."""

    def __init__(self, wall_limit):
        self.out = []
        self.sub = rospy.Subscriber("odometry/filtered", Odometry, self.out.append, queue_size=10000)
        self.odom = rospy.Publisher("odom", Odometry, queue_size=10000)
        self.imu = rospy.Publisher("imu", Imu, queue_size=10000)
        self.fix = rospy.Publisher("fix", PoseWithCovarianceStamped, queue_size=10)
        wait_for(lambda: all(p.get_num_connections() > 0 for p in (self.odom, self.imu, self.fix, self.sub)),
                 "connections to state_estimator", wall_limit)
