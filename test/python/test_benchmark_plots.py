"""benchmark_plots (python/sowing_robot/benchmark_plots.py) on a tiny hand-written benchmark output: every
figure is written as a PNG, a diverged run (inf) is left out of the boxes and counted, and the comparison
names where the reference pair is worse. The metrics.json here is a hand-written excerpt of the registry
(core/evaluation/run_metrics.h); test_run_metrics.py checks the real one against the reader."""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from sowing_robot import benchmark_plots  # noqa: E402

HEADER = ("scenario,controller,seed,amplitude,itae_y,ise_y,iae_theta,worst_cross_track,final_cross_track,effort,"
          "chattering,time_at_limit,contacts,min_clearance,end_distance,diverged,success,failure\n")
ROWS = [
    # the reference: better tracking, much more chattering; one diverged run on the sweep
    "thesis_line,kanayama+atsmc,0,0.5,3.5,0.1,0.2,0.001,0.001,260,1.2e5,0.004,0,nan,nan,0,1,",
    "thesis_line,kanayama+atsmc,1,1.5,3.6,0.1,0.2,0.002,0.001,270,1.3e5,0.004,0,nan,nan,0,1,",
    "thesis_line,rpp+pid,0,0.5,22.0,0.9,0.5,0.008,0.008,57,180,0,0,nan,nan,0,1,",
    "thesis_line,rpp+pid,1,1.5,23.0,0.9,0.5,0.060,0.008,58,190,0,0,nan,nan,0,0,cross-track",
    "disturbance_sweep,kanayama+atsmc,0,1.0,3.8,0.1,0.2,0.002,0.002,470,8e4,0.005,0,nan,nan,0,1,",
    "disturbance_sweep,kanayama+atsmc,1,7.0,inf,inf,inf,inf,inf,inf,inf,0,0,nan,nan,1,0,diverged",
    "disturbance_sweep,rpp+pid,0,1.0,25.0,1.0,0.5,0.02,0.02,320,350,0,0,nan,nan,0,1,",
    "disturbance_sweep,rpp+pid,1,7.0,26.0,1.1,0.6,0.03,0.03,330,360,0,0,nan,nan,0,1,",
]

def metric(name, unit, label, plots=(), compared=False, aggregation="median", better="lower"):
    return {"name": name, "unit": unit, "label": label, "meaning": label, "format": "number", "group": "always",
            "aggregation": aggregation, "better": better, "compared": compared, "plots": list(plots),
            "report_table": True, "overview": "none"}


METRICS = [
    metric("ise_y", "m²·s", "ISE y", ["box"]),
    metric("itae_y", "m·s²", "ITAE y", ["box", "sweep"], True),
    metric("iae_theta", "rad·s", "IAE θ", ["box"], True),
    metric("effort", "N²·m²·s", "effort", ["box"], True),
    metric("chattering", "N·m", "chattering", ["box"], True),
    metric("time_at_limit", "s", "time at limit", ["box"], True, "mean"),
    metric("worst_cross_track", "m", "worst cross-track", ["box", "sweep"], True),
    metric("final_cross_track", "m", "final cross-track", ["box"]),
    metric("min_clearance", "m", "smallest body clearance", ["box"], better="higher"),
    metric("success", "bool", "success", [], True, "share", "higher"),
]
ENVELOPES = "scenario,controller,t,p05,p25,p50,p75,p95,max_abs\n" + "".join(
    f"thesis_line,{c},{0.1 * k:.1f},-0.01,-0.005,0,0.005,0.01,0.01\n"
    for c in ("kanayama+atsmc", "rpp+pid") for k in range(20))


def write_output(tmp_path):
    (tmp_path / "runs.csv").write_text(HEADER + "\n".join(ROWS) + "\n")
    (tmp_path / "envelopes.csv").write_text(ENVELOPES)
    (tmp_path / "metrics.json").write_text(json.dumps(METRICS))
    return tmp_path


def is_png(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_every_figure_is_written(tmp_path):
    d = write_output(tmp_path)
    out = tmp_path / "plots"
    assert benchmark_plots.main([str(d), "--output", str(out)]) == 0
    for name in ("box_itae_y.png", "box_effort.png", "box_chattering.png", "box_time_at_limit.png",
                 "envelope_thesis_line.png", "sweep_disturbance_sweep.png"):
        assert is_png(out / name), name
    # No obstacles anywhere: no clearance figure.
    assert not (out / "box_min_clearance.png").exists()


def test_a_diverged_run_is_counted_not_plotted(tmp_path):
    rows = benchmark_plots.read_runs(str(write_output(tmp_path) / "runs.csv"))
    diverged = [r for r in rows if r["failure"] == "diverged"]
    assert len(diverged) == 1 and diverged[0]["itae_y"] == float("inf")
    assert benchmark_plots.box_plots(rows, METRICS, str(tmp_path))  # does not raise on inf


def test_the_comparison_names_where_the_reference_loses(tmp_path):
    rows = benchmark_plots.read_runs(str(write_output(tmp_path) / "runs.csv"))
    text = benchmark_plots.comparison(rows, METRICS, "kanayama+atsmc")
    line = [l for l in text.splitlines() if l.startswith("- **thesis_line**")][0]
    assert "vs rpp+pid: " in line and "median chattering" in line and "median effort" in line
    assert "ITAE" not in line  # it tracks better there
    sweep = [l for l in text.splitlines() if l.startswith("- **disturbance_sweep**")][0]
    assert "success 50 % vs 100 %" in sweep


def test_differences_within_the_margin_are_ties(tmp_path):
    rows = benchmark_plots.read_runs(str(write_output(tmp_path) / "runs.csv"))
    for r in rows:  # rpp+pid within 1 % of the reference everywhere on the line
        if r["scenario"] == "thesis_line" and r["controller"] == "rpp+pid":
            ref = [x for x in rows if x["scenario"] == "thesis_line" and x["controller"] == "kanayama+atsmc"
                   and x["seed"] == r["seed"]][0]
            for k in ("itae_y", "worst_cross_track", "iae_theta", "effort", "chattering", "time_at_limit", "success"):
                r[k] = ref[k] * 0.99
    line = [l for l in benchmark_plots.comparison(rows, METRICS).splitlines() if l.startswith("- **thesis_line**")][0]
    assert line.endswith("nowhere"), line


def test_a_missing_directory_is_one_error_line(tmp_path, capsys):
    assert benchmark_plots.main([str(tmp_path / "nothing")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("benchmark_plots: ") and err.count("\n") == 1


def test_a_directory_without_metrics_json_is_one_error_line(tmp_path, capsys):
    d = write_output(tmp_path)
    (d / "metrics.json").unlink()
    assert benchmark_plots.main([str(d)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("benchmark_plots: ") and "metrics.json" in err and err.count("\n") == 1
