"""sowing_robot.core.run_estimated (core::runClosedLoop through pybind11): fed the truth it is run() to the bit;
fed the EKF's estimate it is the benchmark's estimated-pose run to the bit (the same scenario through the
`benchmark` executable's runs.csv, 17 digits); its blocks take the nodes' keys and refuse bad ones by name."""
import csv
import os
import subprocess

import numpy as np
import pytest

from conftest import bits, node
from sowing_robot import core

AXES_FIELDS = ("ise", "itse", "iae", "itae", "rise_time", "settling_time", "overshoot")
WET = [{"polygon": [[5.0, 0.0], [15.0, 0.0], [15.0, 6.0], [5.0, 6.0]], "mu_peak": 0.2, "mu_slide": 0.15}]


@pytest.mark.parametrize("pair", ["kanayama+atsmc", "rpp+pid"])
def test_fed_the_truth_it_is_run(pair):
    args = dict(controller=pair, duration=5.0, disturbance=True, mass_scale=1.2, inertia_scale=1.2)
    a = core.run(**args)
    b = core.run_estimated(feedback="ground_truth", **args)
    assert bits(b["metrics"]) == bits(a["metrics"])
    assert np.array_equal(a["final_state"], b["final_state"])
    assert b["fed_error_max"] == 0.0 and b["fixes"]["applied"] == 0  # the truth needs no fix


# The benchmark's estimated_pose scenario with every draw fixed (run_estimated has no amplitude argument:
# the disturbance is the table's 2.75 N.m at 3 rad/s, as disturbance=True gives it); the sensor seed is still
# drawn per run and read back from runs.csv.
SCENARIO = """name: fixed_fused
description: thesis line, fused feedback, draws fixed (test_core_estimated.py)
track: line
duration: 6.0
control_rate: 1000.0
start: {x: -1.0, y: 0.0, theta: 0.0}
line: {x0: 0.0, v_r: 1.0, y: 3.0}
plant:
  disturbance: {frequency: 3.0}
feedback: fused
sensors: {}
estimator: {}
draws:
  base_seed: 1
  mass_scale: 1.2
  inertia_scale: 1.2
  amplitude: 2.75
  phase: 0.0
  noise_std: 0.0
  start_dx: 0.0
  start_dy: 0.0
  start_dtheta: 0.0
success:
  settle_time: 3.0
  cross_track_threshold: 0.05
envelope_period: 0.25
requires: [estimated_pose]
"""


def test_fused_equals_the_benchmark_run(tmpdir_path):
    scenarios = os.path.join(tmpdir_path, "scenarios")
    os.makedirs(scenarios)
    with open(os.path.join(scenarios, "fixed_fused.yaml"), "w") as f:
        f.write(SCENARIO)
    tuned = os.path.join(tmpdir_path, "no_tuned")  # empty: the tables' default gains, as run_estimated's
    os.makedirs(tuned)
    out = os.path.join(tmpdir_path, "out")
    subprocess.run([node("benchmark"), "--scenarios", "fixed_fused", "--controllers", "kanayama+atsmc", "--seeds", "2",
                    "--output", out, "--scenario-dir", scenarios, "--tuned-dir", tuned, "--threads", "1"],
                   check=True, stdout=subprocess.DEVNULL, timeout=300)
    with open(os.path.join(out, "runs.csv")) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    for row in rows:
        r = core.run_estimated(feedback="fused", duration=6.0, disturbance=True, mass_scale=1.2, inertia_scale=1.2,
                               seed=int(row["noise_seed"]), sensors={"seed": int(row["sensor_seed"])},
                               keep_samples=True)
        got = {"%s_%s" % (k, a): float(r["metrics"][a][k]).hex() for a in core.AXES for k in AXES_FIELDS}
        assert got == {k: float(row[k]).hex() for k in got}, row["seed"]
        assert float(r["fed_error_rms"]).hex() == float(row["fed_error_rms"]).hex()
        assert r["fixes"]["applied"] == int(row["fixes_applied"])
    assert rows[0]["sensor_seed"] != rows[1]["sensor_seed"]


def test_fused_estimate_is_close_and_the_trace_says_what_was_fed():
    r = core.run_estimated(feedback="fused", duration=10.0, trace=True)
    assert not r["diverged"] and r["traction"] is False
    assert 0.0 < r["fed_error_rms"] < 0.02 and r["fed_error_max"] < 0.06
    assert r["fixes"]["applied"] >= 95 and r["fixes"]["gated"] == 0
    tr = r["trace"]
    err = np.hypot(tr["fed_x"] - tr["x"], tr["fed_y"] - tr["y"])
    assert err.max() == pytest.approx(r["fed_error_max"], rel=1e-12)
    assert set(tr["slip_right"]) == {0.0}  # the no-slip plant


def test_a_wet_patch_slips_more_and_the_odometry_drifts_more():
    # started on the row: the thesis start's 3 m offset makes the default gains spin the wheels from the start
    runs = [core.run_estimated(feedback="ground_truth", duration=20.0, traction=True, patches=p, start=[0.0, 3.0, 0.0],
                               trace=True) for p in (None, WET)]
    on_patch = []
    for r in runs:
        tr = r["trace"]
        stretch = (tr["x"] > 5.0) & (tr["x"] < 15.0)
        on_patch.append(np.abs(tr["slip_right"][stretch]).max())
    assert on_patch[1] > 1.5 * on_patch[0]  # 0.068 against 0.038
    assert runs[1]["odometry_error_final"] > 1.3 * runs[0]["odometry_error_final"]  # 0.26 m against 0.17 m
    again = core.run_estimated(feedback="ground_truth", duration=20.0, traction=True, patches=WET,
                               start=[0.0, 3.0, 0.0])
    assert bits(again["metrics"]) == bits(runs[1]["metrics"])  # the same arguments, the same run


@pytest.mark.parametrize("kwargs,message", [
    (dict(sensors={"fix": {"sigma": -1.0}}), "sensors/fix/sigma"),
    (dict(estimator={"fix": {"gatee": 1.0}}), "estimator/fix/gatee"),
    (dict(traction={"mu_peak": "wet"}), "traction/mu_peak"),
    (dict(feedback="gps"), "ground_truth, odometry, fused"),
    (dict(traction=True, patches=[{"polygon": [[0, 0], [1, 0]]}]), "patches[0]/polygon"),
    (dict(patches=WET), "patches need traction"),
])
def test_bad_blocks_raise_naming_the_key(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        core.run_estimated(duration=1.0, **kwargs)


def test_the_seed_record_comes_with_its_figures_under_the_registry_names():
    r = core.run_estimated(feedback="fused", duration=10.0)
    seeds, figures = r["seeds"], r["seed_figures"]
    names = {m["name"] for m in core.run_metrics()}
    assert set(figures) <= names and "sown_share" in figures and "quality_of_feed" in figures
    n = len(seeds["t"])
    assert n == figures["seeds"] > 0
    assert all(len(seeds[k]) == n for k in ("x", "y", "believed_x", "believed_y", "row", "depth", "detour"))
    # Fed the EKF's estimate, the robot believed its seeds a little off where they fell; fed the truth, exactly there.
    assert 0.0 < figures["map_error_rms"] < 0.1
    truth = core.run_estimated(feedback="ground_truth", duration=10.0)
    assert truth["seed_figures"]["map_error_rms"] < 1e-12
    # One seed per spacing (0.1 m) of the tool point's travel along the line while it is on it.
    assert np.all(np.diff(seeds["t"]) > 0.0)
