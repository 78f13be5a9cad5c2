"""Reading sowing_robot bags: validation with one-line errors, topic selection, de-duplicated sorted series."""
import os
import struct

import numpy as np

AXES = ("x", "y", "theta")

# topic -> message type recorded by sim.launch
TOPICS = {
    "/tracking_error": "sowing_robot/TrackingError",
    "/odom": "nav_msgs/Odometry",
    "/reference": "sowing_robot/ReferenceState",
    "/desired_velocity": "sowing_robot/DesiredVelocity",
    "/wheel_torque": "sowing_robot/WheelTorque",
    "/torque_controller/state": "sowing_robot/TorqueControllerState",
}
OPTIONAL_TOPICS = {"/field_markers": ("visualization_msgs/MarkerArray", "visualization_msgs/Marker")}


class BagError(Exception):
    """A bag that cannot be analysed; the message is shown to the user as one line."""


def stamp_to_sec(stamp):
    """ros::Time::toSec(): static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec)."""
    return float(stamp.secs) + 1e-9 * float(stamp.nsecs)


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


def open_bag(path):
    """rosbag.Bag(path) with every failure turned into a one-line BagError."""
    import rosbag
    if not os.path.exists(path):
        raise BagError("%s: no such file" % path)
    if os.path.isdir(path):
        raise BagError("%s: is a directory, not a bag file" % path)
    size = os.path.getsize(path)
    if size == 0:
        raise BagError("%s: empty file (0 bytes): the recording never started or was not copied" % path)
    if not os.access(path, os.R_OK):
        raise BagError("%s: permission denied" % path)
    try:
        return rosbag.Bag(path, "r")
    except rosbag.ROSBagUnindexedException:
        header = _read_bag_header(path)
        if header is not None and header[0] > size:
            raise BagError("%s: truncated bag (%d bytes, its index was to start at byte %d): the file is incomplete; "
                           "`rosbag reindex %s` recovers the complete chunks" % (path, size, header[0], path))
        raise BagError("%s: unindexed bag (the recorder was not closed cleanly, e.g. a .bag.active file); "
                       "run `rosbag reindex %s` to fix it" % (path, path))
    except rosbag.ROSBagException as e:
        raise BagError("%s: not a readable bag: %s" % (path, _one_line(e)))
    except (OSError, EOFError, struct.error, ValueError, KeyError, IndexError, MemoryError) as e:
        raise BagError("%s: corrupt bag: %s" % (path, _one_line(e)))


def _one_line(e):
    text = str(e) or type(e).__name__
    return " ".join(text.split())


class Series(object):
    """Messages of one topic, de-duplicated by header.stamp (first kept) and sorted by stamp."""

    def __init__(self, topic):
        self.topic = topic
        self.stamps = []   # float seconds (toSec)
        self.msgs = []
        self.received = 0  # messages in the bag, duplicates included

    @property
    def duplicates(self):
        return self.received - len(self.msgs)

    def __len__(self):
        return len(self.msgs)


def _select_topics(bag, path):
    """{our topic name: topic in the bag} by name (with the expected type), else by a unique type match."""
    info = bag.get_type_and_topic_info()
    types = {name: t.msg_type for name, t in info.topics.items()}
    chosen = {}
    for topic, msg_type in TOPICS.items():
        if types.get(topic) == msg_type:
            chosen[topic] = topic
            continue
        candidates = [name for name, t in types.items() if t == msg_type]
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
    import rosbag
    bag = open_bag(path)
    try:
        chosen = _select_topics(bag, path)
        series = {topic: Series(name) for topic, name in chosen.items()}
        by_name = {name: series[topic] for topic, name in chosen.items()}
        seen = {topic: set() for topic in chosen}
        by_name_seen = {name: seen[topic] for topic, name in chosen.items()}
        try:
            for name, msg, _t in bag.read_messages(topics=list(by_name)):
                s = by_name[name]
                s.received += 1
                header = getattr(msg, "header", None)
                if header is None:  # MarkerArray: keep every message
                    s.stamps.append(float(s.received))
                    s.msgs.append(msg)
                    continue
                key = header.stamp.to_nsec()
                if key in by_name_seen[name]:
                    continue
                by_name_seen[name].add(key)
                s.stamps.append(stamp_to_sec(header.stamp))
                s.msgs.append(msg)
        except rosbag.ROSBagException as e:
            raise BagError("%s: corrupt bag while reading: %s" % (path, _one_line(e)))
        except (OSError, EOFError, struct.error, ValueError, KeyError, IndexError, MemoryError) as e:
            raise BagError("%s: corrupt bag while reading (%s): %s" % (path, type(e).__name__, _one_line(e)))
        except Exception as e:  # genpy.DeserializationError and friends
            if type(e).__name__ in ("DeserializationError", "SerializationError", "ROSException"):
                raise BagError("%s: corrupt message while reading: %s" % (path, _one_line(e)))
            raise
        bag_start, bag_end = bag.get_start_time(), bag.get_end_time()
    finally:
        bag.close()
    for s in series.values():
        if s.msgs and s.topic != "/field_markers":
            order = sorted(range(len(s.stamps)), key=lambda i: s.stamps[i])
            s.stamps = [s.stamps[i] for i in order]
            s.msgs = [s.msgs[i] for i in order]
    return BagData(path, series, bag_start, bag_end)


class BagData(object):
    """The series of one bag (topic -> Series) and its time span."""

    def __init__(self, path, series, bag_start=0.0, bag_end=0.0):
        self.path = path
        self.series = series
        self.bag_start, self.bag_end = bag_start, bag_end
        self.label = None
        self._errors = None

    def get(self, topic):
        return self.series.get(topic) or Series(topic)

    def mode(self):
        """Controller mode from /torque_controller/state (the most frequent), or None."""
        state = self.get("/torque_controller/state")
        counts = {}
        for m in state.msgs:
            if m.mode:
                counts[m.mode] = counts.get(m.mode, 0) + 1
        return max(counts, key=counts.get) if counts else None

    def error_arrays(self):
        """(t, ex, ey, etheta): every /tracking_error sample (unique stamps, sorted), as float64 arrays."""
        if self._errors is None:
            s = self.get("/tracking_error")
            t = np.array(s.stamps, dtype=float)
            e = np.array([(m.x, m.y, m.theta) for m in s.msgs], dtype=float).reshape(-1, 3)
            self._errors = (t, e[:, 0].copy(), e[:, 1].copy(), e[:, 2].copy())
        return self._errors

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
