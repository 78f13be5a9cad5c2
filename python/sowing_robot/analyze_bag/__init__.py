"""Tracking performance of recorded sowing_robot runs (thesis Tables 5.5/5.6) and the thesis-style figures.

  rosrun sowing_robot analyze_bag run.bag [more.bag ...] [options]   (--help: the options, from cli.py)

Reads bags recorded by `roslaunch sowing_robot sim.launch record:=full bag:=NAME`, prints one Markdown table
(core::metricsTable) with one column per bag, a short per-bag summary, and writes PNG figures. A lean bag
(record:=lean, docs/recording.md) gives what it can: metrics from its 10 Hz /tracking_error (approximate), the
seed figures of /seeds/record, the path and tracking figures; a note line on stderr names what it lacks.

Every metric is computed by the C++ core (core::MetricsAccumulator through the sowing_robot.core module), the
code run_monitor and the in-process runner use, so the three agree to the bit. The samples are
/tracking_error's, with t = sec + 1e-9 * nsec as ros::Time::toSec() computes it (genpy's to_sec() divides by
1e9, which differs in the last bit for about 4 % of millisecond stamps), de-duplicated by header.stamp (the
first kept) and sorted by stamp, as run_monitor sees them; the accumulator skips non-finite samples.

The bags are read in C++ (sowing_robot._bag: rosbag's C++ API into NumPy columns), about 1.5 s of CPU for a
110 s run of the default field; rosbag's Python reader needed ~20 s.

Modules: bag (reading and validation), metrics (C++ metrics of a bag, the thesis values, the table and YAML),
report (per-bag summary, gaps), plots (figures), csv_export (--csv), cli (command line; exit codes 0 ok,
1 internal error, 2 bad usage, 3 bad bag).
"""
from sowing_robot.analyze_bag.cli import EXIT_BAD_BAG, EXIT_INTERNAL, EXIT_OK, EXIT_USAGE, main  # noqa: F401
