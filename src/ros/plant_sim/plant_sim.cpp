#include "sowing_robot/ros/plant_sim/plant_sim.h"

#include <algorithm>
#include <cmath>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/urdf_params.h"
#include "sowing_robot/ros/coverage_route.h"
#include "sowing_robot/ros/plant_sim/lockstep.h"
#include "sowing_robot/ros/plant_sim/realtime.h"
#include "sowing_robot/ros/plant_sim/traction.h"

namespace sowing_robot {

namespace {
/// The draft's tool: the seed drill's tool point (URDF link `seed_drill/tool_link`) and its lowering rule
/// (`seed_drill/engage_distance`), read where sim.launch loads config/seed_drill.yaml (the run's
/// namespace), so the plant's "tool down" is the drill's. "" or one line naming the bad key.
std::string loadToolSettings(const ros::NodeHandle& nh, const std::string& urdf, TractionModel::Config& out) {
  std::string link = "tool_link";
  nh.param<std::string>("seed_drill/tool_link", link, link);
  double engage = out.seeding.engage_distance;
  nh.param("seed_drill/engage_distance", engage, engage);
  if (!(engage > 0.0) || !std::isfinite(engage))
    return "parameter " + nh.resolveName("seed_drill/engage_distance") + " must be finite and > 0 (the draft's tool)";
  out.seeding.engage_distance = engage;
  // The agronomic depth band's shallowest depth: the depth the field check judges the drill at.
  double depth_min = out.seeding.depth_min;
  nh.param("seed_drill/depth_min", depth_min, depth_min);
  if (!(depth_min > 0.0) || !std::isfinite(depth_min))
    return "parameter " + nh.resolveName("seed_drill/depth_min") + " must be finite and > 0 (the drill's depth band)";
  out.seeding.depth_min = depth_min;
  double x = 0.0, y = 0.0;
  const std::string e = linkPositionFromUrdf(urdf, link, x, y);
  if (!e.empty()) return "the draft's tool point (seed_drill/tool_link): " + e;
  out.tool = Eigen::Vector2d(x, y);
  return "";
}
}  // namespace

PlantSim::PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  const std::string robot_error = loadRobotParams(pnh, robot);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::PlantSimSettings settings;
  loadTable(p, core::PlantSimSettings::table(), settings);
  // traction/... and field/patches: validated even when traction is off, so a bad value never waits for
  // the day it is switched on.
  TractionModel::Config traction;
  loadTable(p, core::tractionTable(), traction.traction);
  std::vector<core::SoilPatch> patches;
  const std::string patch_error = loadSoilPatches(p, "field/patches", traction.traction, patches);
  core::SensorParams sensors;
  loadTable(p, core::sensorsTable(), sensors);
  // The drive motors (motor/...): between the torques commanded and the wheels, off by default (today's plant).
  core::MotorParams motor;
  loadTable(p, core::motorTable(), motor);
  // The body checked for contacts is the URDF's collision footprint (the one source of the robot's shape).
  core::Footprint footprint;
  std::string key, xml, footprint_error;
  if (robot_error.empty() && pnh.searchParam("robot_description", key) && pnh.getParam(key, xml))
    footprint_error = footprintFromUrdf(xml, footprint);
  const std::string tool_error = traction.traction.enabled && traction.traction.draft_force > 0.0 && robot_error.empty()
                                     ? loadToolSettings(nh, xml, traction)
                                     : "";
  std::string error =
      core::firstError({robot_error, robot_error.empty() ? robot.validate() : "", footprint_error, settings.validate(),
                        traction.traction.validate(), patch_error, tool_error, sensors.validate(), motor.validate()});
  if (error.empty() && p.error().empty() && traction.traction.enabled) {
    // Motors that cannot move the robot against the worst soil's rolling resistance and the draft are refused,
    // as the in-process loop refuses them (core::runClosedLoop).
    double rolling = traction.traction.rolling_resistance;
    for (const core::SoilPatch& patch : patches) rolling = std::max(rolling, patch.rolling_resistance);
    error =
        core::checkMotorsCanMove(motor, robot, settings.disturbance.mass_scale, rolling, traction.traction.draft_force);
  }
  core::Pose2D start = run.start();
  if (error.empty() && p.error().empty() && settings.start_at_route) {
    // Planned from reference_generator's own keys, as it plans: the same start pose (its unknown keys are its own
    // to refuse, so this reader's are not checked).
    ros::NodeHandle ref(nh, "reference_generator");
    ParamReader rp(ref);
    core::ReferenceGeneratorSettings ref_settings;
    loadTable(rp, core::ReferenceGeneratorSettings::table(), ref_settings);
    CoverageRoute route;
    if (ref_settings.type != core::ReferenceGeneratorSettings::Type::kCoverage)
      error = pnh.resolveName("start_at_route") + " needs " + ref.resolveName("type") + " coverage";
    else
      error = loadCoverageRoute(rp, nh, ref_settings, route);
    if (error.empty()) error = rp.error();
    if (!error.empty())
      error = pnh.resolveName("start_at_route") + ": reference_generator's route cannot be planned: " + error;
    else
      start = route.start;
  }
  requireValid(p, error);
  if (settings.start_at_route)
    ROS_INFO("plant_sim: starting at the coverage route's start (%.3f, %.3f, %.3f) (start_at_route)", start.x, start.y,
             start.theta);
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
  cfg_.loop_on_odom = settings.loop_topic == "odom";
  cfg_.startup_delay = settings.startup_delay;
  cfg_.max_speed = settings.max_speed;
  cfg_.exit_at_end = settings.exit_at_end;
  const core::PlantDisturbance& disturbance = settings.disturbance;

  SimulatedPlant::Rates rates;
  rates.period_ns = cfg_.period_ns;
  rates.publish_rate = cfg_.publish_rate;
  rates.clock_rate = cfg_.clock_rate;
  rates.max_speed = cfg_.max_speed;
  rates.odom_frame = run.odom_frame;
  rates.base_frame = run.base_frame;
  std::unique_ptr<PlantModel> model;
  if (traction.traction.enabled) {
    traction.soil = core::SoilMap(patches);  // validated above
    traction.odom_frame = run.odom_frame;
    try {
      model = std::make_unique<TractionModel>(nh, robot, disturbance, SimulatedPlant::restAt(start), traction);
    } catch (const std::invalid_argument& e) {
      refuseToStart(e.what());
    }
  } else if (!patches.empty()) {
    ROS_WARN("plant_sim: %zu soil patch(es) in field/patches have no effect: traction/enabled is false",
             patches.size());
  }
  plant_ = std::make_unique<SimulatedPlant>(nh, robot, disturbance, start, rates, footprint, std::move(model), sensors);
  plant_->setMotor(motor);  // validated above
  const PlantModel& plant = plant_->model();
  logSettings("plant_sim", core::RunSettings::table(), run, "run/");
  logSettings("plant_sim", core::PlantSimSettings::table(), settings);
  logSettings("plant_sim", core::sensorsTable(), sensors);
  if (traction.traction.enabled) {
    logSettings("plant_sim", core::tractionTable(), traction.traction);
    ROS_INFO("plant_sim: traction plant with %zu soil patch(es); tool point (%.3f, %.3f) m", patches.size(),
             traction.tool.x(), traction.tool.y());
  }
  logSettings("plant_sim", core::motorTable(), motor);
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
    c.loop_on_odom = cfg_.loop_on_odom;
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
