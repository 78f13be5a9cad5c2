"""Reading sowing_robot bags: validation with one-line errors, topic selection, and per topic the columns of
its fields (NumPy arrays), de-duplicated by header.stamp (the first received kept) and sorted by stamp. The
messages are read in C++ (sowing_robot._bag, rosbag's C++ API): rosbag's Python reader needed ~20 s for a
110 s run of the default field."""
import os
import struct

import numpy as np

AXES = ("x", "y", "theta")

# topic -> message type recorded by sim.launch
TOPICS = {
    "/tracking_error": "sowing_robot/TrackingError",
    "/odom": "nav_msgs/Odometry",
    # the true state (before the sensors were modelled /odom was the truth). After /odom: in an old bag the type match
    # below finds only /odom, which /odom has taken, so ground_truth stays absent and truth() falls back.
    "/ground_truth": "nav_msgs/Odometry",
    "/reference": "sowing_robot/ReferenceState",
    "/desired_velocity": "sowing_robot/DesiredVelocity",
    "/wheel_torque": "sowing_robot/WheelTorque",
    "/torque_controller/state": "sowing_robot/TorqueControllerState",
    "/seeds/record": "sowing_robot/Seed",  # one message per seed (seed_drill)
}
# What a lean recording (sim.launch record:=lean, docs/recording.md) leaves out of TOPICS, and what of the report
# goes with it.
LEAN_LACKS = {
    "/wheel_torque": "torque",
    "/torque_controller/state": "saturation and adaptive-estimate",
    "/desired_velocity": "desired-velocity",
}
OPTIONAL_TOPICS = {"/field_markers": ("visualization_msgs/MarkerArray", "visualization_msgs/Marker")}


class BagError(Exception):
    """A bag that cannot be analysed; the message is shown to the user as one line."""


def _read_bag_header(path):
    """(index_pos, conn_count, chunk_count) from the bag's file header record, or None when unreadable."""
    try:
        with open(path, "rb") as f:
            magic = f.read(13)
            if magic != b"#ROSBAG V2.0\n":
                return None
            (hlen,) = struct.unpack("<I", f.read(4))
            header = f.read(hlen)
    except (OSError, struct.error):
        return None
    fields, pos = {}, 0
    while pos + 4 <= len(header):
        (flen,) = struct.unpack("<I", header[pos:pos + 4])
        key, _, value = header[pos + 4:pos + 4 + flen].partition(b"=")
        fields[key] = value
        pos += 4 + flen
    try:
        return (struct.unpack("<Q", fields[b"index_pos"])[0], struct.unpack("<I", fields[b"conn_count"])[0],
                struct.unpack("<I", fields[b"chunk_count"])[0])
    except (KeyError, struct.error):
        return None


def _check_file(path):
    """The failures a file can have before it is opened as a bag, as one-line BagErrors; returns its size."""
    if not os.path.exists(path):
        raise BagError("%s: no such file" % path)
    if os.path.isdir(path):
        raise BagError("%s: is a directory, not a bag file" % path)
    size = os.path.getsize(path)
    if size == 0:
        raise BagError("%s: empty file (0 bytes): the recording never started or was not copied" % path)
    if not os.access(path, os.R_OK):
        raise BagError("%s: permission denied" % path)
    header = _read_bag_header(path)
    if header is not None and header[0] > size:
        raise BagError("%s: truncated bag (%d bytes, its index was to start at byte %d): the file is incomplete; "
                       "`rosbag reindex %s` recovers the complete chunks" % (path, size, header[0], path))
    return size


def open_bag(path):
    """sowing_robot._bag.Reader(path) with every failure turned into a one-line BagError."""
    from sowing_robot import _bag
    _check_file(path)
    try:
        return _bag.Reader(path)
    except _bag.BagUnindexed:
        raise BagError("%s: unindexed bag (the recorder was not closed cleanly, e.g. a .bag.active file); "
                       "run `rosbag reindex %s` to fix it" % (path, path))
    except _bag.BagError as e:
        raise BagError("%s: not a readable bag: %s" % (path, _one_line(e)))


