"""Metrics of a bag by the C++ core (sowing_robot.core), the thesis's values, the table and the YAML file."""
from sowing_robot import core
from sowing_robot.analyze_bag.bag import AXES, BagError

# Thesis Tables 5.5 and 5.6: {label: {axis: (ise, itse, iae, itae, rise, settling, overshoot %)}}
THESIS = {
    "PSO-ATSMC (thesis)": {
        "x": (2.139, 7.751, 4.609, 24.91, 1.845, 3.157, 2.0),
        "y": (2.247, 7.579, 4.537, 21.34, 2.55, 4.209, 8.0),
        "theta": (2.111, 9.985, 4.82, 34.9, 3.12, 4.21, 6.0),
    },
    "TSMC (thesis)": {
        "x": (3.123, 10.22, 5.418, 28.27, 2.065, 3.638, 3.0),
        "y": (1.94, 11.9, 5.079, 42.95, 3.62, 5.11, 9.0),
        "theta": (2.101, 13.79, 5.33, 48.87, 4.711, 6.337, 7.0),
    },
}
# The table's rows (core::metricsTable), also the keys written by --yaml (run_monitor's metrics_output): the
# core's axisFigures() (core/simulation/metrics.h).
TABLE_FIELDS = core.TABLE_FIELDS


def bag_metrics(data, until=None):
    """core.MetricsAccumulator over the bag's /tracking_error samples (those with t <= until + 1e-9 s if until is
    given): {axis: {field: value}}. BagError when fewer than 2 samples are usable (finite)."""
    t, ex, ey, eth = data.error_arrays()
    if until is not None:
        n = int((t <= until + 1e-9).sum())  # t is sorted: a prefix
        t, ex, ey, eth = t[:n], ex[:n], ey[:n], eth[:n]
    acc = core.MetricsAccumulator(True)
    acc.add_samples(t, ex, ey, eth)
    if acc.samples < 2:
        raise BagError("%s: %d usable /tracking_error sample(s); at least 2 are needed for the metrics"
                       % (data.path, acc.samples))
    return acc.result()


def thesis_runs():
    """(names, runs) of the thesis's two columns, runs in the metrics-dict form (no peak)."""
    names, runs = [], []
    for label, table in THESIS.items():
        names.append(label)
        runs.append({axis: dict(zip(TABLE_FIELDS, table[axis])) for axis in AXES})
    return names, runs


def metrics_table(names, runs):
    """core::metricsTable: names[j] labels runs[j] (metrics dicts)."""
    return core.metrics_table(list(names), list(runs))


def write_yaml(path, labels, runs):
    """{label: {axis: {field: value}}} at full precision (repr round-trips), run_monitor's metrics_output format."""
    with open(path, "w") as f:
        for lab, m in zip(labels, runs):
            f.write("%s:\n" % lab)
            for axis in AXES:
                f.write("  %s: {%s}\n" % (axis, ", ".join("%s: %r" % (k, float(m[axis][k])) for k in TABLE_FIELDS)))
