"""Per-bag summary lines and the detection of recorder gaps."""
import numpy as np

from sowing_robot.analyze_bag.bag import TOPICS


def gaps(stamps):
    """(missing samples, gaps) in a series sampled at a constant period (the median step)."""
    if len(stamps) < 3:
        return 0, 0
    steps = np.diff(np.asarray(stamps, dtype=float))
    period = np.sort(steps)[len(steps) // 2]
    if not period > 0.0:
        return 0, 0
    k = np.rint(steps / period)  # round half to even, as round()
    k = k[k >= 2]
    return int((k - 1).sum()), int(len(k))


def summary(data, until=None):
    """Short per-bag summary lines (Markdown bullet list)."""
    lines = ["### %s (%s)" % (data.label, data.path)]
    t, ex, ey, eth, skipped = data.error_samples()
    te = data.get("/tracking_error")
    if until is not None:
        n = int((t <= until + 1e-9).sum())  # t is sorted: a prefix
        t, ex, ey, eth = t[:n], ex[:n], ey[:n], eth[:n]
    missing, ngaps = gaps(te.stamps)
    lines.append("- duration: %.3f s of tracking error (t = %.3f .. %.3f s); bag %.3f s"
                 % (t[-1] - t[0], t[0], t[-1], data.bag_end - data.bag_start))
    extra = []
    if te.duplicates:
        extra.append("%d repeated stamps dropped" % te.duplicates)
    if skipped:
        extra.append("%d non-finite skipped" % skipped)
    if ngaps:
        extra.append("%d samples MISSING in %d gaps (the recorder dropped messages; the integrals bridge them)"
                     % (missing, ngaps))
    lines.append("- samples: %d /tracking_error%s" % (len(t), ("; " + ", ".join(extra)) if extra else ""))
    lines.append("- final errors: x %.4g m, y %.4g m, theta %.4g rad" % (ex[-1], ey[-1], eth[-1]))
    torque = data.get("/wheel_torque")
    if len(torque):
        lines.append("- max |torque|: right %.4g N·m, left %.4g N·m"
                     % (np.abs(torque["right"]).max(), np.abs(torque["left"]).max()))
    state = data.get("/torque_controller/state")
    if len(state):
        sat = np.asarray(state["saturated"], dtype=bool)
        runs = int((sat & ~np.concatenate(([False], sat[:-1]))).sum())  # rising edges
        lines.append("- saturated: %d control periods (%d episodes)" % (int(sat.sum()), runs))
        lines.append("- final m0_hat %.5g kg, i0_hat %.5g kg·m²  (mode %s)"
                     % (state["m0_hat"][-1], state["i0_hat"][-1], state["mode"][-1]))
    seeds = data.get("/seeds/record")
    if len(seeds):
        off = np.hypot(seeds["position.x"] - seeds["believed.x"], seeds["position.y"] - seeds["believed.y"])
        detour = np.asarray(seeds["detour"], dtype=bool)
        lines.append("- seeds: %d (%d in detours), depth mean %.4g m; fell from where the robot believed its tool: "
                     "max %.4g m, RMS %.4g m" % (len(seeds), int(detour.sum()), float(np.mean(seeds["depth"])),
                                                 float(off.max()), float(np.sqrt(np.mean(off ** 2)))))
    others = ["%s %d" % (topic, len(data.get(topic))) for topic in TOPICS if topic != "/tracking_error"]
    lines.append("- other topics (unique stamps): " + ", ".join(others))
    return "\n".join(lines)


