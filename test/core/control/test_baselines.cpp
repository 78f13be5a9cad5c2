// The baselines (pure pursuit, Regulated Pure Pursuit, wheel-velocity PID) and the outer/inner
// controller slots of runClosedLoop.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

/// The thesis line with the Fig 5.9 disturbance and 20 % mismatch, 1 kHz, 25 s, start (-1, 0, 0).
Scenario thesisDisturbed(const std::string& pair) {
  Scenario sc;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  const std::string e = parseControllerPair(pair, sc.outer, sc.inner, sc.sliding.adaptive);
  EXPECT_EQ(e, "");
  return sc;
}

struct Tracking {
  RunResult run;
  double worst_ex = 0, worst_ey = 0, worst_eth = 0;  ///< from 15 s to the end
};
Tracking track(const Scenario& sc) {
  LineReference ref;
  Tracking t;
  t.run = runClosedLoop(sc, ref, false, [&](const LoopSample& s) {
    if (s.t < 15.0) return;
    t.worst_ex = std::max(t.worst_ex, std::fabs(s.ex));
    t.worst_ey = std::max(t.worst_ey, std::fabs(s.ey));
    t.worst_eth = std::max(t.worst_eth, std::fabs(s.etheta));
  });
  return t;
}

/// A circle of radius r at speed v_r, counter-clockwise from the origin heading +x.
class CircleReference : public ReferenceSource {
 public:
  CircleReference(double r, double v_r) : r_(r), v_r_(v_r) {}
  std::unique_ptr<ReferenceSource> clone() const override { return std::make_unique<CircleReference>(*this); }

 protected:
  void restart() override {}
  Reference evaluate(double t) override {
    const double th = v_r_ * t / r_;
    Reference ref;
    ref.pose = {r_ * std::sin(th), r_ * (1.0 - std::cos(th)), wrapAngle(th)};
    ref.v = v_r_;
    ref.omega = v_r_ / r_;
    return ref;
  }

 private:
  double r_, v_r_;
};
}  // namespace

TEST(Baselines, PairNamesParseAndUnknownNamesAreNamed) {
  OuterKind o;
  InnerKind i;
  bool adaptive = true;
  EXPECT_EQ(parseControllerPair("rpp+pid", o, i, adaptive), "");
  EXPECT_EQ(o, OuterKind::rpp);
  EXPECT_EQ(i, InnerKind::pid);
  EXPECT_EQ(parseControllerPair("kanayama+tsmc", o, i, adaptive), "");
  EXPECT_EQ(o, OuterKind::kanayama);
  EXPECT_EQ(i, InnerKind::sliding_mode);
  EXPECT_FALSE(adaptive);
  EXPECT_NE(parseControllerPair("mpc+pid", o, i, adaptive).find("'mpc'"), std::string::npos);
  EXPECT_NE(parseControllerPair("rpp+lqr", o, i, adaptive).find("'lqr'"), std::string::npos);
  EXPECT_NE(parseControllerPair("rpp", o, i, adaptive), "");
  EXPECT_EQ(o, OuterKind::kanayama);  // a refused name leaves the choice as it was
  Scenario sc;
  EXPECT_EQ(sc.controllerName(), "kanayama+atsmc");
  sc.outer = OuterKind::pure_pursuit;
  sc.inner = InnerKind::pid;
  EXPECT_EQ(sc.controllerName(), "pure_pursuit+pid");
}

