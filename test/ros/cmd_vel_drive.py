#!/usr/bin/env python3
"""Velocity mode (sim.launch input:=cmd_vel) in lockstep, for the rostests and the tracking figures of
results/cmd_vel.md: a schedule of stamped twists, the driver that publishes it on cmd_vel_stamped and
records what the loop did, and the figures of a step.

As a module: SCHEDULES, bad_twists(), Driver (publish + record, inside a rospy node), reach_time(),
step_figures(). As a node (cmd_vel_nan_test.py starts it in each of its runs): publishes the schedule
`~scenario`, with the bad twists when `~inject_bad` is true, and writes the recorded trace to `~output`
(one line per message, every number as repr(): two runs compare as text), then exits.
`cmd_vel_drive.py --figures TRACE` prints the step's figures of a "step" trace (cmd_vel_timeout 0.5 s).
"""
import math
import sys
import time

import rospy
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from sowing_robot.msg import DesiredVelocity

WALL_LIMIT = 240.0  # [s wall] for a whole run of a few simulated seconds
PERIOD = 1e-3       # [s] the control period (run/control_rate 1 kHz)


def teleop(t0, t1, v, omega, rate=10.0):
    """A teleop at `rate` Hz (simulated time): the twist (v, omega) stamped t0, t0 + 1/rate, ... < t1."""
    n = int(round((t1 - t0) * rate))
    return [(t0 + i / rate, v, omega) for i in range(n)]


# (stamp [s], v [m/s], omega [rad/s]) in stamp order; the last stamp is the run's end (duration): lockstep
# answers the state at t once a twist stamped t or later has come, so the final one lets the run finish.
# The first is stamped one control period in: a stamp of 0 reads as "unstamped" and lockstep drops it.
SCHEDULES = {
    # at rest, then 0.3 m/s and 0.2 rad/s at 10 Hz from 0.5 s to 4 s (the last twist stamped 3.9 s): stale
    # at 4.4 s (cmd_vel_timeout 0.5 s), when the limiter ramps to a stop.
    "step": [(PERIOD, 0.0, 0.0)] + teleop(0.5, 4.0, 0.3, 0.2) + [(8.0, 0.0, 0.0)],
    # astern at -0.3 m/s, -0.2 rad/s, then straight to +0.3, +0.2 (through zero), then stop.
    "reverse": ([(PERIOD, 0.0, 0.0)] + teleop(0.5, 3.0, -0.3, -0.2) + teleop(3.0, 6.0, 0.3, 0.2) +
                teleop(6.0, 8.0, 0.0, 0.0) + [(8.0, 0.0, 0.0)]),
}
STEP_AT = 0.5        # [s] when the step starts, in both schedules
FLIP_AT = 3.0        # [s] reverse: astern -> ahead
LAST_TELEOP = 3.9    # [s] step: the last twist of the teleop
STEP = (0.3, 0.2)    # [m/s], [rad/s]
BAND = 0.05          # settled: within 5 % of the step (the ATSMC leaves ~2 % on omega, docs/cmd_vel.md)


def bad_twists():
    """Twists the limiter must drop, each stamped between good ones: non-finite v, omega or an unused
    component, beyond the limits (1 m/s, 1 rad/s), and one after the last good twist of "step" (which
    must not keep that command fresh)."""
    nan, inf = float("nan"), float("inf")
    out = []
    for stamp, v, omega, y in ((0.25, nan, 0.0, 0.0), (0.55, 0.3, inf, 0.0), (1.05, 0.1, 0.1, nan),
                               (2.05, 1.5, 0.0, 0.0), (2.55, 0.0, -3.0, 0.0), (4.2, nan, nan, 0.0),
                               (4.6, -inf, 0.0, 0.0)):
        m = TwistStamped()
        m.header.stamp = rospy.Time.from_sec(stamp)
        m.twist.linear.x, m.twist.angular.z, m.twist.linear.y = v, omega, y
        out.append(m)
    return out