def _one_line(e):
    text = str(e) or type(e).__name__
    return " ".join(text.split())


class Series(object):
    """One topic of a bag: its unique stamps (sorted) and one column per field.

    stamps: t = ros::Time::toSec() of header.stamp [s]; stamp_ns: the stamp in ns; columns: field name ->
    float64 or bool array, or list (strings), e.g. "x", "pose.pose.position.x", "mode". Marker topics have no
    stamps: markers holds the markers (dicts) of the last message."""

    def __init__(self, topic, data=None):
        data = dict(data or {})
        self.topic = topic
        self.received = int(data.pop("received", 0))  # messages in the bag, repeats included
        self.markers = data.pop("markers", None)
        self.stamp_ns = data.pop("stamp_ns", np.zeros(0, dtype=np.int64))
        self.stamps = data.pop("t", np.zeros(0))
        self.columns = data

    def __getitem__(self, field):
        return self.columns[field]

    @property
    def duplicates(self):
        return self.received - len(self.stamps) if self.markers is None else 0

    def __len__(self):
        return len(self.stamps) if self.markers is None else self.received


def _select_topics(types, path):
    """{our topic name: topic in the bag} by name (with the expected type), or the one namespaced so, else by a
    unique type match.
    types: {topic in the bag: message type}."""
    chosen = {}
    for topic, msg_type in TOPICS.items():
        if types.get(topic) == msg_type:
            chosen[topic] = topic
            continue
        candidates = [name for name, t in types.items() if t == msg_type and name not in TOPICS]
        named = [name for name in candidates if name.endswith(topic)]  # a fleet robot's /robot_<i>/ground_truth
        if len(named) == 1:
            chosen[topic] = named[0]
            continue
        # none named as another of ours: a lean bag's (/robot_<i>)/ground_truth is no /odom (the encoders' odometry
        # is not recorded when it is not fed back)
        candidates = [name for name in candidates if not any(name.endswith(t) for t in TOPICS)]
        if len(candidates) == 1 and candidates[0] not in chosen.values():
            chosen[topic] = candidates[0]
    for topic, msg_types in OPTIONAL_TOPICS.items():
        if types.get(topic) in msg_types:
            chosen[topic] = topic
    if not any(t in chosen for t in TOPICS):
        found = ", ".join("%s (%s)" % (n, types[n]) for n in sorted(types)) or "no topics at all"
        raise BagError("%s: foreign bag: none of the sowing_robot topics (%s) in it; found %s"
                       % (path, ", ".join(sorted(TOPICS)), found))
    return chosen


def load_bag(path):
    """Reads one bag into a BagData; raises BagError for anything that is not a usable recording."""
    from sowing_robot import _bag
    reader = open_bag(path)
    try:
        try:
            types = dict(reader.topics())
            chosen = _select_topics(types, path)
            columns = reader.read({name: types[name] for name in chosen.values()})
            bag_start, bag_end = reader.start_time, reader.end_time
        except _bag.DefinitionMismatch as e:
            raise BagError("%s: %s: analyze_bag reads the message definitions of this build" % (path, _one_line(e)))
        except _bag.DeserializationError as e:
            raise BagError("%s: corrupt message while reading: %s" % (path, _one_line(e)))
        except _bag.BagError as e:
            raise BagError("%s: corrupt bag while reading: %s" % (path, _one_line(e)))
    finally:
        reader.close()
    series = {topic: Series(name, columns[name]) for topic, name in chosen.items()}
    return BagData(path, series, bag_start, bag_end)


