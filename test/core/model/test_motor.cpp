// The drive motors (core/model/motor.h): the torque band of a DC motor with back-EMF and a current limit,
// the lag, a wheel on ice that can no longer spin up without bound, the plants unchanged with the motor
// off, and the refusal of motors that cannot move the robot.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {
MotorParams on() {
  MotorParams m;
  m.enabled = true;
  return m;
}
}  // namespace

TEST(Motor, OffPassesTheCommand) {
  WheelMotor motor;
  EXPECT_EQ(motor.apply(100.0, 50.0, 0.001), 100.0);
  EXPECT_EQ(motor.apply(-3.0, 0.0, 0.001), -3.0);
}

TEST(Motor, TheBandFallsWithSpeedAndStopsAtTheCurrentLimit) {
  const MotorParams m = on();
  double lo, hi;
  m.band(0.0, lo, hi);  // at rest: the current limit both ways (it is below the stall torque)
  EXPECT_DOUBLE_EQ(hi, m.current_limit);
  EXPECT_DOUBLE_EQ(lo, -m.current_limit);
  m.band(m.no_load_speed, lo, hi);  // at no-load speed: no driving torque left
  EXPECT_NEAR(hi, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(lo, -m.current_limit);
  m.band(-m.no_load_speed, lo, hi);
  EXPECT_NEAR(lo, 0.0, 1e-12);
  // Between: the back-EMF line tau_s (1 - W / W_0) once it is below the current limit.
  const double w = 0.95 * m.no_load_speed;
  m.band(w, lo, hi);
  EXPECT_NEAR(hi, m.stall_torque * 0.05, 1e-9);
  WheelMotor motor(m);
  EXPECT_NEAR(motor.apply(100.0, w, 0.001), m.stall_torque * 0.05, 1e-9);
  EXPECT_DOUBLE_EQ(motor.apply(-100.0, 0.0, 0.001), -m.current_limit);
  EXPECT_DOUBLE_EQ(motor.apply(1.0, 0.0, 0.001), 1.0);  // inside the band: the command itself
  // Far beyond W_0 the motor brakes at its current limit whatever the command.
  EXPECT_DOUBLE_EQ(motor.apply(100.0, 10.0 * m.no_load_speed, 0.001), -m.current_limit);
}

TEST(Motor, TheLagFollowsTheCommandWithItsTimeConstant) {
  MotorParams m = on();
  m.time_constant = 0.01;
  WheelMotor motor(m);
  double tau = 0.0;
  for (int i = 0; i < 10; ++i) tau = motor.apply(2.0, 0.0, 0.001);  // one time constant
  EXPECT_NEAR(tau, 2.0 * (1.0 - std::exp(-1.0)), 1e-9);
  motor.reset();
  EXPECT_EQ(motor.applied(), 0.0);
}

// A robot on ice commanded 100 N·m: without motors the wheels spin up without bound (only their inertia
// limits them), with them no faster than the no-load speed.
TEST(Motor, AWheelOnIceSpinsNoFasterThanTheNoLoadSpeed) {
  TractionParams ice;
  ice.mu_peak = ice.mu_slide = 0.0;
  for (const bool with_motor : {false, true}) {
    TractionPlant plant(RobotParams{}, PlantDisturbance{}, ice);
    if (with_motor) plant.setMotor(on());
    plant.reset(State::Zero());
    for (int i = 0; i < 2000; ++i) ASSERT_TRUE(plant.step(100.0, 100.0, 0.001));
    const double w = plant.wheelRate(RIGHT);
    if (with_motor) {
      EXPECT_LE(w, on().no_load_speed * (1.0 + 1e-6));
      EXPECT_GT(w, 0.9 * on().no_load_speed);
      EXPECT_LE(plant.appliedTorque(RIGHT), on().current_limit);
    } else {
      EXPECT_GT(w, 1000.0);
    }
  }
}

// Motor off: both plants step to the same bits as without a motor set.
TEST(Motor, OffTheBothPlantsAreUnchanged) {
  PlantDisturbance d;
  d.sinusoidal = true;
  d.noise_std = 0.2;
  State x0 = State::Zero();
  x0[V] = 0.3;
  Plant a(RobotParams{}, d), b(RobotParams{}, d);
  b.setMotor(MotorParams{});
  TractionPlant ta(RobotParams{}, d, TractionParams{}), tb(RobotParams{}, d, TractionParams{});
  tb.setMotor(MotorParams{});
  a.reset(x0);
  b.reset(x0);
  ta.reset(x0);
  tb.reset(x0);
  for (int i = 0; i < 3000; ++i) {
    const double tau = 5.0 * std::sin(0.01 * i);
    a.step(tau, -tau, 0.001);
    b.step(tau, -tau, 0.001);
    ta.step(tau, 0.5 * tau, 0.001);
    tb.step(tau, 0.5 * tau, 0.001);
  }
  EXPECT_EQ(std::memcmp(a.state().data(), b.state().data(), sizeof(double) * STATE_SIZE), 0);
  EXPECT_EQ(std::memcmp(ta.state().data(), tb.state().data(), sizeof(double) * STATE_SIZE), 0);
}

TEST(Motor, BadParametersAndMotorsThatCannotMoveTheRobotAreRefused) {
  MotorParams m = on();
  m.no_load_speed = -1.0;
  EXPECT_NE(m.validate().find("motor/no_load_speed"), std::string::npos);
  Plant plant(RobotParams{}, PlantDisturbance{});
  EXPECT_THROW(plant.setMotor(m), std::invalid_argument);
  // 0.5 N·m per wheel against 8 % rolling resistance of 18 kg and a 10 N draft (about 1.1 N·m needed).
  m = on();
  m.current_limit = 0.5;
  const std::string e = checkMotorsCanMove(m, RobotParams{}, 1.0, 0.08, 10.0);
  EXPECT_NE(e.find("motor/current_limit"), std::string::npos) << e;
  EXPECT_NE(e.find("traction/draft_force"), std::string::npos) << e;
  EXPECT_EQ(checkMotorsCanMove(on(), RobotParams{}, 1.0, 0.08, 10.0), "");
  // The loop refuses such a set-up before it starts.
  Scenario sc;
  sc.duration = 0.1;
  LoopConfig cfg;
  cfg.traction = TractionParams{};
  cfg.traction->draft_force = 10.0;
  cfg.motor = m;
  LineReference line;
  try {
    runClosedLoop(sc, cfg, line);
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("cannot move the robot"), std::string::npos) << ex.what();
  }
}
