#!/usr/bin/env python3
"""rostest of velocity mode (sim.launch input:=cmd_vel, lockstep): a teleop-like schedule of stamped twists
(cmd_vel_drive.py) drives the robot through cmd_vel_limiter and the ATSMC inner loop.

~scenario step: from rest to 0.3 m/s and 0.2 rad/s at 0.5 s; the limiter's output reaches the command at
  the time its limits give (computed here from the limits in the parameter server), the robot within 2 % of
  it by then plus ~robot_slack; the command goes stale 0.5 s after the last twist (cmd_vel_timeout), and the
  output ramps to zero in the limiter's time, the robot after it.
~scenario reverse: astern (-0.3, -0.2), then straight to ahead (+0.3, +0.2) through zero: the same checks
  both ways, and the robot passes -0.3 / -0.2 by at most its steady offset + OVERSHOOT_ALLOWANCE.
Both: every bound (value, acceleration, jerk) holds throughout, in both directions, and the accelerations
handed to the inner loop are the derivatives of the velocities.

The tracking figures (rise, settling, overshoot, steady error) are printed on one line each, for
results/cmd_vel.md. Verified to fail with the feature broken: see docs/cmd_vel.md, "Tests".
"""
import unittest

import rospy
import rostest

import cmd_vel_drive as drive

TOL = 1e-9  # [unit] rounding allowance on the limiter's exact bounds
# [% of the step] how far the robot may pass its target beyond its own steady offset (reverse scenario). The
# limiter's profile never passes the target (docs/cmd_vel.md), so what the robot shows beyond it is its
# steady offset (the ATSMC's: ~0.3 % on v, ~2.1 % on omega, the steady error's max) plus its transient.
# Lockstep repeats the run bit for bit: measured 0.32 % / 2.14 % with offsets 0.32 % / 2.14 %, a transient
# of < 0.01 %. 1 % leaves room for another controller tuning while a robot that swings past the command (a
# limiter that overshoots, a jerk or acceleration bound lost, a loop gone oscillatory) exceeds it.
OVERSHOOT_ALLOWANCE = 1.0