class BagData(object):
    """The series of one bag (topic -> Series) and its time span."""

    def __init__(self, path, series, bag_start=0.0, bag_end=0.0):
        self.path = path
        self.series = series
        self.bag_start, self.bag_end = bag_start, bag_end
        self.label = None

    def get(self, topic):
        return self.series.get(topic) or Series(topic)

    def truth(self):
        """The robot's true state: /ground_truth, or in a bag recorded before it existed /odom,
        which carried the true state then (truth_from_odom() says so)."""
        s = self.get("/ground_truth")
        return s if len(s) else self.get("/odom")

    def truth_from_odom(self):
        """True when truth() is /odom (an old bag): the caller warns, as /odom is the encoders' now."""
        return not len(self.get("/ground_truth")) and len(self.get("/odom")) > 0

    def is_lean(self):
        """True for a lean recording (sim.launch record:=lean): no /wheel_torque, and /tracking_error at a display
        rate (its stamps 5 ms or more apart; the control loop's are 1 ms)."""
        rate = self.sample_rate("/tracking_error")
        return not len(self.get("/wheel_torque")) and 0.0 < rate <= 200.0

    def lean_notes(self):
        """One line per thing a lean bag lacks, what analyze_bag skips or approximates for it; [] for a full bag."""
        if not self.is_lean():
            return []
        lacking = [topic for topic in LEAN_LACKS if not len(self.get(topic))]
        notes = []
        if lacking:
            notes.append("%s not recorded (lean bag): %s figures skipped"
                         % (", ".join(lacking), ", ".join(LEAN_LACKS[t] for t in lacking)))
        rate = self.sample_rate("/tracking_error")
        notes.append("/tracking_error at %.3g Hz (lean bag): the metrics are approximate, from its samples; "
                     "run_monitor's (metrics_output:=FILE) are exact" % rate)
        return notes

    def sample_rate(self, topic):
        """Samples per second of `topic` from its median stamp step (0 when under 2 samples)."""
        stamps = self.get(topic).stamps
        if len(stamps) < 2:
            return 0.0
        step = float(np.median(np.diff(stamps)))
        return 1.0 / step if step > 0.0 else 0.0

    def mode(self):
        """Controller mode from /torque_controller/state (the most frequent), or None."""
        state = self.get("/torque_controller/state")
        counts = {}
        for mode in state.columns.get("mode", []):
            if mode:
                counts[mode] = counts.get(mode, 0) + 1
        return max(counts, key=counts.get) if counts else None

    def obstacles(self):
        """Obstacle shapes from /field_markers: [(kind, x, y, sx, sy)] in the odom frame."""
        out = []
        s = self.get("/field_markers")
        for mk in s.markers or []:  # those of the last message
            if mk["action"] != 0:  # ADD/MODIFY only
                continue
            x, y, sx, sy = mk["x"], mk["y"], mk["scale_x"], mk["scale_y"]
            if mk["type"] in (2, 3):  # SPHERE, CYLINDER
                out.append(("circle", x, y, sx, sy))
            elif mk["type"] == 1:  # CUBE
                out.append(("box", x, y, sx, sy))
            elif mk["type"] in (6, 7, 8):  # CUBE_LIST, SPHERE_LIST, POINTS
                for qx, qy in mk["points"]:
                    out.append(("circle" if mk["type"] != 6 else "box", x + qx, y + qy, sx, sy))
        return out

    def error_arrays(self):
        """(t, ex, ey, etheta): every /tracking_error sample (unique stamps, sorted), as float64 arrays."""
        s = self.get("/tracking_error")
        if not len(s):
            return (np.zeros(0),) * 4
        return s.stamps, s["x"], s["y"], s["theta"]

    def error_samples(self):
        """(t, ex, ey, etheta, skipped) over the finite /tracking_error samples (for summaries and plots; the
        metrics take every sample and let the C++ accumulator refuse the same non-finite ones)."""
        t, ex, ey, eth = self.error_arrays()
        ok = np.isfinite(t) & np.isfinite(ex) & np.isfinite(ey) & np.isfinite(eth)
        return t[ok], ex[ok], ey[ok], eth[ok], int(len(t) - ok.sum())

    def metrics(self, until=None):
        """{axis: {field: value}} by the C++ core; see metrics.bag_metrics."""
        from sowing_robot.analyze_bag.metrics import bag_metrics
        return bag_metrics(self, until)
