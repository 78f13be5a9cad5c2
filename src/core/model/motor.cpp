#include "sowing_robot/core/model/motor.h"

#include <algorithm>
#include <cmath>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<MotorParams>& motorTable() {
  using M = MotorParams;
  static const ParamTable<M> table({
      flag("motor/enabled", &M::enabled, false,
           "DC motor with gearbox at each wheel (torque falls with wheel speed, current limit); false: the "
           "commanded torque reaches the wheel unchanged"),
      number("motor/stall_torque", &M::stall_torque, 52.6, Limits::positive(), "N·m",
             "wheel torque at rest at full voltage (motor stall torque × gear ratio × gearbox efficiency)"),
      number("motor/no_load_speed", &M::no_load_speed, 30.5, Limits::positive(), "rad/s",
             "wheel speed where the available torque reaches zero (motor no-load speed / gear ratio)"),
      number("motor/current_limit", &M::current_limit, 6.4, Limits::positive(), "N·m",
             "wheel torque at the motor driver's current limit"),
      number("motor/time_constant", &M::time_constant, 0.0, Limits::closed(0.0, 1.0), "s",
             "first-order lag of the torque behind the clipped command; 0 = none"),
  });
  return table;
}

MotorParams::MotorParams() { motorTable().applyDefaults(*this); }

std::string MotorParams::validate() const { return motorTable().checkRanges(*this); }

void MotorParams::band(double w, double& lo, double& hi) const {
  const double slope = stall_torque / no_load_speed;
  lo = std::max(-current_limit, -stall_torque - slope * w);
  hi = std::min(current_limit, stall_torque - slope * w);
}

double WheelMotor::apply(double tau, double w, double dt) {
  if (!params_.enabled) {
    applied_ = tau;
    return tau;
  }
  double lo, hi;
  params_.band(w, lo, hi);
  // Far beyond W_0 even full voltage drives more braking current than the driver's limit: the motor
  // brakes at that limit whatever the command (the band is empty).
  const double target = lo <= hi ? std::clamp(tau, lo, hi) : (w > 0.0 ? lo : hi);
  if (params_.time_constant > 0.0) {
    applied_ += (target - applied_) * -std::expm1(-dt / params_.time_constant);
    applied_ = lo <= hi ? std::clamp(applied_, lo, hi) : target;
  } else {
    applied_ = target;
  }
  return applied_;
}

std::string checkMotorsCanMove(const MotorParams& motor, const RobotParams& robot, double mass_scale,
                               double rolling_resistance, double draft_force) {
  if (!motor.enabled) return "";
  constexpr double kG = 9.81;
  const double needed = 0.5 * robot.R * (rolling_resistance * mass_scale * robot.m() * kG + draft_force);
  const double available = std::min(motor.stall_torque, motor.current_limit);
  if (available > needed) return "";
  return "motor/stall_torque " + formatNumber(motor.stall_torque) + " N·m and motor/current_limit " +
         formatNumber(motor.current_limit) + " N·m cannot move the robot: each wheel needs more than " +
         formatNumber(needed) + " N·m against traction/rolling_resistance " + formatNumber(rolling_resistance) +
         " and traction/draft_force " + formatNumber(draft_force) + " N";
}

}  // namespace core
}  // namespace sowing_robot