class CmdVelStep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("cmd_vel_test")
        cls.scenario = rospy.get_param("~scenario")
        cls.slack = rospy.get_param("~robot_slack")      # [s] the robot behind the limiter's output
        cls.band = rospy.get_param("~robot_band", drive.BAND)  # the robot's settling band, fraction of the step
        p = lambda key: rospy.get_param("/cmd_vel_limiter/" + key)
        cls.timeout = p("cmd_vel_timeout")
        cls.limits = {"v": (p("linear/max_velocity"), p("linear/max_acceleration"), p("linear/max_jerk")),
                      "omega": (p("angular/max_velocity"), p("angular/max_acceleration"), p("angular/max_jerk"))}
        cls.truth, cls.desired = drive.Driver().drive(drive.SCHEDULES[cls.scenario])

    # columns: truth (t, x, y, qz, qw, v, omega); desired (t, v, omega, v_dot, omega_dot)
    AXES = {"v": (5, 1, 3), "omega": (6, 2, 4)}

    def reach(self, axis, dv):
        _, a_max, j_max = self.limits[axis]
        return drive.reach_time(dv, a_max, j_max)

    def desired_at(self, t):
        return min(self.desired, key=lambda d: abs(d[0] - t))

    def expect_change(self, axis, t0, start, target):
        """The limiter's output for `axis` leaves `start` right after t0, is at `target` (exactly, to
        rounding) from t0 + the limiter's time (to the period), and the robot within the band of the step
        by then plus the slack; the figures printed."""
        _, col_d, _ = self.AXES[axis]
        col_t = self.AXES[axis][0]
        t_reach = self.reach(axis, target - start)
        t_end = t0 + t_reach + 1.0
        reached = drive.first_from(self.desired, t0, t_end, lambda d: abs(d[col_d] - target) <= TOL)
        self.assertIsNotNone(reached, "%s: the limiter never reached %g" % (axis, target))
        self.assertAlmostEqual(reached - t0, t_reach, delta=drive.PERIOD + 1e-6,
                               msg="%s: limiter at %g after %.4f s, its limits give %.4f s" %
                               (axis, target, reached - t0, t_reach))
        self.assertNotEqual(self.desired_at(t0 + 0.01)[col_d], start, "%s: no change after the step" % axis)
        tol = self.band * abs(target - start)
        robot = drive.first_from(self.truth, t0, t_end, lambda s: abs(s[col_t] - target) <= tol)
        self.assertIsNotNone(robot, "%s: the robot never settled within %g of %g" % (axis, tol, target))
        self.assertLessEqual(robot - t0, t_reach + self.slack,
                             "%s: the robot within %g of %g only %.3f s after the step (limiter %.3f s + slack "
                             "%.3f s)" % (axis, tol, target, robot - t0, t_reach, self.slack))
        return t_reach, robot - t0

    def test_limits_hold_throughout(self):
        for axis, (_, col_d, col_a) in self.AXES.items():
            v_max, a_max, j_max = self.limits[axis]
            prev = None
            for d in self.desired:
                self.assertLessEqual(abs(d[col_d]), v_max + TOL, "%s at t = %.3f" % (axis, d[0]))
                self.assertLessEqual(abs(d[col_a]), a_max + TOL, "%s acceleration at t = %.3f" % (axis, d[0]))
                if prev is not None:
                    dt = d[0] - prev[0]
                    self.assertLessEqual(abs(d[col_a] - prev[col_a]), j_max * dt + TOL,
                                         "%s jerk at t = %.3f" % (axis, d[0]))
                    # the accelerations handed out are those of the velocities: the change over a period is
                    # their integral (trapezoid rule, off by at most J dt^2 / 4 at a kink of the jerk)
                    self.assertAlmostEqual(d[col_d] - prev[col_d], 0.5 * (d[col_a] + prev[col_a]) * dt,
                                           delta=j_max * dt * dt / 4 + TOL,
                                           msg="%s: acceleration not that of the velocity at t = %.3f" % (axis, d[0]))
                prev = d
        # one answer per state, none missing
        stamps = [d[0] for d in self.desired]
        self.assertEqual(len(stamps), len(set(stamps)))
        self.assertAlmostEqual(stamps[-1] - stamps[0], (len(stamps) - 1) * drive.PERIOD, delta=1e-6)

    def test_step_and_stop(self):
        if self.scenario != "step":
            self.skipTest("step scenario only")
        print("\n".join("cmd_vel " + line for line in drive.step_report(self.truth, self.desired, self.timeout)))
        t_step, stale_at = drive.STEP_AT, drive.LAST_TELEOP + self.timeout
        for axis, target in zip(("v", "omega"), drive.STEP):
            col_t, col_d, _ = self.AXES[axis]
            t_reach, _ = self.expect_change(axis, t_step, 0.0, target)
            # No stop before the timeout: the output holds the command up to the instant it goes stale ...
            held = [d for d in self.desired if t_step + t_reach + 0.01 <= d[0] <= stale_at]
            self.assertTrue(held and all(d[col_d] == held[0][col_d] for d in held),
                            "%s: the output moved before the command went stale (%.3f s)" % (axis, stale_at))
            # ... then ramps to zero in the limiter's time from the command, and the robot follows.
            t_stop = self.reach(axis, target)
            stopped = drive.first_from(self.desired, stale_at, drive.SCHEDULES["step"][-1][0],
                                       lambda d: abs(d[col_d]) <= TOL)
            self.assertIsNotNone(stopped, "%s: no stop after the timeout" % axis)
            self.assertAlmostEqual(stopped - stale_at, t_stop, delta=drive.PERIOD + 1e-6,
                                   msg="%s stopped %.4f s after going stale, limits give %.4f s" %
                                   (axis, stopped - stale_at, t_stop))
            tol = self.band * target
            robot_stop = drive.first_from(self.truth, stale_at, drive.SCHEDULES["step"][-1][0],
                                          lambda s: abs(s[col_t]) <= tol)
            self.assertIsNotNone(robot_stop, "%s: the robot never stopped" % axis)
            self.assertLessEqual(robot_stop - stale_at, t_stop + self.slack)

    def test_reverse(self):
        if self.scenario != "reverse":
            self.skipTest("reverse scenario only")
        for axis, target in zip(("v", "omega"), drive.STEP):
            col_t, col_d, _ = self.AXES[axis]
            back = self.expect_change(axis, drive.STEP_AT, 0.0, -target)
            f = drive.step_figures(self.truth, self.desired, drive.STEP_AT, drive.FLIP_AT, -target, col_t, col_d,
                                   self.band)
            print("cmd_vel reverse %s %g: limiter reach %.3f s, robot settled %.3f s, overshoot %.2f %%, steady "
                  "error mean %.2e max %.2e" % (axis, -target, back[0], back[1], f["overshoot_pct"], f["steady_mean"],
                                                f["steady_max"]))
            offset_pct = f["steady_max"] / abs(target) * 100.0
            self.assertLessEqual(f["overshoot_pct"], offset_pct + OVERSHOOT_ALLOWANCE,
                                 "%s: the robot passed %g by %.2f %% of the step, %.2f %% beyond its steady offset" %
                                 (axis, -target, f["overshoot_pct"], f["overshoot_pct"] - offset_pct))
            # and never out of the settling band, whatever its offset
            self.assertLess(f["overshoot_pct"], self.band * 100.0, "%s: overshoot beyond the settling band" % axis)
            flip = self.expect_change(axis, drive.FLIP_AT, -target, target)
            print("cmd_vel flip %s %g -> %g: limiter reach %.3f s, robot settled %.3f s" %
                  (axis, -target, target, flip[0], flip[1]))


if __name__ == "__main__":
    rostest.rosrun("sowing_robot", "cmd_vel_test", CmdVelStep)
