"""The thesis-style PNG figures of one or more bags."""
import math
import os

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


def _yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _markers(data):
    """Obstacle shapes from /field_markers: (kind, x, y, sx, sy) in the odom frame."""
    out = []
    s = data.get("/field_markers")
    if not len(s):
        return out
    last = s.msgs[-1]
    for mk in getattr(last, "markers", [last]):
        if mk.action != 0:  # ADD/MODIFY only
            continue
        p = mk.pose.position
        if mk.type in (2, 3):  # SPHERE, CYLINDER
            out.append(("circle", p.x, p.y, mk.scale.x, mk.scale.y))
        elif mk.type == 1:  # CUBE
            out.append(("box", p.x, p.y, mk.scale.x, mk.scale.y))
        elif mk.type in (6, 7, 8):  # CUBE_LIST, SPHERE_LIST, POINTS
            for q in mk.points:
                out.append(("circle" if mk.type != 6 else "box", p.x + q.x, p.y + q.y, mk.scale.x, mk.scale.y))
    return out


def write_plots(datas, out_dir, prefix):
    """Writes the thesis-style PNG figures; returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    os.makedirs(out_dir, exist_ok=True)
    colors = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown"]
    styles = ["-", "--", "-.", ":"]  # runs often overlap (ATSMC vs TSMC): colour and dash tell them apart
    written = []

    def sty(i, **kw):
        kw.setdefault("lw", 1.3)
        return dict(color=colors[i % len(colors)], ls=styles[i % len(styles)], **kw)

    def arr(series, fn):
        return np.array(series.stamps), np.array([fn(m) for m in series.msgs], dtype=float)

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
        ax.plot([m.x for m in ref.msgs], [m.y for m in ref.msgs], "k--", lw=1.5, label="reference")
    for i, d in enumerate(datas):
        odom = d.get("/odom")
        if len(odom):
            xs = [m.pose.pose.position.x for m in odom.msgs]
            ys = [m.pose.pose.position.y for m in odom.msgs]
            ax.plot(xs, ys, label="robot, %s" % d.label, **sty(i, lw=1.6))
            ax.plot(xs[0], ys[0], "o", color=colors[i % len(colors)], ms=5)
    obstacles = _markers(datas[0])
    for k, (kind, x, y, sx, sy) in enumerate(obstacles):
        lab = "obstacle" if k == 0 else None
        if kind == "circle":
            ax.add_patch(plt.Circle((x, y), max(sx, sy) / 2.0, color="0.5", alpha=0.5, label=lab))
        else:
            ax.add_patch(plt.Rectangle((x - sx / 2.0, y - sy / 2.0), sx, sy, color="0.5", alpha=0.5, label=lab))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if obstacles:
        ax.set_aspect("equal", adjustable="datalim")
    finish(fig, "path", "Path in the plane: robot vs reference")

    # 2. posture tracking
    fig, axs = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    units = ("m", "m", "rad")
    if len(ref):
        t = np.array(ref.stamps)
        vals = (np.array([m.x for m in ref.msgs]), np.array([m.y for m in ref.msgs]),
                np.unwrap(np.array([m.theta for m in ref.msgs])))
        for a in range(3):
            axs[a].plot(t, vals[a], "k--", lw=1.5, label="reference")
    for i, d in enumerate(datas):
        odom = d.get("/odom")
        if not len(odom):
            continue
        t = np.array(odom.stamps)
        vals = (np.array([m.pose.pose.position.x for m in odom.msgs]),
                np.array([m.pose.pose.position.y for m in odom.msgs]),
                np.unwrap(np.array([_yaw(m.pose.pose.orientation) for m in odom.msgs])))
        for a in range(3):
            axs[a].plot(t, vals[a], label=d.label, **sty(i))
    for a, axis in enumerate(AXES):
        axs[a].set_ylabel("%s [%s]" % (axis, units[a]))
    axs[-1].set_xlabel("time [s]")
    finish(fig, "tracking", "Posture tracking: x, y, theta vs reference")

    # 3. errors
    fig, axs = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    for i, d in enumerate(datas):
        t, ex, ey, eth, _ = d.error_samples()
        for a, e in enumerate((ex, ey, eth)):
            axs[a].plot(t, e, label=d.label, **sty(i))
    for a, axis in enumerate(AXES):
        axs[a].axhline(0.0, color="k", lw=0.6)
        axs[a].set_ylabel("e_%s [%s]" % (axis, units[a]))
    axs[-1].set_xlabel("time [s]")
    finish(fig, "errors", "Tracking errors (reference minus actual, world frame)")

    # 4. velocities
    fig, axs = plt.subplots(2, 2, figsize=(13, 8), sharex=True)
    for i, d in enumerate(datas):
        c = colors[i % len(colors)]
        odom, des, st = d.get("/odom"), d.get("/desired_velocity"), d.get("/torque_controller/state")
        if len(des):
            t, v = arr(des, lambda m: m.v)
            axs[0, 0].plot(t, v, color=c, lw=4, alpha=0.3, label="desired v_d, %s" % d.label)
            t, w = arr(des, lambda m: m.omega)
            axs[1, 0].plot(t, w, color=c, lw=4, alpha=0.3, label="desired ω_d, %s" % d.label)
        if len(odom):
            t, v = arr(odom, lambda m: m.twist.twist.linear.x)
            axs[0, 0].plot(t, v, label="actual v, %s" % d.label, **sty(i))
            t, w = arr(odom, lambda m: m.twist.twist.angular.z)
            axs[1, 0].plot(t, w, label="actual ω, %s" % d.label, **sty(i))
        if len(st):
            t, ev = arr(st, lambda m: m.e_v)
            axs[0, 1].plot(t, ev, label=d.label, **sty(i))
            t, ew = arr(st, lambda m: m.e_omega)
            axs[1, 1].plot(t, ew, label=d.label, **sty(i))
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

    # 5. torques
    fig, axs = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for i, d in enumerate(datas):
        tq = d.get("/wheel_torque")
        if len(tq):
            t, r = arr(tq, lambda m: m.right)
            axs[0].plot(t, r, label=d.label, **sty(i, lw=1.0))
            t, l_ = arr(tq, lambda m: m.left)
            axs[1].plot(t, l_, label=d.label, **sty(i, lw=1.0))
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
            t, s1 = arr(st, lambda m: m.s_v)
            axs[0].plot(t, s1, label=d.label, **sty(i, lw=1.0))
            t, s2 = arr(st, lambda m: m.s_omega)
            axs[1].plot(t, s2, label=d.label, **sty(i, lw=1.0))
    axs[0].set_ylabel("S1 = s_v [m/s]")
    axs[1].set_ylabel("S2 = s_ω [rad/s]")
    for ax in axs:
        ax.axhline(0.0, color="k", lw=0.6)
    axs[-1].set_xlabel("time [s]")
    finish(fig, "sliding", "Sliding variables")

    # 7. adaptive estimates: left with the projection bounds, right zoomed on the estimates
    b = projection_bounds()
    fig, axs = plt.subplots(2, 2, figsize=(13, 7), sharex=True)
    rows = ((lambda m: m.m0_hat, "m0_min", "m0_max", "m0_hat [kg]", "mass estimate"),
            (lambda m: m.i0_hat, "i0_min", "i0_max", "I0_hat [kg·m²]", "inertia estimate"))
    for r, (fn, lo, hi, ylabel, title) in enumerate(rows):
        for i, d in enumerate(datas):
            st = d.get("/torque_controller/state")
            if len(st):
                t, v = arr(st, fn)
                for c in range(2):
                    axs[r, c].plot(t, v, label=d.label, **sty(i, lw=1.6))
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