def stamped(stamp, v, omega):
    m = TwistStamped()
    m.header.stamp = rospy.Time.from_sec(stamp)
    m.twist.linear.x, m.twist.angular.z = v, omega
    return m


class Driver:
    """Publishes a schedule on cmd_vel_stamped and records ground_truth and desired_velocity up to its end."""

    def __init__(self):
        self.truth, self.desired = [], []
        self.subs = [rospy.Subscriber("ground_truth", Odometry, self.on_truth, queue_size=20000, tcp_nodelay=True),
                     rospy.Subscriber("desired_velocity", DesiredVelocity, self.on_desired, queue_size=20000,
                                      tcp_nodelay=True)]
        self.pub = rospy.Publisher("cmd_vel_stamped", TwistStamped, queue_size=1000)
        self.plain = rospy.Publisher("cmd_vel", Twist, queue_size=10)

    def on_truth(self, m):
        q = m.pose.pose.orientation
        self.truth.append((m.header.stamp.to_sec(), m.pose.pose.position.x, m.pose.pose.position.y, q.z, q.w,
                           m.twist.twist.linear.x, m.twist.twist.angular.z))

    def on_desired(self, m):
        self.desired.append((m.header.stamp.to_sec(), m.v, m.omega, m.v_dot, m.omega_dot))

    def wait(self, condition, what):
        deadline = time.time() + WALL_LIMIT
        while not condition():
            if rospy.is_shutdown() or time.time() > deadline:
                raise RuntimeError("cmd_vel_drive: no %s after %.0f s wall" % (what, WALL_LIMIT))
            time.sleep(0.01)

    def drive(self, schedule, extra=()):
        """Publishes the schedule (and `extra` TwistStamped, merged by stamp; plain Twists go to cmd_vel,
        which lockstep ignores) once the loop listens, then records up to the schedule's last stamp."""
        self.wait(lambda: self.pub.get_num_connections() > 0 and
                  all(s.get_num_connections() > 0 for s in self.subs), "connection to cmd_vel_limiter and plant_sim")
        msgs = sorted([stamped(*s) for s in schedule] + list(extra), key=lambda m: m.header.stamp)
        for m in msgs:
            self.pub.publish(m)
        end = schedule[-1][0]
        self.wait(lambda: self.truth and self.truth[-1][0] >= end - 1e-9 and self.desired and
                  self.desired[-1][0] >= end - 1e-9, "state at t = %.3f s" % end)
        for s in self.subs:
            s.unregister()
        return self.truth, self.desired


def reach_time(dv, a_max, j_max):
    """The limiter's time from rest (or from one rest to another) across a change dv at full jerk and
    acceleration: an acceleration trapezoid when the peak reaches a_max, a triangle otherwise."""
    dv = abs(dv)
    return dv / a_max + a_max / j_max if dv >= a_max * a_max / j_max else 2.0 * math.sqrt(dv / j_max)


def first_from(samples, t0, t1, ok):
    """The first stamp in [t0, t1] from which ok(sample) holds up to t1 (None if it never settles)."""
    found = None
    for s in samples:
        if s[0] < t0 - 1e-9 or s[0] > t1 + 1e-9:
            continue
        if ok(s):
            found = s[0] if found is None else found
        else:
            found = None
    return found


def crossing(samples, t0, col, level):
    """First stamp at or after t0 where samples[col] reaches `level` (rising or falling towards it)."""
    start = next(s[col] for s in samples if s[0] >= t0 - 1e-9)
    for s in samples:
        if s[0] >= t0 - 1e-9 and (s[col] - level) * (start - level) <= 0.0:
            return s[0]
    return None


