"""sowing_robot.core.run_closed_loop (the C++ in-process runner through pybind11) against the run_scenario
executable's numbers (equal, not close), its trace against its metrics, and analyze_bag on a bag of the trace
against the runner: the chain run_monitor/record.test checks with ROS, here without a master."""
import math
import os
import subprocess

import numpy as np
import pytest
import yaml

from conftest import bits, node, sec_of_ns, write_error_bag
from sowing_robot import core

TABLE_FIELDS = ("ise", "itse", "iae", "itae", "rise_time", "settling_time", "overshoot")


def run_scenario_yaml(tmpdir, *args):
    """Metrics of `run_scenario ARGS --yaml FILE` (C++ writes them at 17 digits, which round-trip)."""
    path = os.path.join(tmpdir, "run.yaml")
    subprocess.run([node("run_scenario")] + list(args) + ["--yaml", path], check=True, stdout=subprocess.DEVNULL,
                   timeout=120)
    with open(path) as f:
        (_label, axes), = yaml.safe_load(f).items()
    return {a: {k: float(v) for k, v in fields.items()} for a, fields in axes.items()}  # "nan" is a str in YAML


def table_part(metrics):
    return {a: {k: metrics[a][k] for k in TABLE_FIELDS} for a in core.AXES}


@pytest.mark.parametrize("adaptive,extra", [(True, {}), (False, {}),
                                            (True, {"disturbance": True, "mass_scale": 1.2, "inertia_scale": 1.2})])
def test_equals_run_scenario(adaptive, extra, tmpdir_path):
    args = ["--atsmc" if adaptive else "--tsmc", "--duration", "4"]
    if extra:
        args += ["--disturbance", "--mismatch", "1.2"]
    expected = run_scenario_yaml(tmpdir_path, *args)
    r = core.run_closed_loop(adaptive=adaptive, duration=4.0, **extra)
    assert bits(table_part(r["metrics"])) == bits(expected)
    assert not r["diverged"] and r["periods"] == 4000


def test_trace_is_the_run():
    r = core.run_closed_loop(duration=2.0, disturbance=True, trace=True)
    tr = r["trace"]
    n = r["periods"] + 1
    assert all(len(v) == n for v in tr.values())
    assert [t.hex() for t in tr["t"][:5]] == [sec_of_ns(k * 1000000).hex() for k in range(5)]
    # the errors of the trace, through the accumulator, give the run's metrics to the bit
    assert bits(core.metrics(tr["t"], tr["ex"], tr["ey"], tr["etheta"])) == bits(r["metrics"])
    # errors are reference minus state (the yaw through a quaternion aside)
    assert np.array_equal(tr["ex"], tr["x_ref"] - tr["x"]) and np.array_equal(tr["ey"], tr["y_ref"] - tr["y"])
    assert tr["x"][0] == -1.0 and tr["y_ref"][0] == 3.0
    assert r["final_state"].shape == (7,)
    assert set(tr["saturated"]) <= {0.0, 1.0}


def test_keep_samples_off_gives_integrals_only():
    full = core.run_closed_loop(duration=1.0)
    fast = core.run_closed_loop(duration=1.0, keep_samples=False)
    for a in core.AXES:
        assert [full["metrics"][a][k] for k in ("ise", "itse", "iae", "itae")] == \
               [fast["metrics"][a][k] for k in ("ise", "itse", "iae", "itae")]
        assert math.isnan(fast["metrics"][a]["rise_time"])


def test_options_change_the_run():
    base = core.run_closed_loop(duration=1.0)["metrics"]["y"]["ise"]
    assert core.run_closed_loop(duration=1.0, start=(-1.0, 0.5, 0.0))["metrics"]["y"]["ise"] != base
    assert core.run_closed_loop(duration=1.0, line=(1.0, 2.0, 0.0))["metrics"]["y"]["ise"] < base
    assert core.run_closed_loop(duration=1.0, noise_std=1.0, seed=3)["metrics"]["y"]["ise"] != base
    assert core.run_closed_loop(duration=1.0, switching="tanh", width=0.05)["metrics"]["y"]["ise"] != base


def test_invalid_scenarios_raise():
    with pytest.raises(ValueError, match="duration"):
        core.run_closed_loop(duration=-1.0)
    with pytest.raises(ValueError, match="switching"):
        core.run_closed_loop(switching="bogus")
    with pytest.raises(TypeError):
        core.run_closed_loop(True)  # keyword-only


def test_bag_of_a_run_equals_the_runner(tmpdir_path):
    """A bag with the runner's errors at the runner's stamps: analyze_bag's metrics == the runner's, bit for bit."""
    from sowing_robot.analyze_bag.bag import load_bag
    r = core.run_closed_loop(duration=3.0, disturbance=True, mass_scale=1.2, inertia_scale=1.2, trace=True)
    tr = r["trace"]
    path = os.path.join(tmpdir_path, "run.bag")
    write_error_bag(path, [k * 1000000 for k in range(len(tr["t"]))], tr["ex"], tr["ey"], tr["etheta"])
    assert bits(load_bag(path).metrics()) == bits(r["metrics"])
    assert bits(load_bag(path).metrics(until=2.0)) == bits(core.run_closed_loop(
        duration=2.0, disturbance=True, mass_scale=1.2, inertia_scale=1.2)["metrics"])
