"""analyze_bag --csv (one tidy CSV per topic and bag, read back exactly by pandas), the C++ bag reader's columns
(de-duplicated by stamp, first kept; sorted) and CSV writer, and the figures' thinning. No ROS master."""
import math
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from sowing_robot import _bag
from sowing_robot.analyze_bag.plots import envelope, thin


def script():
    import rospkg
    return os.path.join(rospkg.RosPack().get_path("sowing_robot"), "scripts", "analyze_bag")


def write_full_bag(path, n=400):
    """Every recorded topic for n ms, received out of stamp order, with repeated stamps, and one marker array."""
    import rosbag
    import rospy
    from nav_msgs.msg import Odometry
    from visualization_msgs.msg import Marker, MarkerArray
    from sowing_robot.msg import (DesiredVelocity, ReferenceState, TorqueControllerState, TrackingError,
                                  WheelTorque)
    order = list(range(n))
    order[10:60] = reversed(order[10:60])
    with rosbag.Bag(path, "w") as bag:
        for i, k in enumerate(order + [5, 7]):  # the last two: repeats of stamps 5 and 7 ms, bogus values
            st = rospy.Time(0, k * 1000000)
            rt = rospy.Time(1, i + 1)
            bogus = i >= n
            t = k * 1e-3
            e = TrackingError()
            e.header.stamp = st
            e.x, e.y, e.theta = (99.0, 99.0, 99.0) if bogus else (math.exp(-t), -0.1 * t, math.sin(t) / 3.0)
            bag.write("/tracking_error", e, rt)
            o = Odometry()
            o.header.stamp = st
            o.pose.pose.position.x, o.pose.pose.position.y = t / 7.0, 3.0
            o.pose.pose.orientation.z, o.pose.pose.orientation.w = math.sin(0.1 * t), math.cos(0.1 * t)
            o.twist.twist.linear.x = 1.0 / 3.0 + t
            bag.write("/odom", o, rt)
            r = ReferenceState()
            r.header.stamp = st
            r.x, r.y, r.v, r.tool_down = t, 3.0, 1.0, k % 3 == 0
            bag.write("/reference", r, rt)
            d = DesiredVelocity()
            d.header.stamp = st
            d.v, d.omega = 1.0 + t, -t
            bag.write("/desired_velocity", d, rt)
            w = WheelTorque()
            w.header.stamp = st
            w.right, w.left = 0.1 * k, -0.2 * k
            bag.write("/wheel_torque", w, rt)
            s = TorqueControllerState()
            s.header.stamp = st
            s.mode = "a,\"b\"" if k == 3 else "atsmc"  # a string that needs quoting
            s.m0_hat, s.saturated = 18.5 + t, k < 4
            bag.write("/torque_controller/state", s, rt)
        markers = MarkerArray()
        for x in (20.0, 50.0):
            mk = Marker(type=Marker.CYLINDER, action=Marker.ADD)
            mk.pose.position.x, mk.pose.position.y = x, 3.0
            mk.scale.x = mk.scale.y = 0.6
            markers.markers.append(mk)
        bag.write("/field_markers", markers, rospy.Time(1, 1))


@pytest.fixture(scope="module")
def full_bag(tmp_path_factory):
    path = str(tmp_path_factory.mktemp("bags") / "full.bag")
    write_full_bag(path)
    return path


def test_reader_columns(full_bag):
    r = _bag.Reader(full_bag)
    types = dict(r.topics())
    assert types["/odom"] == "nav_msgs/Odometry" and types["/field_markers"] == "visualization_msgs/MarkerArray"
    cols = r.read(types)
    r.close()
    e = cols["/tracking_error"]
    assert e["received"] == 402 and len(e["t"]) == 400
    assert list(e["stamp_ns"]) == [k * 1000000 for k in range(400)]
    assert [t.hex() for t in e["t"]] == [(1e-9 * float(k * 1000000)).hex() for k in range(400)]
    assert e["x"][5] == math.exp(-0.005) and e["x"][7] == math.exp(-0.007)  # the first received kept
    assert e["x"].dtype == np.float64 and cols["/reference"]["tool_down"].dtype == np.bool_
    assert cols["/torque_controller/state"]["mode"][3] == "a,\"b\""
    assert [m["x"] for m in cols["/field_markers"]["markers"]] == [20.0, 50.0]
    with pytest.raises(ValueError):
        _bag.Reader(full_bag).read({"/odom": "std_msgs/String"})