// Every baseline pair reaches the row and stays on it under the disturbance and 20 % mismatch. Pure
// pursuit with nav2's constant speed (k_along 0) keeps the along-track lag it started with (it tracks
// the path, not the time); k_along closes it.
TEST(Baselines, EachPairTracksTheThesisLineUnderDisturbanceAndMismatch) {
  for (const char* pair :
       {"kanayama+pid", "pure_pursuit+atsmc", "pure_pursuit+pid", "rpp+atsmc", "rpp+tsmc", "rpp+pid"}) {
    for (double k_along : {0.0, 1.0}) {
      Scenario sc = thesisDisturbed(pair);
      sc.pure_pursuit.k_along = k_along;
      const Tracking t = track(sc);
      SCOPED_TRACE(std::string(pair) + " k_along " + std::to_string(k_along));
      EXPECT_FALSE(t.run.diverged);
      EXPECT_EQ(t.run.periods, sc.steps());
      EXPECT_LT(std::fabs(t.run.final_state[Y] - 3.0), 0.02);
      EXPECT_LT(std::fabs(t.run.final_state[THETA]), 0.05);
      EXPECT_LT(t.worst_ey, 0.03);
      EXPECT_LT(t.worst_eth, 0.05);
      const bool lag_kept = sc.outer != OuterKind::kanayama && k_along == 0.0;
      EXPECT_LT(t.worst_ex, lag_kept ? 2.5 : 0.15);
      if (lag_kept) EXPECT_GT(t.worst_ex, 1.0);  // the along-track lag is real, and documented
    }
  }
}

TEST(Baselines, TheRunTimeInterfacesGiveTheTemplatedLoopsNumbers) {
  for (const char* pair : {"kanayama+atsmc", "rpp+pid", "pure_pursuit+tsmc"}) {
    const Scenario sc = thesisDisturbed(pair);
    LineReference ref;
    const RunResult fast = runClosedLoop(sc, ref, false);
    auto outer = makeOuterController(sc);
    auto inner = makeInnerController(sc, sc.robot);
    const RunResult generic = runClosedLoop(sc, ref, *outer, *inner, false);
    EXPECT_EQ(fast.final_state, generic.final_state) << pair;
    for (int k = 0; k < AXIS_COUNT; ++k) EXPECT_EQ(fast.metrics[k].itae, generic.metrics[k].itae) << pair;
  }
}

TEST(PurePursuit, CurvatureIsTwoYOverDSquaredAndOmegaIsVKappa) {
  PurePursuit pp({}, false);
  Reference ref;
  ref.pose = {0.0, 0.2, 0.0};
  ref.v = 1.0;
  const VelocityCommand c = pp.compute(ref, Pose2D{}, 1.0, 0.0);
  const double x = 0.6, y = 0.2;  // the carrot: 0.6 m ahead of the reference point
  EXPECT_DOUBLE_EQ(c.v, 1.0);
  EXPECT_DOUBLE_EQ(c.omega, 1.0 * 2.0 * y / (x * x + y * y));
}

TEST(PurePursuit, OnACircleTheCarrotGivesTheCircleCurvature) {
  PurePursuit pp({}, false);
  Reference ref;
  ref.v = 1.0;
  ref.omega = 1.0 / 1.5;  // radius 1.5 m
  const VelocityCommand c = pp.compute(ref, Pose2D{}, 1.0, 0.0);
  EXPECT_NEAR(c.omega, 1.0 / 1.5, 1e-12);
  EXPECT_NEAR(c.v, 1.0, 1e-12);
}

TEST(PurePursuit, RegulationSlowsOnHighCurvatureDownToTheMinimumSpeed) {
  PurePursuit pp({}, false), rpp({}, true);
  Reference ref;
  ref.v = 1.0;
  ref.omega = 1.0 / 0.5;  // radius 0.5 m < regulated_linear_scaling_min_radius 0.9 m
  EXPECT_NEAR(pp.compute(ref, Pose2D{}, 1.0, 2.0).v, 1.0, 1e-12);
  const VelocityCommand slow = rpp.compute(ref, Pose2D{}, 1.0, 2.0);
  EXPECT_NEAR(slow.v, 0.5 / 0.9, 1e-9);
  EXPECT_NEAR(slow.omega, slow.v / 0.5, 1e-9);
  ref.omega = 1.0 / 0.1;  // radius 0.1 m: 1 * 0.1 / 0.9 < 0.25, held at the minimum regulated speed
  EXPECT_NEAR(rpp.compute(ref, Pose2D{}, 1.0, 10.0).v, 0.25, 1e-12);
  ref.omega = 1.0 / 2.0;  // radius 2 m: no regulation
  EXPECT_NEAR(rpp.compute(ref, Pose2D{}, 1.0, 0.5).v, 1.0, 1e-12);
}

