// NaN and infinity at every core entry point that takes run-time input: a bad value is refused
// where it enters, leaves the component's state exactly as it was, and the next good input gives the
// same result as in a twin that never saw the bad one. Each test fails if its guard is removed: the
// state or output would turn NaN (or, for the potential field given t = inf, the integration would
// never end).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/potential_field.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/simulation/metrics.h"

using namespace sowing_robot::core;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
const std::vector<double> kBadValues{kNaN, kInf, -kInf};

bool sameReference(const Reference& a, const Reference& b) {
  return a.pose.x == b.pose.x && a.pose.y == b.pose.y && a.pose.theta == b.pose.theta && a.v == b.v &&
         a.omega == b.omega && a.v_dot == b.v_dot && a.omega_dot == b.omega_dot && a.tool_down == b.tool_down;
}

PlantDisturbance noisyDisturbance() {
  PlantDisturbance d;
  d.sinusoidal = true;
  d.noise_std = 0.5;  // a refused step must not draw from the noise generator either
  return d;
}

// Feeds `bad` to a fresh copy of a reference source between good queries and checks it against a twin.
void expectReferenceRefusesNonFiniteTime(const ReferenceSource& prototype) {
  auto source = prototype.clone(), twin = prototype.clone();
  Reference last;
  for (int k = 1; k <= 300; ++k) {
    const double t = 0.01 * k;
    last = source->next(t);
    ASSERT_TRUE(sameReference(last, twin->next(t))) << "t " << t;
    if (k % 100 == 0) {
      for (double bad : kBadValues) EXPECT_TRUE(sameReference(source->next(bad), last)) << "bad t " << bad;
    }
  }
  EXPECT_EQ(source->rejected(), 3 * static_cast<std::int64_t>(kBadValues.size()));
  EXPECT_EQ(twin->rejected(), 0);
  source->reset();
  EXPECT_EQ(source->rejected(), 0);
}
}  // namespace

TEST(NonFinite, PlantStepRefusesBadTorquesAndTimeSteps) {
  const RobotParams p;
  Plant plant(p, noisyDisturbance()), twin(p, noisyDisturbance());
  plant.reset(State::Zero());
  twin.reset(State::Zero());
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(plant.step(2.0, 1.0, 1e-3));
    twin.step(2.0, 1.0, 1e-3);
  }
  const State before = plant.state();
  const double t_before = plant.time();
  for (double bad : kBadValues) {
    EXPECT_FALSE(plant.step(bad, 1.0, 1e-3));
    EXPECT_FALSE(plant.step(1.0, bad, 1e-3));
    EXPECT_FALSE(plant.step(1.0, 1.0, bad));
  }
  EXPECT_FALSE(plant.step(1.0, 1.0, 0.0));
  EXPECT_FALSE(plant.step(1.0, 1.0, -1e-3));
  EXPECT_EQ(plant.state(), before);
  EXPECT_EQ(plant.time(), t_before);
  // Same noise draw and same result as the twin: nothing of the refused steps leaked in.
  ASSERT_TRUE(plant.step(2.0, 1.0, 1e-3));
  twin.step(2.0, 1.0, 1e-3);
  EXPECT_EQ(plant.state(), twin.state());
}

TEST(NonFinite, PlantRefusesBadParametersAndInitialStates) {
  RobotParams p;
  p.mc = kNaN;
  EXPECT_THROW(Plant(p, PlantDisturbance{}), std::invalid_argument);
  PlantDisturbance d;
  d.amplitude = kInf;
  EXPECT_THROW(Plant(RobotParams{}, d), std::invalid_argument);
  Plant plant(RobotParams{}, PlantDisturbance{});
  State s = State::Zero();
  s[THETA] = kNaN;
  EXPECT_THROW(plant.reset(s), std::invalid_argument);
  EXPECT_THROW(plant.reset(State::Zero(), kInf), std::invalid_argument);
}

