"""Figures and the comparison table of a `benchmark` output directory.

Reads DIR/runs.csv (one row per run), DIR/metrics.json (the benchmark's metric registry, core/evaluation/
run_metrics.h: each metric's name, unit, label, which figures it gets, how runs aggregate and which direction is
better) and DIR/envelopes.csv (per scenario, controller and time: quantiles of the cross-track error over the
runs, computed by the C++ benchmark from each run's cross-track sampled every envelope_period) and writes, into
the output directory:

- box_<metric>.png for every metric whose plots include "box": one panel per scenario, one box per controller
  (runs whose value is not finite, i.e. diverged, are left out of the box and counted in the panel's title; a
  metric no run has, e.g. min_clearance without obstacles, gets no figure);
- envelope_<scenario>.png: per controller, the median cross-track and its 25-75 % and 5-95 % bands over time;
- sweep_<scenario>.png for scenarios named *sweep*: the metrics whose plots include "sweep" against the drawn
  disturbance amplitude, one colour per controller;
- comparison.md: per scenario, where the reference pair (kanayama+atsmc) is worse than another pair by more
  than --margin (5 %) in a compared metric: a share (success rate) by at least one run, the others by their
  aggregation over the runs (median, or mean for the time at the torque limit); the raw material of a reading.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from sowing_robot.cli import Parser  # noqa: E402

def _float(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def read_runs(path):
    """runs.csv as a list of dicts; numeric columns as floats (inf and nan kept)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no runs")
    text_cols = {"scenario", "set", "controller", "failure"}
    for r in rows:
        for k, v in r.items():
            if k not in text_cols:
                r[k] = _float(v)
    return rows


def read_metrics(path):
    """metrics.json (written by benchmark beside runs.csv) as a list of dicts, one per metric."""
    with open(path) as f:
        metrics = json.load(f)
    for m in metrics:
        for k in ("name", "unit", "label", "aggregation", "better", "compared", "plots"):
            if k not in m:
                raise ValueError(f"{path}: metric without '{k}'")
    return metrics


def _plotted(metrics, kind):
    return [m for m in metrics if kind in m["plots"]]


def _title(m):
    return f"{m['label']} [{m['unit']}]"


def read_envelopes(path):
    """envelopes.csv as {(scenario, controller): {column: [values]}}; {} when the file is missing."""
    if not os.path.exists(path):
        return {}
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            key = (r["scenario"], r["controller"])
            d = out.setdefault(key, {c: [] for c in ("t", "p05", "p25", "p50", "p75", "p95", "max_abs")})
            for c in d:
                d[c].append(_float(r[c]))
    return out


def _ordered(values):
    seen = []
    for v in values:
        if v not in seen:
            seen.append(v)
    return seen


def _median(values):
    v = sorted(values)
    if not v:
        return math.nan
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def _save(fig, out_dir, name, title, written, **title_style):
    """Titles, lays out, writes (DIR/name, 90 dpi) and closes one figure; appends its name to `written`."""
    fig.suptitle(title, **title_style)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, name), dpi=90)
    plt.close(fig)
    written.append(name)


