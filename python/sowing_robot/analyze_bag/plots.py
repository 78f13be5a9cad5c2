"""The thesis-style PNG figures of one or more bags."""
import os

import numpy as np

from sowing_robot.analyze_bag.bag import AXES

# Projection bounds used when config/controllers.yaml cannot be read.
DEFAULT_BOUNDS = {"m0_min": 17.51, "m0_max": 37.51, "i0_min": 0.57, "i0_max": 4.57}


def projection_bounds():
    """m0/i0 projection bounds from the package's config/controllers.yaml (defaults if unreadable)."""
    bounds = dict(DEFAULT_BOUNDS)
    try:
        import rospkg
        import yaml
        path = os.path.join(rospkg.RosPack().get_path("sowing_robot"), "config", "controllers.yaml")
        with open(path) as f:
            cfg = yaml.safe_load(f).get("torque_controller", {})
        for k in bounds:
            if k in cfg:
                bounds[k] = float(cfg[k])
    except Exception:
        pass
    return bounds


def _yaw(odom):
    """Yaw of an Odometry series' orientation quaternions (array)."""
    qx, qy, qz, qw = (odom["pose.pose.orientation." + c] for c in "xyzw")
    return np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


# Points per plotted line: a figure is at most 1430 px wide (13 in at 110 dpi). Drawing, and above all the
# legend's loc="best" (which tests every vertex), took ~15 s for the 110 k samples of two field runs.
ENVELOPE_BUCKETS = 2000
PATH_POINTS = 20000