// The analytic desired accelerations are the time derivatives of the commands along the closed loop:
// integrated over 50 ms windows they give the commands' change. (Period by period they do not: they
// use the measured v, omega, which carry the inner loop's ripple, as Kanayama's do.) A circle of radius
// 0.7 m keeps RPP's regulation on all the time.
TEST(PurePursuit, DesiredAccelerationsIntegrateToTheCommandsChange) {
  for (bool regulated : {false, true}) {
    Scenario sc;
    sc.outer = regulated ? OuterKind::rpp : OuterKind::pure_pursuit;
    sc.start = {0.0, -0.3, 0.3};
    sc.duration = 6.0;
    sc.pure_pursuit.k_along = 1.0;
    CircleReference circle(0.7, 0.8);
    std::vector<VelocityCommand> cmds;
    runClosedLoop(sc, circle, false, [&](const LoopSample& s) { cmds.push_back(*s.desired); });
    ASSERT_EQ(cmds.size(), 6001u);
    const double dt = 1e-3;
    const std::size_t w = 50;
    double worst_v = 0, worst_w = 0, largest_dv = 0, largest_dw = 0;
    for (std::size_t k = 100; k + w < cmds.size(); k += w) {
      double int_v = 0, int_w = 0;
      for (std::size_t j = k; j < k + w; ++j) {  // trapezoid
        int_v += 0.5 * dt * (cmds[j].v_dot + cmds[j + 1].v_dot);
        int_w += 0.5 * dt * (cmds[j].omega_dot + cmds[j + 1].omega_dot);
      }
      const double dv = cmds[k + w].v - cmds[k].v, dw = cmds[k + w].omega - cmds[k].omega;
      worst_v = std::max(worst_v, std::fabs(dv - int_v));
      worst_w = std::max(worst_w, std::fabs(dw - int_w));
      largest_dv = std::max(largest_dv, std::fabs(dv));
      largest_dw = std::max(largest_dw, std::fabs(dw));
    }
    EXPECT_LT(worst_v, 0.05 * largest_dv) << regulated << " " << worst_v << " " << largest_dv;
    EXPECT_LT(worst_w, 0.05 * largest_dw) << regulated << " " << worst_w << " " << largest_dw;
    EXPECT_GT(largest_dv, 1e-2) << regulated;  // the commands do change: a zero derivative would fail
    EXPECT_GT(largest_dw, 1e-2) << regulated;
  }
}

TEST(PurePursuit, ParameterValidationNamesTheKey) {
  PurePursuitParams p;
  EXPECT_EQ(p.validate(), "");
  EXPECT_DOUBLE_EQ(p.lookahead_dist, 0.6);  // nav2's defaults
  EXPECT_DOUBLE_EQ(p.min_lookahead_dist, 0.3);
  EXPECT_DOUBLE_EQ(p.max_lookahead_dist, 0.9);
  EXPECT_DOUBLE_EQ(p.lookahead_time, 1.5);
  EXPECT_DOUBLE_EQ(p.min_radius, 0.9);
  EXPECT_DOUBLE_EQ(p.min_speed, 0.25);
  p.lookahead_dist = 1.2;
  EXPECT_NE(p.validate().find("lookahead_dist"), std::string::npos) << p.validate();
  EXPECT_THROW(PurePursuit(p, true), std::invalid_argument);
  p = PurePursuitParams{};
  p.min_lookahead_dist = 1.0;
  EXPECT_NE(p.validate().find("min_lookahead_dist"), std::string::npos) << p.validate();
  p = PurePursuitParams{};
  p.min_radius = kNaN;
  EXPECT_NE(p.validate().find("regulated_linear_scaling_min_radius"), std::string::npos) << p.validate();
  Scenario sc;
  sc.outer = OuterKind::rpp;
  sc.pure_pursuit.k_along = -1.0;
  EXPECT_NE(sc.validate().find("k_along"), std::string::npos) << sc.validate();
  EXPECT_TRUE(purePursuitTable().find("lookahead_dist")->info.tunable);
}