def box_plots(rows, metrics, out_dir):
    """One PNG per metric whose plots include "box" (metrics: read_metrics()); returns the file names written."""
    scenarios = _ordered(r["scenario"] for r in rows)
    controllers = _ordered(r["controller"] for r in rows)
    written = []
    for m in _plotted(metrics, "box"):
        metric, label = m["name"], _title(m)
        if metric not in rows[0]:
            continue
        panels = [s for s in scenarios if any(math.isfinite(r[metric]) for r in rows if r["scenario"] == s)]
        if not panels:
            continue
        cols = min(3, len(panels))
        nrows = int(math.ceil(len(panels) / cols))
        fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.4 * nrows), squeeze=False)
        for i, s in enumerate(panels):
            ax = axes[i // cols][i % cols]
            data, dropped = [], 0
            for c in controllers:
                vals = [r[metric] for r in rows if r["scenario"] == s and r["controller"] == c]
                finite = [v for v in vals if math.isfinite(v)]
                dropped += len(vals) - len(finite)
                data.append(finite if finite else [math.nan])
            ax.boxplot(data, labels=controllers, showfliers=True)
            ax.set_title(s + (f" ({dropped} not finite)" if dropped else ""), fontsize=9)
            ax.tick_params(axis="x", labelrotation=30, labelsize=7)
            flat = [v for d in data for v in d if math.isfinite(v)]
            if flat and min(flat) > 0 and max(flat) / min(flat) > 100:
                ax.set_yscale("log")
        for j in range(len(panels), nrows * cols):
            axes[j // cols][j % cols].axis("off")
        _save(fig, out_dir, f"box_{metric}.png", label, written)
    return written


def envelope_plots(envelopes, out_dir):
    """One PNG per scenario: a panel per controller with the cross-track quantile bands over time."""
    written = []
    for s in _ordered(k[0] for k in envelopes):
        controllers = [k[1] for k in envelopes if k[0] == s]
        fig, axes = plt.subplots(len(controllers), 1, figsize=(8, 1.9 * len(controllers) + 0.6), sharex=True,
                                 squeeze=False)
        for ax, c in zip(axes[:, 0], controllers):
            e = envelopes[(s, c)]
            ax.fill_between(e["t"], e["p05"], e["p95"], alpha=0.25, label="5-95 %")
            ax.fill_between(e["t"], e["p25"], e["p75"], alpha=0.5, label="25-75 %")
            ax.plot(e["t"], e["p50"], lw=0.8, label="median")
            ax.set_ylabel("e_y [m]", fontsize=8)
            ax.set_title(c, fontsize=9)
            # The start transient (metres) would hide the tracking (millimetres): show the band after it.
            late = [abs(v) for t, lo, hi in zip(e["t"], e["p05"], e["p95"]) if t >= 0.3 * e["t"][-1]
                    for v in (lo, hi) if math.isfinite(v)]
            if late:
                lim = max(late) * 1.3 or 1e-3
                ax.set_ylim(-lim, lim)
        axes[0, 0].legend(fontsize=7, loc="upper right")
        axes[-1, 0].set_xlabel("t [s]")
        _save(fig, out_dir, f"envelope_{s}.png",
              f"{s}: cross-track envelope over the runs (y range: after the first 30 % of the run)", written,
              fontsize=9)
    return written


def sweep_plots(rows, metrics, out_dir):
    """For scenarios named *sweep*: the metrics whose plots include "sweep" against the drawn amplitude."""
    written = []
    swept = [m for m in _plotted(metrics, "sweep") if m["name"] in rows[0]]
    if not swept:
        return written
    for s in _ordered(r["scenario"] for r in rows):
        if "sweep" not in s:
            continue
        fig, axes = plt.subplots(1, len(swept), figsize=(5 * len(swept), 3.6), squeeze=False)
        axes = axes[0]
        for c in _ordered(r["controller"] for r in rows if r["scenario"] == s):
            pts = [r for r in rows if r["scenario"] == s and r["controller"] == c]
            for ax, m in zip(axes, swept):
                ax.scatter([r["amplitude"] for r in pts], [r[m["name"]] for r in pts], s=8, label=c)
        for ax, m in zip(axes, swept):
            ax.set_xlabel("disturbance amplitude A [N·m]")
            ax.set_ylabel(_title(m))
            ax.set_yscale("log")
        axes[0].legend(fontsize=7)
        _save(fig, out_dir, f"sweep_{s}.png", s, written)
    return written


def _fmt(v):
    return "inf" if v == math.inf else f"{v:.4g}"


def comparison(rows, metrics, reference="kanayama+atsmc", margin=0.05):
    """Markdown: per scenario and other pair, every compared metric (metrics: read_metrics()) where `reference`
    is worse by more than `margin` (relative; a share, e.g. the success rate, by at least one run), with both
    values. Smaller differences are ties. Shares come first, then the others in the registry's order."""
    lines = [f"Where **{reference}** is worse than another pair by more than {100 * margin:g} % (generated from "
             "runs.csv by benchmark_plots; success: by at least one run):", ""]
    any_loss = False
    compared = [m for m in metrics if m["compared"] and m["name"] in rows[0]]
    compared = ([m for m in compared if m["aggregation"] == "share"] +
                [m for m in compared if m["aggregation"] != "share"])

    def figure(runs, m):
        vals = [r[m["name"]] for r in runs]
        if m["aggregation"] == "share":
            return 100.0 * sum(1 for v in vals if v == 1) / len(vals)
        if m["aggregation"] == "mean":
            return sum(vals) / len(vals)
        return _median([v if not math.isnan(v) else math.inf for v in vals])

    def worse(a, b, m, runs):  # a (reference) worse than b
        if m["better"] == "higher":
            a, b = b, a
        if m["aggregation"] == "share":
            return a - b >= 100.0 / max(len(runs), 1) - 1e-9
        if a == b or math.isnan(a) or math.isnan(b):
            return False
        if b == 0.0:
            return a > 0.0
        return a > b * (1.0 + margin)

    for s in _ordered(r["scenario"] for r in rows):
        by = {}
        for r in rows:
            if r["scenario"] == s:
                by.setdefault(r["controller"], []).append(r)
        if reference not in by:
            continue
        ref = by[reference]
        per_pair = []
        for c, runs in by.items():
            if c == reference:
                continue
            losses = []
            for m in compared:
                a, b = figure(ref, m), figure(runs, m)
                if not worse(a, b, m, runs):
                    continue
                if m["aggregation"] == "share":
                    losses.append(f"{m['label']} {_fmt(a)} % vs {_fmt(b)} %")
                else:
                    losses.append(f"{m['aggregation']} {m['label']} {_fmt(a)} vs {_fmt(b)}")
            if losses:
                per_pair.append(f"vs {c}: " + ", ".join(losses))
        lines.append(f"- **{s}**: " + ("; ".join(per_pair) if per_pair else "nowhere"))
        any_loss = any_loss or bool(per_pair)
    if not any_loss:
        lines.append("")
        lines.append(f"({reference} is not worse in any compared figure.)")
    return "\n".join(lines) + "\n"


def main(argv=None):
    p = Parser(__doc__, prog="benchmark_plots")
    p.add_argument("dir", help="a benchmark --output directory (runs.csv, metrics.json, envelopes.csv)")
    p.add_argument("--output", help="where the PNGs and comparison.md go (default: DIR)")
    p.add_argument("--reference", default="kanayama+atsmc", help="the pair compared against the others")
    p.add_argument("--margin", type=float, default=0.05, help="relative difference below which figures tie")
    a = p.parse_args(argv)
    out = a.output or a.dir
    os.makedirs(out, exist_ok=True)
    try:
        rows = read_runs(os.path.join(a.dir, "runs.csv"))
        metrics = read_metrics(os.path.join(a.dir, "metrics.json"))
    except (OSError, ValueError, KeyError) as e:
        print(f"benchmark_plots: {e}", file=sys.stderr)
        return 2
    files = box_plots(rows, metrics, out)
    files += envelope_plots(read_envelopes(os.path.join(a.dir, "envelopes.csv")), out)
    files += sweep_plots(rows, metrics, out)
    with open(os.path.join(out, "comparison.md"), "w") as f:
        f.write(comparison(rows, metrics, a.reference, a.margin))
    files.append("comparison.md")
    print(f"benchmark_plots: {len(files)} files in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