TEST(NonFinite, KanayamaGivesTheStopCommandForEveryBadInput) {
  const Kanayama k;
  Reference ref;
  ref.pose = {1.0, 3.0, 0.1};
  ref.v = 1.0;
  ref.omega = 0.2;
  const Pose2D pose{0.0, 2.5, 0.0};
  const VelocityCommand good = k.compute(ref, pose, 0.5, 0.0);
  ASSERT_NE(good.v, 0.0);
  // Every input field in turn.
  std::vector<std::function<void(Reference&, Pose2D&, double&, double&, double)>> poison{
      [](Reference& r, Pose2D&, double&, double&, double b) { r.pose.x = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.pose.y = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.pose.theta = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.v = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.omega = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.v_dot = b; },
      [](Reference& r, Pose2D&, double&, double&, double b) { r.omega_dot = b; },
      [](Reference&, Pose2D& a, double&, double&, double b) { a.x = b; },
      [](Reference&, Pose2D& a, double&, double&, double b) { a.y = b; },
      [](Reference&, Pose2D& a, double&, double&, double b) { a.theta = b; },
      [](Reference&, Pose2D&, double& v, double&, double b) { v = b; },
      [](Reference&, Pose2D&, double&, double& w, double b) { w = b; }};
  for (std::size_t i = 0; i < poison.size(); ++i) {
    for (double bad : kBadValues) {
      Reference r = ref;
      Pose2D a = pose;
      double v = 0.5, w = 0.0;
      poison[i](r, a, v, w, bad);
      const VelocityCommand c = k.compute(r, a, v, w);
      EXPECT_TRUE(c.v == 0.0 && c.omega == 0.0 && c.v_dot == 0.0 && c.omega_dot == 0.0)
          << "input " << i << " = " << bad;
    }
  }
}

TEST(NonFinite, KanayamaRefusesBadGains) {
  KanayamaGains g;
  g.ky = kNaN;
  EXPECT_THROW(Kanayama{g}, std::invalid_argument);
  Kanayama k;
  EXPECT_THROW(k.setGains(g), std::invalid_argument);
  EXPECT_EQ(k.gains().ky, KanayamaGains{}.ky);  // old gains kept
}

TEST(NonFinite, SlidingModeHoldsItsOutputAndLeavesIntegralsAndEstimatesAlone) {
  SlidingModeParams params;
  params.adaptive = true;
  const RobotParams robot;
  SlidingModeController smc(params, robot), twin(params, robot);
  VelocityCommand cmd;
  cmd.v = 1.0;
  cmd.omega = 0.3;
  cmd.v_dot = 0.1;
  SlidingModeOutput last;
  for (int i = 0; i < 200; ++i) {
    last = smc.update(cmd, 0.2, 0.05, 1e-3);
    twin.update(cmd, 0.2, 0.05, 1e-3);
  }
  ASSERT_NE(smc.m0Hat(), SlidingModeController(params, robot).m0Hat());  // the estimates do move
  const double m0 = smc.m0Hat(), i0 = smc.i0Hat();
  std::vector<std::function<void(VelocityCommand&, double&, double&, double&, double)>> poison{
      [](VelocityCommand& c, double&, double&, double&, double b) { c.v = b; },
      [](VelocityCommand& c, double&, double&, double&, double b) { c.omega = b; },
      [](VelocityCommand& c, double&, double&, double&, double b) { c.v_dot = b; },
      [](VelocityCommand& c, double&, double&, double&, double b) { c.omega_dot = b; },
      [](VelocityCommand&, double& v, double&, double&, double b) { v = b; },
      [](VelocityCommand&, double&, double& w, double&, double b) { w = b; },
      [](VelocityCommand&, double&, double&, double& dt, double b) { dt = b; }};
  for (std::size_t i = 0; i < poison.size(); ++i) {
    for (double bad : kBadValues) {
      VelocityCommand c = cmd;
      double v = 0.2, w = 0.05, dt = 1e-3;
      poison[i](c, v, w, dt, bad);
      const SlidingModeOutput out = smc.update(c, v, w, dt);
      EXPECT_TRUE(out.rejected) << "input " << i << " = " << bad;
      EXPECT_EQ(out.torques.right, last.torques.right);
      EXPECT_EQ(out.torques.left, last.torques.left);
    }
  }
  EXPECT_TRUE(smc.update(cmd, 0.2, 0.05, 0.0).rejected);
  EXPECT_EQ(smc.m0Hat(), m0);
  EXPECT_EQ(smc.i0Hat(), i0);
  // The next good period matches the twin's bit for bit: the integrals were not touched.
  const SlidingModeOutput a = smc.update(cmd, 0.2, 0.05, 1e-3), b = twin.update(cmd, 0.2, 0.05, 1e-3);
  EXPECT_FALSE(a.rejected);
  EXPECT_EQ(a.torques.right, b.torques.right);
  EXPECT_EQ(a.torques.left, b.torques.left);
  EXPECT_EQ(a.s_v, b.s_v);
  EXPECT_EQ(a.s_omega, b.s_omega);
}

