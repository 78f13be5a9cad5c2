"""sowing_robot.core.run_metrics(): the benchmark's metric registry (core/evaluation/run_metrics.h), as the
benchmark writes it to metrics.json: names unique, each with a unit and a one-line meaning, and every field
benchmark_plots reads, with values it knows; the axis figures are those of the metrics YAML."""
from sowing_robot import core


def test_names_are_unique_and_each_has_a_unit_and_a_meaning():
    metrics = core.run_metrics()
    names = [m["name"] for m in metrics]
    assert len(names) == len(set(names))
    for m in metrics:
        assert m["unit"] and m["label"], m["name"]
        assert m["meaning"] and "\n" not in m["meaning"], m["name"]


def test_every_entry_has_what_benchmark_plots_reads():
    for m in core.run_metrics():
        assert m["format"] in ("number", "count", "flag"), m
        assert m["group"] in ("always", "realism"), m
        assert m["aggregation"] in ("median", "mean", "share"), m
        assert m["better"] in ("lower", "higher", "none"), m
        assert set(m["plots"]) <= {"box", "sweep"}, m
        assert isinstance(m["compared"], bool) and isinstance(m["report_table"], bool), m
        assert isinstance(m["overview_column"], int) and isinstance(m["overview_p95"], bool), m
        assert not (m["compared"] and m["better"] == "none"), m
    by = {m["name"]: m for m in core.run_metrics()}
    assert by["success"]["aggregation"] == "share" and by["success"]["better"] == "higher"
    assert by["worst_cross_track"]["unit"] == "m" and "sweep" in by["worst_cross_track"]["plots"]


def test_the_axis_columns_are_the_yaml_figures_on_each_axis():
    names = {m["name"] for m in core.run_metrics()}
    assert core.TABLE_FIELDS == ("ise", "itse", "iae", "itae", "rise_time", "settling_time", "overshoot")
    assert core.FIELDS == core.TABLE_FIELDS + ("peak",)
    for axis in core.AXES:
        for f in core.TABLE_FIELDS:
            assert f + "_" + axis in names
