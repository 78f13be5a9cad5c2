// Plant model: closed-form straight run, turning in place, mirror symmetries, energy balance of the
// centre-of-mass coupling (which checks the sign choice between eqs 3.53 and 3.54), RK4 order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "sowing_robot/core/model/plant.h"

using namespace sowing_robot::core;

namespace {
constexpr double kDt = 1e-3;

State runOpenLoop(const RobotParams& p, const PlantDisturbance& d, double tr, double tl, double seconds,
                  double dt = kDt) {
  Plant plant(p, d);
  plant.reset(State::Zero());
  const int n = static_cast<int>(std::llround(seconds / dt));
  for (int i = 0; i < n; ++i) plant.step(tr, tl, dt);
  return plant.state();
}
}  // namespace

TEST(Plant, DerivedParametersMatchTable51) {
  RobotParams p;
  EXPECT_DOUBLE_EQ(p.m(), 18.0);
  EXPECT_NEAR(p.I(), 2 * 0.5 * 0.0576 + 17 * 0.0025 + 2 * 0.0011 + 0.537, 1e-15);
  EXPECT_NEAR(p.m0(), 18.0 + 2 * 0.0023 / (0.095 * 0.095), 1e-12);
  EXPECT_NEAR(p.I0(), p.I() + 2 * 0.0576 * 0.0023 / (0.095 * 0.095), 1e-12);
  EXPECT_TRUE(p.validate().empty());
}

TEST(Plant, StraightRunMatchesClosedForm) {
  RobotParams p;
  const double tau = 0.78, a = 2 * tau / (p.R * p.m0());  // eq 3.54 with omega = 0
  Plant plant(p, {});
  plant.reset(State::Zero());
  for (int i = 1; i <= 10000; ++i) {
    plant.step(tau, tau, kDt);
    const double t = i * kDt;
    const State& s = plant.state();
    ASSERT_NEAR(s[Y], 0.0, 1e-12);
    ASSERT_NEAR(s[THETA], 0.0, 1e-12);
    ASSERT_NEAR(s[OMEGA], 0.0, 1e-12);
    ASSERT_NEAR(s[V], a * t, 1e-6 * a * t);
    ASSERT_NEAR(s[X], 0.5 * a * t * t, 1e-6 * 0.5 * a * t * t);
    ASSERT_NEAR(s[PHI_R], s[X] / p.R, 1e-9);
  }
  // The thesis reports ~72 m in 10 s; its own equations with Table 5.1 give 0.5 a t^2:
  EXPECT_NEAR(plant.state()[X], 44.36, 0.01);
}

TEST(Plant, EqualAndOppositeTorquesTurnInPlaceWithoutOffset) {
  RobotParams p;
  p.d = 0.0;
  const State s = runOpenLoop(p, {}, 0.3, -0.3, 5.0);
  EXPECT_NEAR(s[X], 0.0, 1e-12);
  EXPECT_NEAR(s[Y], 0.0, 1e-12);
  EXPECT_GT(s[THETA], 1.0);
  EXPECT_NEAR(s[PHI_R], -s[PHI_L], 1e-9);
}

TEST(Plant, CentreOfMassOffsetPushesASpinningRobotForward) {
  // eq 3.54: m0 v' = mc d w^2 + u1/R. With u1 = 0 a spin accelerates the axle forward when d > 0.
  RobotParams p;
  const State s = runOpenLoop(p, {}, 0.3, -0.3, 2.0);
  EXPECT_GT(s[V], 0.0);
  p.d = -0.05;
  EXPECT_LT(runOpenLoop(p, {}, 0.3, -0.3, 2.0)[V], 0.0);
}

TEST(Plant, ReversedTorquesMirrorTheStraightPath) {
  RobotParams p;
  const State f = runOpenLoop(p, {}, 0.78, 0.78, 10.0), b = runOpenLoop(p, {}, -0.78, -0.78, 10.0);
  EXPECT_NEAR(b[X], -f[X], 1e-9);
  EXPECT_NEAR(b[V], -f[V], 1e-12);
  EXPECT_NEAR(b[Y], 0.0, 1e-12);
}

TEST(Plant, SwappingWheelsMirrorsTheTurn) {
  RobotParams p;
  const State l = runOpenLoop(p, {}, 0.9, 0.5, 6.0), r = runOpenLoop(p, {}, 0.5, 0.9, 6.0);
  EXPECT_NEAR(r[X], l[X], 1e-9);
  EXPECT_NEAR(r[Y], -l[Y], 1e-9);
  EXPECT_NEAR(r[THETA], -l[THETA], 1e-12);
  EXPECT_GT(l[THETA], 0.1);  // more torque on the right wheel turns left (counter-clockwise)
}

