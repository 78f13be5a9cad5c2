"""sowing_robot.core's metrics (the C++ MetricsAccumulator through pybind11) and analyze_bag's bag path against
golden numbers that the C++ core wrote (metrics_golden.cpp, checked against the core by test_metrics_golden),
to the last bit, on the edge cases: one sample, uneven stamps, a gap, non-finite samples, a peak at t = 0, ..."""
import math
import os

import numpy as np
import pytest

from conftest import bits, sec_of_ns, write_error_bag
from sowing_robot import core

GOLDEN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "golden", "metrics_edge_cases.txt")


def load_golden():
    cases, cur = {}, None
    with open(GOLDEN) as f:
        for line in f:
            w = line.split()
            if not w or w[0].startswith("#"):
                continue
            if w[0] == "case":
                cur = cases[w[1]] = {"ns": [], "t": [], "ex": [], "ey": [], "eth": [], "kept": {}, "integrals": {}}
            elif w[0] == "s":
                cur["ns"].append(int(w[1]))
                for key, v in zip(("t", "ex", "ey", "eth"), w[2:]):
                    cur[key].append(float.fromhex(v))
            elif w[0] == "count":
                cur["accepted"], cur["rejected"] = int(w[1]), int(w[2])
            elif w[0] in ("kept", "integrals"):
                cur[w[0]][w[1]] = dict(zip(core.FIELDS, (float.fromhex(v) for v in w[2:])))
            elif w[0] != "end":
                raise ValueError("%s: unknown record %r" % (GOLDEN, line))
    return cases


CASES = load_golden()
NAMES = sorted(CASES)


def arrays(c):
    return tuple(np.array(c[k], dtype=float) for k in ("t", "ex", "ey", "eth"))


def test_the_edge_cases_are_there():
    for name in ("one_sample", "uneven_stamps", "gap", "nan_sample", "peak_at_t0"):
        assert name in CASES
    assert CASES["nan_sample"]["rejected"] == 3
    assert len(CASES["one_sample"]["t"]) == 1


def test_fields_are_the_cores():
    assert core.FIELDS == ("ise", "itse", "iae", "itae", "rise_time", "settling_time", "overshoot", "peak")
    assert core.AXES == ("x", "y", "theta")


@pytest.mark.parametrize("name", NAMES)
def test_stamps_to_seconds_as_ros_time(name):
    c = CASES[name]
    assert [sec_of_ns(ns).hex() for ns in c["ns"]] == [t.hex() for t in c["t"]]


@pytest.mark.parametrize("name", NAMES)
def test_sample_by_sample_equals_golden(name):
    c = CASES[name]
    acc = core.MetricsAccumulator(keep_samples=True)
    accepted = [acc.add(t, x, y, th) for t, x, y, th in zip(c["t"], c["ex"], c["ey"], c["eth"])]
    assert (sum(accepted), acc.samples, acc.rejected) == (c["accepted"], c["accepted"], c["rejected"])
    assert bits(acc.result()) == bits(c["kept"])


@pytest.mark.parametrize("name", NAMES)
def test_arrays_equal_golden(name):
    c = CASES[name]
    t, ex, ey, eth = arrays(c)
    acc = core.MetricsAccumulator()
    assert acc.add_samples(t, ex, ey, eth) == c["accepted"]
    assert bits(acc.result()) == bits(c["kept"])
    assert bits(core.metrics(t, ex, ey, eth)) == bits(c["kept"])
    assert bits(core.metrics(t, ex, ey, eth, keep_samples=False)) == bits(c["integrals"])
    # lists convert too
    assert bits(core.metrics(list(t), list(ex), list(ey), list(eth))) == bits(c["kept"])


@pytest.mark.parametrize("name", NAMES)
def test_time_domain_metrics_equal_golden(name):
    c = CASES[name]
    t, ex, ey, eth = arrays(c)
    ok = np.isfinite(t) & np.isfinite(ex) & np.isfinite(ey) & np.isfinite(eth)  # what the accumulator kept
    for axis, e in zip(core.AXES, (ex, ey, eth)):
        td = core.time_domain_metrics(t[ok], e[ok])
        assert {k: v.hex() for k, v in td.items()} == {k: c["kept"][axis][k].hex() for k in td}


def test_reset_and_accumulate_in_pieces():
    c = CASES["gap"]
    t, ex, ey, eth = arrays(c)
    acc = core.MetricsAccumulator()
    acc.add_samples(t[:5], ex[:5], ey[:5], eth[:5])
    acc.reset()
    assert acc.samples == 0
    half = len(t) // 2
    acc.add_samples(t[:half], ex[:half], ey[:half], eth[:half])
    acc.add_samples(t[half:], ex[half:], ey[half:], eth[half:])
    assert bits(acc.result()) == bits(c["kept"])


def test_bad_arrays_are_refused():
    with pytest.raises(ValueError):
        core.metrics([0.0, 1.0], [0.0], [0.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError):
        core.metrics(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError):
        core.time_domain_metrics([0.0, 1.0], [1.0])


def test_empty_accumulator():
    r = core.MetricsAccumulator().result()
    assert r["x"]["ise"] == 0.0 and math.isnan(r["x"]["rise_time"])


# --- analyze_bag reads a bag of these samples into the same numbers -------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_bag_metrics_equal_golden(name, tmpdir_path):
    from sowing_robot.analyze_bag.bag import BagError, load_bag
    c = CASES[name]
    path = os.path.join(tmpdir_path, name + ".bag")
    write_error_bag(path, c["ns"], c["ex"], c["ey"], c["eth"], shuffle_seed=len(c["ns"]))  # received unsorted
    data = load_bag(path)
    if c["accepted"] < 2:
        with pytest.raises(BagError, match="at least 2"):
            data.metrics()
        return
    assert bits(data.metrics()) == bits(c["kept"])
    t = data.error_samples()[0]
    assert len(t) == c["accepted"] and np.all(np.diff(t) > 0)
