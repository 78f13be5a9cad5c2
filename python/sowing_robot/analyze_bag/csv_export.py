"""--csv DIR: one tidy CSV per topic and bag (a row per unique stamp, a column per field), for pandas:
  pandas.read_csv("DIR/run_tracking_error.csv", float_precision="round_trip")  # time, stamp_ns, x, y, theta, ...
time is ros::Time::toSec() of header.stamp [s] (what the metrics use), stamp_ns the exact stamp; the rows are
the de-duplicated, stamp-sorted series analyze_bag works on. Floats are written in their shortest form that
reads back exactly (pandas: float_precision="round_trip"; its default parser can be off by an ulp);
booleans as True/False. Written in C++ (sowing_robot._bag.write_csv): for the 1.3 M rows of
two field runs pandas' to_csv took ~8 s.
/field_markers gives <bag>_obstacles.csv: kind, x, y, scale_x, scale_y of the obstacles shown in the figures."""
import os

import numpy as np


def csv_name(topic):
    """/torque_controller/state -> torque_controller_state."""
    return topic.strip("/").replace("/", "_")


def write_csv(datas, out_dir, stems):
    """Writes the CSVs of each bag (file names start with its stem); returns their paths."""
    from sowing_robot import _bag
    os.makedirs(out_dir, exist_ok=True)
    written = []
    for data, stem in zip(datas, stems):
        for topic in sorted(data.series):
            s = data.series[topic]
            if s.markers is not None:
                rows = data.obstacles()
                names = ["kind", "x", "y", "scale_x", "scale_y"]
                columns = [[r[0] for r in rows]] + [np.array([r[k] for r in rows], dtype=float) for k in range(1, 5)]
                path = os.path.join(out_dir, "%s_obstacles.csv" % stem)
            else:
                names = ["time", "stamp_ns"] + list(s.columns)
                columns = [s.stamps, s.stamp_ns] + list(s.columns.values())
                path = os.path.join(out_dir, "%s_%s.csv" % (stem, csv_name(topic)))
            _bag.write_csv(path, names, columns)
            written.append(path)
    return written