TEST(Plant, KineticEnergyIsConservedWithoutTorque) {
  // The Coriolis terms of eq 3.54 do no work: v (mc d w^2) - w (mc d w v) = 0. With eq 3.53's sign they
  // would inject energy, so this fails if the coupling sign is wrong.
  RobotParams p;
  Plant plant(p, {});
  State x0 = State::Zero();
  x0[V] = 1.0;
  x0[OMEGA] = 2.0;
  plant.reset(x0);
  auto energy = [&](const State& s) { return 0.5 * p.m0() * s[V] * s[V] + 0.5 * p.I0() * s[OMEGA] * s[OMEGA]; };
  const double e0 = energy(plant.state());
  for (int i = 0; i < 5000; ++i) plant.step(0.0, 0.0, kDt);
  EXPECT_NEAR(energy(plant.state()), e0, 1e-9 * e0);
  EXPECT_NE(plant.state()[V], 1.0);  // energy moved between the channels
}

TEST(Plant, Rk4ConvergesAtFourthOrder) {
  RobotParams p;
  PlantDisturbance d;
  d.sinusoidal = true;
  auto run = [&](double dt) { return runOpenLoop(p, d, 1.5, 0.2, 2.0, dt); };
  const State ref = run(1e-4);
  const double e1 = (run(0.02) - ref).norm(), e2 = (run(0.01) - ref).norm();
  const double order = std::log2(e1 / e2);
  EXPECT_GT(order, 3.7);
  EXPECT_LT(order, 4.3);
}

// step() shares the disturbance between RK4 stages and turns one sincos of the heading by each stage's
// increment; it must agree with the textbook RK4 of derivative() (std::sin/cos per stage) to rounding,
// both on the small-increment series (1 kHz) and on the library fallback (large steps, fast turn).
TEST(Plant, StepMatchesTextbookRk4OfDerivative) {
  PlantDisturbance d;
  d.sinusoidal = true;
  RobotParams p;
  for (const double dt : {1e-3, 0.05}) {
    Plant plant(p, d), reference(p, d);
    State x = State::Zero();
    plant.reset(x);
    const double tr = 3.0, tl = -1.0;  // turning: heading increments are not zero
    const int n = static_cast<int>(std::llround(4.0 / dt));
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      auto f = [&](const State& s, double ts) {
        double dr, dl;
        reference.sinusoidalDisturbance(ts, dr, dl);
        return reference.derivative(s, tr + dr, tl + dl);
      };
      const State k1 = f(x, t), k2 = f(x + 0.5 * dt * k1, t + 0.5 * dt), k3 = f(x + 0.5 * dt * k2, t + 0.5 * dt),
                  k4 = f(x + dt * k3, t + dt);
      x += (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      plant.step(tr, tl, dt);
    }
    EXPECT_GT(std::fabs(x[THETA]), 1.0) << "dt " << dt;  // the robot really turned
    for (int i = 0; i < STATE_SIZE; ++i)
      EXPECT_NEAR(plant.state()[i], x[i], 1e-11 * (1.0 + std::fabs(x[i]))) << "dt " << dt << " index " << i;
  }
}

TEST(Plant, SinusoidalDisturbanceMatchesFigure59) {
  PlantDisturbance d;
  d.sinusoidal = true;
  Plant plant(RobotParams{}, d);
  double r, l;
  plant.sinusoidalDisturbance(0.5, r, l);
  EXPECT_DOUBLE_EQ(r, 2.75 * std::sin(1.5));
  EXPECT_DOUBLE_EQ(l, 2.75 * std::cos(1.5));
  d.sinusoidal = false;
  Plant off(RobotParams{}, d);
  off.sinusoidalDisturbance(0.5, r, l);
  EXPECT_EQ(r, 0.0);
  EXPECT_EQ(l, 0.0);
}

TEST(Plant, MismatchScalesTheTrueInertias) {
  PlantDisturbance d;
  d.mass_scale = 1.2;
  d.inertia_scale = 1.5;
  RobotParams p;
  Plant plant(p, d);
  EXPECT_DOUBLE_EQ(plant.trueM0(), 1.2 * p.m0());
  EXPECT_DOUBLE_EQ(plant.trueI0(), 1.5 * p.I0());
  const State s = runOpenLoop(p, d, 0.78, 0.78, 1.0);
  EXPECT_NEAR(s[V], 2 * 0.78 / (p.R * 1.2 * p.m0()), 1e-9);
}

TEST(Plant, NoiseIsSeededAndRepeatable) {
  PlantDisturbance d;
  d.noise_std = 0.5;
  d.seed = 7;
  RobotParams p;
  const State a = runOpenLoop(p, d, 0.5, 0.5, 1.0), b = runOpenLoop(p, d, 0.5, 0.5, 1.0);
  EXPECT_EQ(a, b);
  d.seed = 8;
  EXPECT_NE(runOpenLoop(p, d, 0.5, 0.5, 1.0), a);
  EXPECT_NE(a[Y], 0.0);  // noise differs between the wheels, so the robot turns
}

TEST(Plant, ValidationNamesTheBadParameter) {
  RobotParams p;
  p.mc = -1;
  EXPECT_NE(p.validate().find("mc"), std::string::npos);
  p = {};
  p.R = 0;
  EXPECT_NE(p.validate().find("R"), std::string::npos);
  p = {};
  p.Ic = std::nan("");
  EXPECT_NE(p.validate().find("Ic"), std::string::npos);
  PlantDisturbance d;
  d.mass_scale = 0;
  EXPECT_NE(d.validate().find("mass_scale"), std::string::npos);
}