TEST(NonFinite, SlidingModeRefusesBadParameters) {
  SlidingModeParams params;
  params.k1 = kNaN;
  EXPECT_THROW(SlidingModeController(params, RobotParams{}), std::invalid_argument);
  SlidingModeController smc(SlidingModeParams{}, RobotParams{});
  EXPECT_THROW(smc.setParams(params), std::invalid_argument);
  EXPECT_EQ(smc.params().k1, SlidingModeParams{}.k1);  // old parameters kept
}

TEST(NonFinite, LineReferenceRefusesNonFiniteTime) { expectReferenceRefusesNonFiniteTime(LineReference()); }

TEST(NonFinite, PotentialFieldRefusesNonFiniteTime) {
  expectReferenceRefusesNonFiniteTime(PotentialField(PotentialFieldParams{}, RowLine{}, {{1.5, 3.2, 0.3}}));
}

TEST(NonFinite, FieldReferenceRefusesNonFiniteTime) {
  expectReferenceRefusesNonFiniteTime(FieldReference(FieldParams{}));
}

TEST(NonFinite, MetricsRefuseNonFiniteSamples) {
  MetricsAccumulator m, twin;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k, e = std::exp(-t);
    ASSERT_TRUE(m.add(t, e, -e, 0.1 * e));
    twin.add(t, e, -e, 0.1 * e);
    if (k == 50) {
      for (double bad : kBadValues) {
        EXPECT_FALSE(m.add(bad, 0.0, 0.0, 0.0));
        EXPECT_FALSE(m.add(t + 0.005, bad, 0.0, 0.0));
        EXPECT_FALSE(m.add(t + 0.005, 0.0, bad, 0.0));
        EXPECT_FALSE(m.add(t + 0.005, 0.0, 0.0, bad));
      }
    }
  }
  EXPECT_EQ(m.rejected(), 4 * kBadValues.size());
  EXPECT_EQ(m.samples(), twin.samples());
  const auto a = m.result(), b = twin.result();
  for (int axis = 0; axis < AXIS_COUNT; ++axis) {
    EXPECT_EQ(a[axis].itae, b[axis].itae);
    EXPECT_EQ(a[axis].ise, b[axis].ise);
    EXPECT_EQ(a[axis].settling_time, b[axis].settling_time);
  }
}

TEST(NonFinite, SeedDrillRefusesNonFinitePositions) {
  SeedingParams p;
  const std::vector<RowSegment> rows{{Eigen::Vector2d(0, 3), Eigen::Vector2d(100, 3)}};
  SeedDrill drill(p, rows, {}, 0.5), twin(p, rows, {}, 0.5);
  Eigen::Vector2d seed;
  int seeds = 0, twin_seeds = 0;
  for (int i = 0; i <= 2000; ++i) {
    const Eigen::Vector2d at(i * 1e-3, 3.0);
    seeds += drill.update(at, true, seed);
    twin_seeds += twin.update(at, true, seed);
    if (i == 1000) {
      for (double bad : kBadValues) {
        EXPECT_FALSE(drill.update({bad, 3.0}, true, seed));
        EXPECT_FALSE(drill.update({1.0, bad}, true, seed));
      }
    }
  }
  EXPECT_EQ(drill.rejected(), 2 * kBadValues.size());
  EXPECT_EQ(seeds, twin_seeds);
  EXPECT_EQ(drill.onRows().count, twin.onRows().count);
  EXPECT_EQ(drill.onRows().max, twin.onRows().max);
}
