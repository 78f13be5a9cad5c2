"""sowing_robot.core.run() and tune() for every controller pair against numbers the C++ core wrote (equal, not
close): golden/pairs.txt (written and checked by the gtest test_pairs_golden), run_scenario's output, and the
tuned gains in config/tuned/ (their files' best_cost, found by the C++ PSO)."""
import glob
import math
import os
import re

import pytest
import yaml

from conftest import bits
from sowing_robot import core
from test_core_runner import run_scenario_yaml, table_part

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "golden", "pairs.txt")
TUNED = os.path.join(os.path.dirname(os.path.dirname(HERE)), "config", "tuned")
LINE = dict(disturbance=True, mass_scale=1.2, inertia_scale=1.2)  # the golden runs' plant


def value(word):
    if re.match(r"^-?0x", word):
        return float.fromhex(word)
    return {"true": True, "false": False}.get(word, word)


def load_golden():
    cases, tunes, cur = [], [], None
    with open(GOLDEN) as f:
        for line in f:
            w = line.split()
            if not w or w[0].startswith("#"):
                continue
            if w[0] == "case":
                cur = {"name": w[1], "pair": w[2], "params": {}, "metrics": {}}
                cases.append(cur)
            elif w[0] == "param":
                cur["params"]["%s/%s" % (w[1], w[2])] = value(w[3])
            elif w[0] == "metrics":
                cur["metrics"][w[1]] = dict(zip(core.FIELDS, (float.fromhex(v) for v in w[2:])))
            elif w[0] == "final":
                cur["final"] = [float.fromhex(v) for v in w[1:]]
            elif w[0] == "counts":
                cur["periods"], cur["saturated"] = int(w[1]), int(w[2])
            elif w[0] == "tune":
                cur = {"pair": w[1], "particles": int(w[2]), "iterations": int(w[3]), "seed": int(w[4]), "gains": {}}
                tunes.append(cur)
            elif w[0] == "best":
                cur["best"], cur["initial"] = float.fromhex(w[1]), float.fromhex(w[2])
            elif w[0] == "gain":
                cur["gains"][w[1]] = float.fromhex(w[2])
            elif w[0] != "end":
                raise ValueError("%s: unknown record %r" % (GOLDEN, line))
    return cases, tunes


CASES, TUNES = load_golden()


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_run_equals_the_golden_run(case):
    r = core.run(controller=case["pair"], params=case["params"] or None, duration=4.0, **LINE)
    assert r["controller"] == case["pair"]
    assert bits(r["metrics"]) == bits(case["metrics"])
    assert [v.hex() for v in r["final_state"]] == [v.hex() for v in case["final"]]
    assert (r["periods"], r["saturated_steps"]) == (case["periods"], case["saturated"])