def step_figures(truth, desired, t_step, t_end, target, col_truth, col_desired, band):
    """Tracking figures of a step from rest to `target` at t_step, up to t_end: the limiter's (desired)
    and the robot's (truth) 10-90 % rise time and settling time (within band x the step), the robot's
    overshoot beyond the target [% of the step] and its steady error (mean and max |error| over the last
    second)."""
    tol = band * abs(target)
    f = {}
    for name, samples, col in (("limiter", desired, col_desired), ("robot", truth, col_truth)):
        t10 = crossing(samples, t_step, col, 0.1 * target)
        t90 = crossing(samples, t_step, col, 0.9 * target)
        f[name + "_rise"] = t90 - t10 if t10 is not None and t90 is not None else float("nan")
        settled = first_from(samples, t_step, t_end, lambda s: abs(s[col] - target) <= tol)
        f[name + "_settle"] = settled - t_step if settled is not None else float("nan")
    window = [s[col_truth] for s in truth if t_step - 1e-9 <= s[0] <= t_end + 1e-9]
    peak = max(window) if target > 0 else min(window)
    f["overshoot_pct"] = max(0.0, (peak - target) / target * 100.0)
    tail = [abs(s[col_truth] - target) for s in truth if t_end - 1.0 - 1e-9 <= s[0] <= t_end + 1e-9]
    f["steady_mean"] = sum(tail) / len(tail)
    f["steady_max"] = max(tail)
    return f


def read_trace(path):
    """(truth, desired) rows of a trace the node wrote."""
    truth, desired = [], []
    with open(path) as f:
        for line in f:
            kind, *numbers = line.split()
            (truth if kind == "truth" else desired).append(tuple(float(x) for x in numbers))
    return truth, desired


def step_report(truth, desired, timeout):
    """One line per axis of the "step" schedule: the figures of the step, up to the moment the command goes
    stale, and of the stop after it (settled: within BAND of the step)."""
    stale_at, end = LAST_TELEOP + timeout, SCHEDULES["step"][-1][0]
    lines = []
    for name, target, col_t, col_d in (("v", STEP[0], 5, 1), ("omega", STEP[1], 6, 2)):
        f = step_figures(truth, desired, STEP_AT, stale_at, target, col_t, col_d, BAND)
        tol = BAND * target
        lim_stop = first_from(desired, stale_at, end, lambda d: abs(d[col_d]) <= 1e-9)
        robot_stop = first_from(truth, stale_at, end, lambda s: abs(s[col_t]) <= tol)
        rest = [abs(s[col_t]) for s in truth if end - 1.0 <= s[0] <= end]
        lines.append(
            "%s step 0 -> %g: rise 10-90%% limiter %.3f s, robot %.3f s; settling %g%% limiter %.3f s, robot %.3f s; "
            "overshoot %.2f %%; steady |error| mean %.2e, max %.2e; stop (stale at %.1f s): limiter at 0 after "
            "%.3f s, robot within %g%% after %s; at rest |%s| max %.2e" %
            (name, target, f["limiter_rise"], f["robot_rise"], BAND * 100, f["limiter_settle"], f["robot_settle"],
             f["overshoot_pct"], f["steady_mean"], f["steady_max"], stale_at,
             lim_stop - stale_at if lim_stop is not None else float("nan"), BAND * 100,
             "%.3f s" % (robot_stop - stale_at) if robot_stop is not None else "never", name, max(rest)))
    return lines


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--figures":  # the figures of a trace written before
        truth, desired = read_trace(sys.argv[2])
        print("\n".join(step_report(truth, desired, 0.5)))
        return
    rospy.init_node("cmd_vel_drive")
    scenario = rospy.get_param("~scenario", "step")
    inject = rospy.get_param("~inject_bad", False)
    output = rospy.get_param("~output")
    driver = Driver()
    extra = bad_twists() if inject else []
    if inject:  # lockstep has no use for a plain Twist: ignored, with a warning
        driver.wait(lambda: driver.plain.get_num_connections() > 0, "connection on cmd_vel")
        driver.plain.publish(Twist())
    truth, desired = driver.drive(SCHEDULES[scenario], extra)
    with open(output, "w") as f:
        for row in truth:
            f.write("truth " + " ".join(repr(x) for x in row) + "\n")
        for row in desired:
            f.write("desired " + " ".join(repr(x) for x in row) + "\n")


if __name__ == "__main__":
    main()