def test_csv_round_trips(full_bag, tmp_path):
    out = str(tmp_path / "csv")
    proc = subprocess.run([sys.executable, script(), full_bag, "--no-plots", "--csv", out], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    names = sorted(os.listdir(out))
    assert names == ["full_desired_velocity.csv", "full_obstacles.csv", "full_odom.csv", "full_reference.csv",
                     "full_torque_controller_state.csv", "full_tracking_error.csv", "full_wheel_torque.csv"]
    r = _bag.Reader(full_bag)
    cols = r.read(dict(r.topics()))
    for topic, series in cols.items():
        if topic == "/field_markers":
            continue
        f = pd.read_csv(os.path.join(out, "full_%s.csv" % topic.strip("/").replace("/", "_")),
                        float_precision="round_trip", keep_default_na=False)
        assert list(f.columns[:2]) == ["time", "stamp_ns"]
        assert np.array_equal(f["time"].to_numpy(), series["t"])
        for k, v in series.items():
            if k in ("received", "t"):
                continue
            got = f[k].to_numpy()
            if isinstance(v, list):
                assert list(got) == v
            else:
                assert got.dtype == v.dtype and np.array_equal(got, v), (topic, k)
    obstacles = pd.read_csv(os.path.join(out, "full_obstacles.csv"))
    assert obstacles.to_dict("list") == {"kind": ["circle", "circle"], "x": [20.0, 50.0], "y": [3.0, 3.0],
                                         "scale_x": [0.6, 0.6], "scale_y": [0.6, 0.6]}


def test_csv_cannot_write(full_bag, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    proc = subprocess.run([sys.executable, script(), full_bag, "--no-plots", "--csv", str(blocker / "sub")],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
    assert proc.returncode == 2 and "cannot write --csv" in proc.stderr and "Traceback" not in proc.stderr


def test_write_csv_values(tmp_path):
    path = str(tmp_path / "v.csv")
    vals = np.array([0.1, 1.0 / 3.0, -2.0, 1e-300, 5e-324, 1.7e9 + 0.123, np.nan, np.inf, -np.inf, 0.0])
    _bag.write_csv(path, ["f", "i", "b", "s"], [vals, np.arange(10, dtype=np.int64) - 3, np.arange(10) % 2 == 0,
                                               ["x", "a,b", "q\"q", "", "e", "f", "g", "h", "i", "j"]])
    f = pd.read_csv(path, float_precision="round_trip", keep_default_na=False, na_values={"f": ["nan"]})
    assert [v.hex() for v in f["f"]] == [v.hex() for v in vals]
    assert list(f["i"]) == list(range(-3, 7)) and list(f["b"]) == [k % 2 == 0 for k in range(10)]
    assert list(f["s"]) == ["x", "a,b", "q\"q", "", "e", "f", "g", "h", "i", "j"]
    with open(path) as fh:
        assert fh.readline() == "f,i,b,s\n" and fh.readline() == "0.1,-3,True,x\n"
    with pytest.raises(ValueError):
        _bag.write_csv(path, ["a", "b"], [np.zeros(2), np.zeros(3)])
    with pytest.raises(OSError):
        _bag.write_csv(str(tmp_path / "no" / "dir.csv"), ["a"], [np.zeros(2)])


def test_envelope_keeps_the_extremes():
    rng = np.random.default_rng(1)
    t = np.arange(110001) * 1e-3
    y = rng.normal(size=t.size)
    y[777] = 50.0
    y[50001] = np.nan
    tt, yy = envelope(t, y)
    assert len(tt) < 6200 and np.all(np.diff(tt) > 0) and tt[0] == 0.0 and tt[-1] == t[-1]
    assert np.nanmax(yy) == 50.0 and np.nanmin(yy) == np.nanmin(y)
    k = y.size // 2000
    for b in (0, 14, 999):  # every run keeps its own extremes
        run = y[b * k:(b + 1) * k]
        sel = yy[(tt >= t[b * k]) & (tt <= t[(b + 1) * k - 1])]
        assert np.nanmax(sel) == np.nanmax(run) and np.nanmin(sel) == np.nanmin(run)
    short_t, short_y = envelope(t[:3000], y[:3000])
    assert np.array_equal(short_t, t[:3000])
    x, yp = thin(np.arange(110001.0), np.zeros(110001))
    assert len(x) <= 20002 and x[-1] == 110000.0


def test_another_message_definition_is_a_one_line_error(tmp_path):
    """A bag recorded with an older TrackingError (no robot-frame errors): exit 3, one line naming both md5s."""
    import genpy.dynamic
    import rosbag
    import rospy
    old = genpy.dynamic.generate_dynamic(
        "sowing_robot/TrackingError", "Header header\nfloat64 x\nfloat64 y\nfloat64 theta\n" + "=" * 80 +
        "\nMSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n")["sowing_robot/TrackingError"]
    path = str(tmp_path / "old.bag")
    with rosbag.Bag(path, "w") as bag:
        for k in range(3):
            m = old()
            m.header.stamp = rospy.Time(0, k * 1000000)
            bag.write("/tracking_error", m, rospy.Time(1, k + 1))
    proc = subprocess.run([sys.executable, script(), path, "--no-plots"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 3 and len(lines) == 1, proc.stderr
    assert "another definition" in lines[0] and old._md5sum in lines[0] and lines[0].startswith("analyze_bag: ")
