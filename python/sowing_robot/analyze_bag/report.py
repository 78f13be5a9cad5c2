"""Per-bag summary lines and the detection of recorder gaps."""
from sowing_robot.analyze_bag.bag import TOPICS


def gaps(stamps):
    """(missing samples, gaps) in a series sampled at a constant period (the median step)."""
    if len(stamps) < 3:
        return 0, 0
    steps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    period = steps[len(steps) // 2]
    if not period > 0.0:
        return 0, 0
    missing = count = 0
    for a, b in zip(stamps, stamps[1:]):
        k = int(round((b - a) / period))
        if k >= 2:
            missing += k - 1
            count += 1
    return missing, count


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
                     % (max(abs(m.right) for m in torque.msgs), max(abs(m.left) for m in torque.msgs)))
    state = data.get("/torque_controller/state")
    if len(state):
        sat = [bool(m.saturated) for m in state.msgs]
        runs = sum(1 for i, s in enumerate(sat) if s and (i == 0 or not sat[i - 1]))
        lines.append("- saturated: %d control periods (%d episodes)" % (sum(sat), runs))
        last = state.msgs[-1]
        lines.append("- final m0_hat %.5g kg, i0_hat %.5g kg·m²  (mode %s)" % (last.m0_hat, last.i0_hat, last.mode))
    others = ["%s %d" % (topic, len(data.get(topic))) for topic in TOPICS if topic != "/tracking_error"]
    lines.append("- other topics (unique stamps): " + ", ".join(others))
    return "\n".join(lines)


