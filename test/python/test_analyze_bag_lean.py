"""analyze_bag on a lean bag (sim.launch record:=lean, docs/recording.md): the state at 10 Hz, the seed record, no
torques, LZ4-compressed. It reports what it can (metrics from the 10 Hz samples, the seed figures, the path figure)
with one note line per thing the bag lacks; a truncated lean bag is a one-line error. No ROS master."""
import math
import os
import subprocess
import sys

import pytest


def script():
    import rospkg
    return os.path.join(rospkg.RosPack().get_path("sowing_robot"), "scripts", "analyze_bag")


def write_lean_bag(path, seconds=20.0, rate=10.0):
    """What record:=lean leaves: /ground_truth, /reference, /tracking_error at `rate` Hz of stamps, one seed per
    0.5 s (every tenth in a detour, 2 mm from where the robot believed its tool), a /plan-like marker array."""
    import rosbag
    import rospy
    from nav_msgs.msg import Odometry
    from visualization_msgs.msg import Marker, MarkerArray
    from sowing_robot.msg import ReferenceState, Seed, TrackingError
    n = int(seconds * rate) + 1
    with rosbag.Bag(path, "w", compression="lz4") as bag:
        for k in range(n):
            t = k / rate
            st = rospy.Time.from_sec(t)
            bt = st + rospy.Duration(1)  # the bag's time: a stamp of 0 is no valid one there
            e = TrackingError()
            e.header.stamp = st
            e.x, e.y, e.theta = math.exp(-t), 0.5 * math.exp(-t), 0.1 * math.exp(-2.0 * t)
            bag.write("/tracking_error", e, bt)
            o = Odometry()
            o.header.stamp = st
            o.pose.pose.position.x, o.pose.pose.position.y = t - e.x, 3.0 - e.y
            o.pose.pose.orientation.w = 1.0
            bag.write("/ground_truth", o, bt)
            r = ReferenceState()
            r.header.stamp = st
            r.x, r.y, r.v = t, 3.0, 1.0
            bag.write("/reference", r, bt)
            if k % 5 == 0:
                s = Seed()
                s.header.stamp = st
                s.position.x, s.position.y = o.pose.pose.position.x, 3.002
                s.believed.x, s.believed.y = o.pose.pose.position.x, 3.0
                s.depth, s.detour = 0.03, k % 50 == 0
                bag.write("/seeds/record", s, bt)
        markers = MarkerArray()
        mk = Marker(type=Marker.CYLINDER, action=Marker.ADD)
        mk.pose.position.x, mk.pose.position.y = 10.0, 3.0
        mk.scale.x = mk.scale.y = 0.5
        markers.markers.append(mk)
        bag.write("/field_markers", markers, rospy.Time(0, 1))


@pytest.fixture(scope="module")
def lean_bag(tmp_path_factory):
    path = str(tmp_path_factory.mktemp("bags") / "lean.bag")
    write_lean_bag(path)
    return path


def run(*args):
    return subprocess.run([sys.executable, script()] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          universal_newlines=True, timeout=120)


def test_lean_bag_gives_what_it_can(lean_bag, tmp_path):
    plots = str(tmp_path / "plots")
    proc = run(lean_bag, "--plots", plots)
    assert proc.returncode == 0, proc.stderr
    notes = proc.stderr.strip().splitlines()
    assert len(notes) == 2, proc.stderr
    assert notes[0] == ("analyze_bag: note: %s: /wheel_torque, /torque_controller/state, /desired_velocity not "
                        "recorded (lean bag): torque, saturation and adaptive-estimate, desired-velocity figures "
                        "skipped" % lean_bag)
    assert "/tracking_error at 10 Hz (lean bag): the metrics are approximate" in notes[1]
    assert "| ITAE | y |" in proc.stdout
    assert "- samples: 201 /tracking_error\n" in proc.stdout  # no gap reported at 10 Hz
    assert "- seeds: 41 (5 in detours), depth mean 0.03 m; fell from where the robot believed its tool: max 0.002 m, " \
        "RMS 0.002 m" in proc.stdout
    assert "max |torque|" not in proc.stdout
    written = sorted(os.listdir(plots))
    assert written == ["lean_errors.png", "lean_path.png", "lean_tracking.png", "lean_velocity.png"], written


def test_truncated_lean_bag_is_a_one_line_error(lean_bag, tmp_path):
    path = str(tmp_path / "half.bag")
    with open(lean_bag, "rb") as f:
        data = f.read()
    with open(path, "wb") as f:
        f.write(data[:len(data) * 2 // 3])
    proc = run(path, "--no-plots")
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 3 and len(lines) == 1, proc.stderr
    assert lines[0].startswith("analyze_bag: error: ") and "truncated bag" in lines[0]


def test_full_rate_bag_has_no_lean_note(tmp_path):
    """A 1 kHz /tracking_error without torques (a synthetic bag) is not taken for a lean one."""
    from conftest import write_error_bag
    path = str(tmp_path / "errors.bag")
    n = 2000
    write_error_bag(path, [k * 1000000 for k in range(n)], [math.exp(-k * 1e-3) for k in range(n)], [0.0] * n,
                    [0.0] * n)
    proc = run(path, "--no-plots")
    assert proc.returncode == 0 and "lean" not in proc.stderr, proc.stderr