TEST(PurePursuit, VelocityScaledLookaheadIsClamped) {
  PurePursuitParams p;
  p.use_velocity_scaled_lookahead_dist = true;
  const PurePursuit pp(p, true);
  EXPECT_DOUBLE_EQ(pp.lookahead(0.4), 0.6);
  EXPECT_DOUBLE_EQ(pp.lookahead(0.1), 0.3);
  EXPECT_DOUBLE_EQ(pp.lookahead(-2.0), 0.9);
}

TEST(PurePursuit, NonFiniteInputGivesTheStopCommand) {
  const PurePursuit rpp({}, true);
  Reference good;
  good.pose = {1.0, 3.0, 0.0};
  good.v = 1.0;
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int field = 0; field < 12; ++field) {
      Reference ref = good;
      Pose2D pose{0.0, 0.0, 0.1};
      double v = 0.5, omega = 0.1;
      double* slots[] = {&ref.pose.x,    &ref.pose.y, &ref.pose.theta, &ref.v,      &ref.omega, &ref.v_dot,
                         &ref.omega_dot, &pose.x,     &pose.y,         &pose.theta, &v,         &omega};
      *slots[field] = bad;
      const VelocityCommand c = rpp.compute(ref, pose, v, omega);
      EXPECT_EQ(c.v, 0.0) << field;
      EXPECT_EQ(c.omega, 0.0) << field;
      EXPECT_EQ(c.v_dot, 0.0) << field;
      EXPECT_EQ(c.omega_dot, 0.0) << field;
    }
  }
}

// With the motor limit far below what the error asks for, the anti-windup keeps the integral term
// within the limit, so the torque reverses the moment the error does; without it the integral winds up
// and the torque stays at the wrong limit long after.
TEST(WheelPid, AntiWindupStopsTheIntegratorRunningAwayAtSaturation) {
  const RobotParams robot;
  for (bool anti_windup : {true, false}) {
    WheelPidParams p;
    p.max_torque = 1.0;
    p.anti_windup = anti_windup;
    WheelPid pid(p, robot);
    VelocityCommand far;
    far.v = 10.0;  // unreachable: the wheel stays still (measured 0)
    WheelPidOutput out;
    for (int k = 0; k < 5000; ++k) out = pid.update(far, 0.0, 0.0, 1e-3);
    EXPECT_TRUE(out.saturated);
    EXPECT_DOUBLE_EQ(out.torques.right, 1.0);
    VelocityCommand back;
    back.v = -0.5;  // the error changes sign
    out = pid.update(back, 0.0, 0.0, 1e-3);
    if (anti_windup) {
      EXPECT_LE(std::fabs(out.i_right), p.max_torque);
      EXPECT_LT(out.torques.right, 0.0);
    } else {
      EXPECT_GT(out.i_right, 100.0 * p.max_torque);  // wound up
      EXPECT_DOUBLE_EQ(out.torques.right, 1.0);      // still pushing the wrong way
    }
  }
}

// A layer after the PID (the traction control) holding its torque back is the PID's saturation too: the
// integral does not grow in the held direction while the layer holds it (heldBack), and does again after.
TEST(WheelPid, ATorqueHeldBackByALayerStopsTheIntegral) {
  const RobotParams robot;
  WheelPid pid(WheelPidParams{}, robot);
  VelocityCommand far;
  far.v = 1.0;  // the wheels stand: a steady positive error
  WheelPidOutput out = pid.update(far, 0.0, 0.0, 1e-3);
  const double first = out.i_right;
  ASSERT_GT(first, 0.0);
  for (int k = 0; k < 100; ++k) {
    pid.heldBack({0.5 * out.torques.right, out.torques.left});  // right held below its output, left not
    out = pid.update(far, 0.0, 0.0, 1e-3);
  }
  EXPECT_EQ(out.i_right, first);        // held: no integration upwards
  EXPECT_GT(out.i_left, 50.0 * first);  // the left wheel integrated on
  // An error the other way still integrates (it pulls out of the held torque).
  pid.heldBack({0.5 * out.torques.right, out.torques.left});
  VelocityCommand back;
  back.v = -1.0;
  out = pid.update(back, 0.0, 0.0, 1e-3);
  EXPECT_LT(out.i_right, first);
  // Not held any more: integrates again.
  out = pid.update(far, 0.0, 0.0, 1e-3);
  const double again = out.i_right;
  out = pid.update(far, 0.0, 0.0, 1e-3);
  EXPECT_GT(out.i_right, again);
}