def test_golden_covers_every_pair_and_the_variant():
    pairs = {c["pair"] for c in CASES}
    assert pairs >= {"kanayama+atsmc", "kanayama+tsmc", "kanayama+pid", "rpp+pid", "rpp+atsmc", "pure_pursuit+pid"}
    assert any(p.get("torque_controller/adaptation") == "eq_4_22" for p in (c["params"] for c in CASES))
    # the cases differ from each other (a swapped controller would not go unnoticed)
    assert len({bits(c["metrics"])["y"]["ise"] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("tune", TUNES, ids=[t["pair"] for t in TUNES])
def test_tune_equals_the_golden_tuning(tune):
    # threads=1 here, 2 in the gtest: the PSO's result does not depend on the thread count
    r = core.tune(controller=tune["pair"], particles=tune["particles"], iterations=tune["iterations"],
                  pso_seed=tune["seed"], threads=1, duration=2.0, **LINE)
    assert r["best_cost"].hex() == tune["best"].hex()
    assert r["initial_best_cost"].hex() == tune["initial"].hex()
    assert list(r["best_gains"]) == list(tune["gains"])
    assert {k: v.hex() for k, v in r["best_gains"].items()} == {k: v.hex() for k, v in tune["gains"].items()}
    assert [b[0] for b in r["bounds"]] == [b[0] for b in core.tunable_gains(tune["pair"])]
    assert len(r["cost_per_iteration"]) == tune["iterations"] + 1
    assert r["cost_per_iteration"][-1] == r["best_cost"] <= r["initial_best_cost"]


@pytest.mark.parametrize("pair,flag", [("kanayama+atsmc", "--atsmc"), ("kanayama+tsmc", "--tsmc")])
def test_run_equals_run_scenario(pair, flag, tmpdir_path):
    expected = run_scenario_yaml(tmpdir_path, flag, "--duration", "3", "--disturbance", "--mismatch", "1.4")
    r = core.run(controller=pair, duration=3.0, disturbance=True, mass_scale=1.4, inertia_scale=1.4)
    assert bits(table_part(r["metrics"])) == bits(expected)


def header(text, key):
    m = re.search(r"^# %s: (\S+)" % key, text, re.M)
    assert m, "no '# %s:' line" % key
    return m.group(1)


TUNED_FILES = sorted(glob.glob(os.path.join(TUNED, "*.yaml")))


def test_every_benchmarked_pair_has_tuned_gains():
    names = {os.path.basename(p)[:-5] for p in TUNED_FILES}
    assert names >= {"kanayama+atsmc", "kanayama+tsmc", "kanayama+pid", "rpp+pid", "rpp+atsmc",
                     "kanayama+atsmc-eq_4_22"}


@pytest.mark.parametrize("path", TUNED_FILES, ids=[os.path.basename(p) for p in TUNED_FILES])
def test_tuned_file_reproduces_its_cost(path):
    """The YAML as rosparam loads it, through the parameter tables, gives the cost the C++ PSO found."""
    with open(path) as f:
        text = f.read()
    pair = header(text, "controller")
    r = core.run(controller=pair, params=yaml.safe_load(text), keep_samples=False, **LINE)
    itae = sum(r["metrics"][a]["itae"] for a in core.AXES)
    # The file records the cost the PSO found with the build it ran on; the core's numbers may since have
    # moved at round-off (std::sin/std::cos in place of a series heading turn: 3e-15 relative), far below
    # any change of the gains.
    assert itae == pytest.approx(float(header(text, "best_cost")), rel=1e-12, abs=0)
    assert itae < float(header(text, "untuned_cost"))


def test_params_and_gains_reach_the_controllers():
    base = core.run(controller="rpp+pid", duration=2.0)["metrics"]["y"]["ise"]
    nested = core.run(controller="rpp+pid", duration=2.0,
                      params={"torque_controller": {"kp": 6.0}})["metrics"]["y"]["ise"]
    flat = core.run(controller="rpp+pid", duration=2.0, params={"torque_controller/kp": 6.0})["metrics"]["y"]["ise"]
    by_name = core.run(controller="rpp+pid", duration=2.0, gains={"kp": 6.0})["metrics"]["y"]["ise"]
    assert nested == flat == by_name != base
    variant = core.run(controller="kanayama+atsmc", duration=2.0, disturbance=True, mass_scale=1.5, inertia_scale=1.5,
                       params={"torque_controller": {"adaptation": "eq_4_22"}})
    today = core.run(controller="kanayama+atsmc", duration=2.0, disturbance=True, mass_scale=1.5, inertia_scale=1.5)
    assert variant["metrics"]["y"]["ise"] != today["metrics"]["y"]["ise"]


def test_bad_names_and_values_raise():
    with pytest.raises(ValueError, match="unknown outer controller"):
        core.run(controller="dwa+pid")
    with pytest.raises(ValueError, match="is no controller parameter"):
        core.run(params={"torque_controller": {"k9": 1.0}})
    with pytest.raises(ValueError, match="k1"):
        core.run(params={"torque_controller": {"k1": -1.0}})
    with pytest.raises(ValueError, match="adaptation"):
        core.run(params={"torque_controller": {"adaptation": "bogus"}})
    with pytest.raises(ValueError, match="no tunable gain of rpp\\+pid"):
        core.run(controller="rpp+pid", gains={"kx": 1.0})
    with pytest.raises(ValueError, match="no tunable gain"):
        core.tune(controller="rpp+pid", bounds=[("kx", 0.1, 10.0)], particles=2, iterations=0, duration=0.1)
    with pytest.raises(ValueError, match="cost"):
        core.tune(cost="bogus", particles=2, iterations=0, duration=0.1)
    assert math.isfinite(core.tune(particles=2, iterations=0, duration=0.1)["best_cost"])