def envelope(t, y, buckets=ENVELOPE_BUCKETS):
    """(t, y) thinned to the first, the smallest and the largest sample of each of `buckets` runs of samples
    (and the tail), in time order: at the figures' resolution the same line, peaks included."""
    t, y = np.asarray(t), np.asarray(y, dtype=float)
    n = len(y)
    k = n // buckets
    if k < 2:
        return t, y
    m = (n // k) * k
    base = np.arange(0, m, k)
    runs = y[:m].reshape(-1, k)
    finite = np.isfinite(runs)  # a NaN sample is no extreme (nor drawn)
    keep = np.concatenate((base, base + np.argmin(np.where(finite, runs, np.inf), axis=1),
                           base + np.argmax(np.where(finite, runs, -np.inf), axis=1), np.arange(m, n), [n - 1]))
    keep = np.unique(keep)
    return t[keep], y[keep]


def thin(x, y, points=PATH_POINTS):
    """Every k-th point of a path in the plane (and its last), at most points + 1 (the samples are 1 mm apart)."""
    x, y = np.asarray(x), np.asarray(y)
    k = max(1, -(-len(x) // points))  # ceil
    keep = np.unique(np.append(np.arange(0, len(x), k), len(x) - 1)) if len(x) else np.arange(0)
    return x[keep], y[keep]


def write_plots(datas, out_dir, prefix):
    """Writes the thesis-style PNG figures; returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(out_dir, exist_ok=True)
    colors = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown"]
    styles = ["-", "--", "-.", ":"]  # runs often overlap (ATSMC vs TSMC): colour and dash tell them apart
    written = []

    def sty(i, **kw):
        kw.setdefault("lw", 1.3)
        return dict(color=colors[i % len(colors)], ls=styles[i % len(styles)], **kw)

    def plot(ax, t, y, *args, **kw):
        ax.plot(*envelope(t, y), *args, **kw)

    def arr(series, field):
        return series.stamps, np.asarray(series[field], dtype=float)

    def finish(fig, name, title):
        fig.suptitle(title, fontsize=13)
        for ax in fig.axes:
            ax.grid(True, alpha=0.4)
            handles, _ = ax.get_legend_handles_labels()
            if handles:
                ax.legend(fontsize=8, loc="best")
        fig.tight_layout(rect=(0, 0, 1, 0.96))
        path = os.path.join(out_dir, "%s_%s.png" % (prefix, name))
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    # 1. XY path
    fig, ax = plt.subplots(figsize=(9, 6))
    ref = datas[0].get("/reference")
    if len(ref):
        ax.plot(*thin(ref["x"], ref["y"]), "k--", lw=1.5, label="reference")
    for i, d in enumerate(datas):
        odom = d.truth()
        if len(odom):
            xs, ys = odom["pose.pose.position.x"], odom["pose.pose.position.y"]
            ax.plot(*thin(xs, ys), label="robot, %s" % d.label, **sty(i, lw=1.6))
            ax.plot(xs[0], ys[0], "o", color=colors[i % len(colors)], ms=5)
    obstacles = datas[0].obstacles()
    for k, (kind, x, y, sx, sy) in enumerate(obstacles):
        lab = "obstacle" if k == 0 else None
        if kind == "circle":
            ax.add_patch(plt.Circle((x, y), max(sx, sy) / 2.0, color="0.5", alpha=0.5, label=lab))
        else:
            ax.add_patch(plt.Rectangle((x - sx / 2.0, y - sy / 2.0), sx, sy, color="0.5", alpha=0.5, label=lab))
    seeds = datas[0].get("/seeds/record")
    if len(seeds):
        ax.plot(seeds["position.x"], seeds["position.y"], ".", color="tab:green", ms=2, label="seeds")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if obstacles:
        ax.set_aspect("equal", adjustable="datalim")
    finish(fig, "path", "Path in the plane: robot vs reference")

    # 2. posture tracking
    fig, axs = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    units = ("m", "m", "rad")
    if len(ref):
        t = ref.stamps
        vals = (ref["x"], ref["y"], np.unwrap(ref["theta"]))
        for a in range(3):
            plot(axs[a], t, vals[a], "k--", lw=1.5, label="reference")
    for i, d in enumerate(datas):
        odom = d.truth()
        if not len(odom):
            continue
        t = odom.stamps
        vals = (odom["pose.pose.position.x"], odom["pose.pose.position.y"], np.unwrap(_yaw(odom)))
        for a in range(3):
            plot(axs[a], t, vals[a], label=d.label, **sty(i))
    for a, axis in enumerate(AXES):
        axs[a].set_ylabel("%s [%s]" % (axis, units[a]))
    axs[-1].set_xlabel("time [s]")
    finish(fig, "tracking", "Posture tracking: x, y, theta vs reference")

    # 3. errors
    fig, axs = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    for i, d in enumerate(datas):
        t, ex, ey, eth, _ = d.error_samples()
        for a, e in enumerate((ex, ey, eth)):
            plot(axs[a], t, e, label=d.label, **sty(i))
    for a, axis in enumerate(AXES):
        axs[a].axhline(0.0, color="k", lw=0.6)
        axs[a].set_ylabel("e_%s [%s]" % (axis, units[a]))
    axs[-1].set_xlabel("time [s]")
    finish(fig, "errors", "Tracking errors (reference minus actual, world frame)")

    # 4. velocities
    fig, axs = plt.subplots(2, 2, figsize=(13, 8), sharex=True)
    for i, d in enumerate(datas):
        c = colors[i % len(colors)]
        odom, des, st = d.truth(), d.get("/desired_velocity"), d.get("/torque_controller/state")
        if len(des):
            t, v = arr(des, "v")
            plot(axs[0, 0], t, v, color=c, lw=4, alpha=0.3, label="desired v_d, %s" % d.label)
            t, w = arr(des, "omega")
            plot(axs[1, 0], t, w, color=c, lw=4, alpha=0.3, label="desired ω_d, %s" % d.label)
        if len(odom):
            t, v = arr(odom, "twist.twist.linear.x")
            plot(axs[0, 0], t, v, label="actual v, %s" % d.label, **sty(i))
            t, w = arr(odom, "twist.twist.angular.z")
            plot(axs[1, 0], t, w, label="actual ω, %s" % d.label, **sty(i))
        if len(st):
            t, ev = arr(st, "e_v")
            plot(axs[0, 1], t, ev, label=d.label, **sty(i))
            t, ew = arr(st, "e_omega")
            plot(axs[1, 1], t, ew, label=d.label, **sty(i))
    axs[0, 0].set_ylabel("v [m/s]")
    axs[1, 0].set_ylabel("ω [rad/s]")
    axs[0, 1].set_ylabel("e_v = v_d - v [m/s]")
    axs[1, 1].set_ylabel("e_ω = ω_d - ω [rad/s]")
    axs[0, 0].set_title("linear velocity")
    axs[1, 0].set_title("angular velocity")
    axs[0, 1].set_title("linear velocity error")
    axs[1, 1].set_title("angular velocity error")
    for ax in axs[1]:
        ax.set_xlabel("time [s]")
    finish(fig, "velocity", "Body velocities vs desired (Kanayama outer loop output)")

    # 5.-7. need the full recording's torque and controller state (a lean bag has neither): skipped without them
    if not any(len(d.get("/wheel_torque")) or len(d.get("/torque_controller/state")) for d in datas):
        return written

    # 5. torques
    fig, axs = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for i, d in enumerate(datas):
        tq = d.get("/wheel_torque")
        if len(tq):
            t, r = arr(tq, "right")
            plot(axs[0], t, r, label=d.label, **sty(i, lw=1.0))
            t, l_ = arr(tq, "left")
            plot(axs[1], t, l_, label=d.label, **sty(i, lw=1.0))
    axs[0].set_ylabel("τ_R [N·m]")
    axs[1].set_ylabel("τ_L [N·m]")
    axs[0].set_title("right wheel")
    axs[1].set_title("left wheel")
    axs[-1].set_xlabel("time [s]")
    finish(fig, "torques", "Wheel torques")

    # 6. sliding variables
    fig, axs = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for i, d in enumerate(datas):
        st = d.get("/torque_controller/state")
        if len(st):
            t, s1 = arr(st, "s_v")
            plot(axs[0], t, s1, label=d.label, **sty(i, lw=1.0))
            t, s2 = arr(st, "s_omega")
            plot(axs[1], t, s2, label=d.label, **sty(i, lw=1.0))
    axs[0].set_ylabel("S1 = s_v [m/s]")
    axs[1].set_ylabel("S2 = s_ω [rad/s]")
    for ax in axs:
        ax.axhline(0.0, color="k", lw=0.6)
    axs[-1].set_xlabel("time [s]")
    finish(fig, "sliding", "Sliding variables")

    # 7. adaptive estimates: left with the projection bounds, right zoomed on the estimates
    b = projection_bounds()
    fig, axs = plt.subplots(2, 2, figsize=(13, 7), sharex=True)
    rows = (("m0_hat", "m0_min", "m0_max", "m0_hat [kg]", "mass estimate"),
            ("i0_hat", "i0_min", "i0_max", "I0_hat [kg·m²]", "inertia estimate"))
    for r, (fn, lo, hi, ylabel, title) in enumerate(rows):
        for i, d in enumerate(datas):
            st = d.get("/torque_controller/state")
            if len(st):
                t, v = arr(st, fn)
                for c in range(2):
                    plot(axs[r, c], t, v, label=d.label, **sty(i, lw=1.6))
        axs[r, 0].axhline(b[lo], color="k", ls="--", lw=1.0, label="projection bounds [%g, %g]" % (b[lo], b[hi]))
        axs[r, 0].axhline(b[hi], color="k", ls="--", lw=1.0)
        axs[r, 0].set_ylabel(ylabel)
        axs[r, 0].set_title("%s, with the projection bounds" % title)
        axs[r, 1].set_title("%s (zoom)" % title)
        axs[r, 1].ticklabel_format(axis="y", useOffset=False)
    for ax in axs[1]:
        ax.set_xlabel("time [s]")
    finish(fig, "adaptive", "Adaptive parameter estimates (TSMC: fixed nominal values)")
    return written


