#include "sowing_robot/ros/plant_sim.h"

#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/plant_sim_lockstep.h"
#include "sowing_robot/ros/plant_sim_realtime.h"
#include "sowing_robot/ros/urdf_params.h"

namespace sowing_robot {

PlantSim::PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  const std::string robot_error = loadRobotParams(pnh, robot);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::PlantSimSettings settings;
  loadTable(p, core::PlantSimSettings::table(), settings);
  // The body checked for contacts is the URDF's collision footprint (the one source of the robot's shape).
  core::Footprint footprint;
  std::string key, xml, footprint_error;
  if (robot_error.empty() && pnh.searchParam("robot_description", key) && pnh.getParam(key, xml))
    footprint_error = footprintFromUrdf(xml, footprint);
  requireValid(p, core::firstError({robot_error, robot_error.empty() ? robot.validate() : "", footprint_error,
                                    settings.validate()}));
  cfg_.lockstep = run.lockstep;
  cfg_.period_ns = run.periodNs();
  cfg_.duration = run.duration;
  cfg_.realtime_factor = settings.realtime_factor;
  cfg_.torque_timeout = settings.torque_timeout;
  cfg_.publish_rate = settings.publish_rate;
  cfg_.clock_rate = settings.clock_rate;
  cfg_.lockstep_retry = settings.lockstep_retry;
  cfg_.lockstep_timeout = settings.lockstep_timeout;
  cfg_.lockstep_give_up = settings.lockstep_give_up;
  cfg_.min_subscribers = settings.min_subscribers;
  cfg_.wait_for = settings.waitForNames();
  cfg_.startup_delay = settings.startup_delay;
  cfg_.max_speed = settings.max_speed;
  cfg_.exit_at_end = settings.exit_at_end;
  const core::Pose2D start = run.start();
  const core::PlantDisturbance& disturbance = settings.disturbance;

  SimulatedPlant::Rates rates;
  rates.period_ns = cfg_.period_ns;
  rates.publish_rate = cfg_.publish_rate;
  rates.clock_rate = cfg_.clock_rate;
  rates.max_speed = cfg_.max_speed;
  rates.odom_frame = run.odom_frame;
  rates.base_frame = run.base_frame;
  plant_ = std::make_unique<SimulatedPlant>(nh, robot, disturbance, start, rates, footprint);
  const core::Plant& plant = plant_->plant();
  logSettings("plant_sim", core::RunSettings::table(), run, "run/");
  logSettings("plant_sim", core::PlantSimSettings::table(), settings);
  ROS_INFO("plant_sim: m0 %.4f kg (true %.4f), I0 %.5f kg m^2 (true %.5f)", robot.m0(), plant.trueM0(), robot.I0(),
           plant.trueI0());

  if (cfg_.lockstep) {
    LockstepDriver::Config c;
    c.timing.retry = cfg_.lockstep_retry;
    c.timing.timeout = cfg_.lockstep_timeout;
    c.timing.give_up = cfg_.lockstep_give_up;
    c.timing.startup_delay = cfg_.startup_delay;
    c.duration = cfg_.duration;
    c.min_subscribers = cfg_.min_subscribers;
    c.wait_for = cfg_.wait_for;
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
