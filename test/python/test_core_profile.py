"""sowing_robot.core.run_estimated(profile=...): a profile file (config/profiles/NAME.yaml, what sim.launch profile:=
and benchmark --profile apply) read by the benchmark's own loader and applied on top of the call's blocks: the same
run as the keys written out, and the same run as the benchmark's with --profile (its runs.csv, 17 digits)."""
import csv
import os
import subprocess

import pytest

from conftest import bits, node
from sowing_robot import core

HERE = os.path.dirname(os.path.abspath(__file__))
FIELD = os.path.join(os.path.dirname(os.path.dirname(HERE)), "config", "profiles", "field.yaml")
WET = [{"polygon": [[1.0, 0.0], [5.0, 0.0], [5.0, 6.0], [1.0, 6.0]], "mu_peak": 0.25, "mu_slide": 0.2}]
PLANT = dict(duration=4.0, disturbance=True, mass_scale=1.2, inertia_scale=1.2)
# config/profiles/field.yaml spelled out by hand: a key added to the profile and not here fails the tests below
FIELD_KEYS = dict(limits={"enabled": True}, traction={"enabled": True}, motor={"enabled": True}, hitch_control={"enabled": True},
                  traction_control={"enabled": True, "raise_rate": 10.0, "speed_floor": 0.3, "anti_windup": True,
                                    "max_ground_accel": 1.0, "slip_target": 0.1, "min_torque": 1.4},
                  speed_governor={"enabled": True}, estimator={"slip": {"detect": True}})


def test_the_field_profile_is_its_keys_written_out():
    by_name = core.run_estimated(profile="field", patches=WET, **PLANT)
    by_path = core.run_estimated(profile=FIELD, patches=WET, **PLANT)
    spelled = core.run_estimated(feedback="fused", patches=WET, **FIELD_KEYS, **PLANT)
    bare = core.run_estimated(feedback="ground_truth", traction=True, patches=WET, **PLANT)
    assert by_name["profile"] == "field" and bare["profile"] == ""
    assert (by_name["feedback"], by_name["traction"], by_name["motor"], by_name["limits"], by_name["traction_control"],
            by_name["speed_governor"], by_name["hitch_control"]) == ("fused", True, True, True, True, True, True)
    assert bits(by_name["metrics"]) == bits(spelled["metrics"]) == bits(by_path["metrics"])
    assert bits(by_name["metrics"]) != bits(bare["metrics"])
    # the layers at work on the wet stretch, not only switched on
    assert by_name["traction_control_time"] > 0.0 and by_name["governor_min_rate"] < 1.0


def test_the_calls_own_keys_stay_under_the_profile():
    own = dict(traction={"mu_peak": 0.3, "mu_slide": 0.25}, motor={"stall_torque": 30.0}, **PLANT)
    a = core.run_estimated(profile="field", **own)
    keys = dict(FIELD_KEYS, traction={"enabled": True, "mu_peak": 0.3, "mu_slide": 0.25},
                motor={"enabled": True, "stall_torque": 30.0})
    b = core.run_estimated(feedback="fused", **keys, **PLANT)
    assert bits(a["metrics"]) == bits(b["metrics"])
    # the profile's feedback replaces the call's (as a scenario's under benchmark --profile)
    assert core.run_estimated(profile="field", feedback="odometry", **PLANT)["feedback"] == "fused"


@pytest.mark.parametrize("profile,message", [("feild", "unknown profile 'feild'"), ("/no/such.yaml", "no/such.yaml")])
def test_a_bad_profile_is_refused_by_name(profile, message):
    with pytest.raises(ValueError, match=message):
        core.run_estimated(profile=profile, duration=0.1)


SCENARIO = """name: fixed_line
description: thesis line, draws fixed (test_core_profile.py)
track: line
duration: 4.0
control_rate: 1000.0
start: {x: -1.0, y: 0.0, theta: 0.0}
line: {x0: 0.0, v_r: 1.0, y: 3.0}
plant:
  disturbance: {frequency: 3.0}
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
"""


def test_the_profile_gives_the_benchmarks_run(tmpdir_path):
    scenarios = os.path.join(tmpdir_path, "scenarios")
    os.makedirs(scenarios)
    with open(os.path.join(scenarios, "fixed_line.yaml"), "w") as f:
        f.write(SCENARIO)
    tuned = os.path.join(tmpdir_path, "no_tuned")  # empty: the tables' default gains, as run_estimated's
    os.makedirs(tuned)
    out = os.path.join(tmpdir_path, "out")
    subprocess.run([node("benchmark"), "--scenarios", "fixed_line", "--controllers", "kanayama+atsmc", "--seeds", "1",
                    "--output", out, "--scenario-dir", scenarios, "--tuned-dir", tuned, "--threads", "1",
                    "--profile", FIELD], check=True, stdout=subprocess.DEVNULL, timeout=300)
    with open(os.path.join(out, "runs.csv")) as f:
        (row,) = list(csv.DictReader(f))
    r = core.run_estimated(profile="field", seed=int(row["noise_seed"]), sensors={"seed": int(row["sensor_seed"])},
                           **PLANT)
    got = {"%s_%s" % (k, a): float(r["metrics"][a][k]).hex() for a in core.AXES for k in ("ise", "iae", "itae")}
    assert got == {k: float(row[k]).hex() for k in got}
    assert float(r["fed_error_rms"]).hex() == float(row["fed_error_rms"]).hex()
