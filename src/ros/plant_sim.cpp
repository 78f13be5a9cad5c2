#include "sowing_robot/ros/plant_sim.h"

#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/plant_sim_lockstep.h"
#include "sowing_robot/ros/plant_sim_realtime.h"

namespace sowing_robot {

PlantSim::PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  std::string error = loadRobotParams(pnh, robot);
  const std::string mode = p.get("mode", "realtime");
  if (error.empty() && mode != "realtime" && mode != "lockstep")
    error = "mode = '" + mode + "' must be 'realtime' or 'lockstep'";
  cfg_.lockstep = mode == "lockstep";
  cfg_.period_ns = loadControlPeriod(p, error);
  cfg_.duration = p.get("duration", cfg_.duration);
  cfg_.realtime_factor = p.get("realtime_factor", cfg_.realtime_factor);
  cfg_.torque_timeout = p.get("torque_timeout", cfg_.torque_timeout);
  cfg_.publish_rate = p.get("publish_rate", cfg_.publish_rate);
  cfg_.clock_rate = p.get("clock_rate", cfg_.clock_rate);
  cfg_.lockstep_retry = p.get("lockstep_retry", cfg_.lockstep_retry);
  cfg_.lockstep_timeout = p.get("lockstep_timeout", cfg_.lockstep_timeout);
  cfg_.lockstep_give_up = p.get("lockstep_give_up", cfg_.lockstep_give_up);
  cfg_.min_subscribers = p.get("min_subscribers", cfg_.min_subscribers);
  cfg_.startup_delay = p.get("startup_delay", cfg_.startup_delay);
  cfg_.max_speed = p.get("max_speed", cfg_.max_speed);
  cfg_.exit_at_end = p.get("exit_at_end", cfg_.exit_at_end);
  const core::Pose2D start = loadStartPose(p);
  const core::PlantDisturbance disturbance = loadDisturbance(p);
  if (error.empty())
    error = core::firstError(
        {robot.validate(), disturbance.validate(), core::checkRange("duration", cfg_.duration, 0.0, 1e7, "s"),
         core::checkRange("realtime_factor", cfg_.realtime_factor, 0.01, 1000.0),
         core::checkPositive("torque_timeout", cfg_.torque_timeout, "s"),
         core::checkRange("publish_rate", cfg_.publish_rate, 0.1, 1000.0, "Hz"),
         core::checkRange("clock_rate", cfg_.clock_rate, 0.0, 1e6, "Hz"),
         core::checkPositive("lockstep_retry", cfg_.lockstep_retry, "s"),
         core::checkPositive("lockstep_timeout", cfg_.lockstep_timeout, "s"),
         core::checkNonNegative("lockstep_give_up", cfg_.lockstep_give_up, "s"),
         core::checkRange("min_subscribers", cfg_.min_subscribers, 0, 100),
         core::checkNonNegative("startup_delay", cfg_.startup_delay, "s"),
         core::checkPositive("max_speed", cfg_.max_speed, "m/s"),
         core::allFinite(start.x, start.y, start.theta) ? "" : "start pose must be finite"});
  requireValid(p, error);

  SimulatedPlant::Rates rates;
  rates.period_ns = cfg_.period_ns;
  rates.publish_rate = cfg_.publish_rate;
  rates.clock_rate = cfg_.clock_rate;
  rates.max_speed = cfg_.max_speed;
  plant_ = std::make_unique<SimulatedPlant>(nh, robot, disturbance, start, rates);
  const core::Plant& plant = plant_->plant();
  ROS_INFO("plant_sim: %s mode, %.0f Hz, duration %.3f s, m0 %.4f kg (true %.4f), I0 %.5f kg m^2 (true %.5f), "
           "sinusoidal disturbance %s, noise std %.3f N m, start (%.3f, %.3f, %.3f)",
           mode.c_str(), 1e9 / cfg_.period_ns, cfg_.duration, robot.m0(), plant.trueM0(), robot.I0(),
           plant.trueI0(), disturbance.sinusoidal ? "on" : "off", disturbance.noise_std, start.x, start.y,
           start.theta);

  if (cfg_.lockstep) {
    LockstepDriver::Config c;
    c.timing.retry = cfg_.lockstep_retry;
    c.timing.timeout = cfg_.lockstep_timeout;
    c.timing.give_up = cfg_.lockstep_give_up;
    c.timing.startup_delay = cfg_.startup_delay;
    c.duration = cfg_.duration;
    c.min_subscribers = cfg_.min_subscribers;
    driver_ = std::make_unique<LockstepDriver>(nh, *plant_, c);
  } else {
    RealtimeDriver::Config c;
    c.realtime_factor = cfg_.realtime_factor;
    c.torque_timeout = cfg_.torque_timeout;
    driver_ = std::make_unique<RealtimeDriver>(nh, *plant_, c);
  }
}

PlantSim::~PlantSim() = default;

void PlantSim::run() { driver_->run(); }

void PlantSim::stop() { driver_->stop(); }

}  // namespace sowing_robot