TEST(WheelPid, FeedforwardIsTheNominalInertiaAndTheSpeedsComeFromRAndL) {
  const RobotParams robot;
  WheelPidParams p;
  p.kp = p.ki = 0.0;
  WheelPid pid(p, robot);
  VelocityCommand d;
  d.v_dot = 0.5;
  d.omega_dot = 0.2;
  const WheelPidOutput out = pid.update(d, 0.0, 0.0, 1e-3);
  const double sum = robot.m0() * robot.R * 0.5, diff = robot.I0() * robot.R / robot.L * 0.2;
  EXPECT_NEAR(out.torques.right, 0.5 * (sum + diff), 1e-12);
  EXPECT_NEAR(out.torques.left, 0.5 * (sum - diff), 1e-12);
  d = VelocityCommand{};
  d.v = 1.0;
  d.omega = 0.5;
  const WheelPidOutput e = pid.update(d, 0.2, 0.1, 1e-3);
  EXPECT_NEAR(e.e_right, (0.8 + robot.L * 0.4) / robot.R, 1e-12);
  EXPECT_NEAR(e.e_left, (0.8 - robot.L * 0.4) / robot.R, 1e-12);
}

TEST(WheelPid, ParameterValidationNamesTheKey) {
  WheelPidParams p;
  EXPECT_EQ(p.validate(), "");
  p.kp = -1.0;
  EXPECT_NE(p.validate().find("kp"), std::string::npos) << p.validate();
  EXPECT_THROW(WheelPid(p, RobotParams{}), std::invalid_argument);
  p = WheelPidParams{};
  p.max_torque = kInf;
  EXPECT_NE(p.validate().find("max_torque"), std::string::npos) << p.validate();
  Scenario sc;
  sc.inner = InnerKind::pid;
  sc.pid.feedforward = 3.0;
  EXPECT_NE(sc.validate().find("feedforward"), std::string::npos) << sc.validate();
  EXPECT_TRUE(wheelPidTable().find("ki")->info.tunable);
}

// A bad input is refused and leaves no trace: the next good input gives what a twin that never saw it
// gives.
TEST(WheelPid, NonFiniteInputIsRefusedAndLeavesTheStateAlone) {
  const RobotParams robot;
  VelocityCommand good;
  good.v = 0.8;
  good.omega = 0.3;
  good.v_dot = 0.1;
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int field = 0; field < 7; ++field) {
      WheelPid pid(WheelPidParams{}, robot), twin(WheelPidParams{}, robot);
      const WheelPidOutput first = pid.update(good, 0.1, 0.0, 1e-3);
      twin.update(good, 0.1, 0.0, 1e-3);
      VelocityCommand d = good;
      double v = 0.2, omega = 0.05, dt = 1e-3;
      double* slots[] = {&d.v, &d.omega, &d.v_dot, &d.omega_dot, &v, &omega, &dt};
      *slots[field] = bad;
      const WheelPidOutput held = pid.update(d, v, omega, dt);
      EXPECT_TRUE(held.rejected) << field;
      EXPECT_EQ(held.torques.right, first.torques.right) << field;
      EXPECT_EQ(held.torques.left, first.torques.left) << field;
      const WheelPidOutput a = pid.update(good, 0.3, 0.1, 1e-3), b = twin.update(good, 0.3, 0.1, 1e-3);
      EXPECT_FALSE(a.rejected);
      EXPECT_EQ(a.torques.right, b.torques.right) << field;
      EXPECT_EQ(a.torques.left, b.torques.left) << field;
    }
  }
  WheelPid pid(WheelPidParams{}, robot);
  EXPECT_TRUE(pid.update(good, 0.0, 0.0, 0.0).rejected);  // dt must be positive
  EXPECT_TRUE(pid.update(good, 0.0, 0.0, -1e-3).rejected);
}
