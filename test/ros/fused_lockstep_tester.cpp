// rostest (fused_lockstep.test): the node pipeline in lockstep with feedback:=fused (plant_sim's sensors,
// state_estimator, the controllers on odometry/filtered) against the in-process loop with the EKF in it
// (core/simulation/runner.h) on the same parameters, read from the nodes' own namespaces (the scenario and the
// controller pair as pipeline_tester reads them; plant_sim's sensors/..., state_estimator's estimator/...).
// Every period's true pose (ground_truth) and estimate (odometry/filtered) must equal the in-process ones
// bit for bit. Fails without what it protects: an in-process loop that fed the controllers at another step,
// formed the EKF's inputs otherwise (e.g. without the quaternion round trip or the increment covariance) or
// applied the fixes at another time gives other numbers (the printed differences say how far).
// The drive train comes from the nodes' namespaces too: plant_sim's traction/ (+ field/patches) and
// motor/, kinematic_controller's limits/, torque_controller's traction_control/, reference_generator's speed_governor/
// (fused_field_lockstep.test: sim.launch profile:=field on a wet stretch of the line). ~expect_drive_train: the
// in-process run must show the traction control cutting and the governor slowing the target, so the comparison
// covers them at work.
// The reference is reference_generator's: the line, or with its type field the field's plan (its field/, potential/,
// obstacles and the URDF's footprint, as the node reads them; fused_field_wet_lockstep.test: sim.launch
// profile:=field outer:=rpp inner:=pid on the wet thesis field, to its end and the stop hold there).
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/param_reader.h"
#include "sowing_robot/ros/common/publisher_links.h"
#include "sowing_robot/ros/plant_sim/traction.h"

using namespace sowing_robot;

namespace {
struct Recorded {
  std::map<std::uint64_t, core::Pose2D> truth, estimate;
  void onTruth(const nav_msgs::Odometry::ConstPtr& m) { truth[m->header.stamp.toNSec()] = poseOf(*m); }
  void onEstimate(const nav_msgs::Odometry::ConstPtr& m) { estimate[m->header.stamp.toNSec()] = poseOf(*m); }
  void onOdom(const nav_msgs::Odometry::ConstPtr&) {}
};
}  // namespace

TEST(FusedLockstep, NodePipelineEqualsTheInProcessEstimatedLoop) {
  ros::NodeHandle nh, pnh("~");
  double timeout = 400.0;
  pnh.getParam("wall_timeout", timeout);
  core::Scenario sc;
  double duration = 0;
  const std::string err = loadPipelineScenario(sc, duration);
  ASSERT_TRUE(err.empty()) << err;
  core::LoopConfig cfg;
  cfg.feedback = core::Feedback::fused;
  ParamReader plant(ros::NodeHandle("/plant_sim")), estimator(ros::NodeHandle("/state_estimator")),
      torque(ros::NodeHandle("/torque_controller")), reference(ros::NodeHandle("/reference_generator")),
      kinematic(ros::NodeHandle("/kinematic_controller"));
  loadTable(plant, core::sensorsTable(), cfg.sensors);
  loadTable(estimator, core::ekfTable(), cfg.estimator);
  core::TractionParams traction;
  loadTable(plant, core::tractionTable(), traction);
  std::string patch_error;
  if (traction.enabled) {
    cfg.traction = traction;
    patch_error = loadSoilPatches(plant, "field/patches", traction, cfg.patches);
  }
  loadTable(plant, core::motorTable(), cfg.motor);
  loadTable(kinematic, core::commandLimitsTable(), cfg.limits);
  loadTable(torque, core::tractionControlTable(), cfg.traction_control);
  loadTable(torque, core::hitchControlTable(), cfg.hitch_control);  // inert here: no draft, no tool
  loadTable(reference, core::speedGovernorTable(), cfg.speed_governor);
  ASSERT_EQ(core::firstError({plant.error(), estimator.error(), kinematic.error(), torque.error(), reference.error(),
                              patch_error, cfg.validate()}),
            "");
  // The tool's draft needs the plan's rows and the URDF's tool point here too: not set up by this tester.
  ASSERT_EQ(traction.draft_force, 0.0) << "this tester compares runs without the tool's draft";
  bool slip_aware = false;  // what the .test expects of state_estimator's estimator/slip/detect
  pnh.getParam("slip_aware", slip_aware);
  ASSERT_EQ(cfg.estimator.slip.detect, slip_aware);
  bool expect_drive_train = false;
  pnh.getParam("expect_drive_train", expect_drive_train);
  std::printf(
      "fused lockstep: pair %s, %g s, sensors seed %llu, bias state %s, slip-aware %s; traction %s (%zu patch(es)), "
      "motors %s, "
      "traction control %s, speed governor %s\n",
      sc.controllerName().c_str(), duration, static_cast<unsigned long long>(cfg.sensors.seed),
      cfg.estimator.estimate_bias ? "on" : "off", slip_aware ? "on" : "off", cfg.traction ? "on" : "off",
      cfg.patches.size(), cfg.motor.enabled ? "on" : "off", cfg.traction_control.enabled ? "on" : "off",
      cfg.speed_governor.enabled ? "on" : "off");

  Recorded rec;
  const auto hints = ros::TransportHints().tcpNoDelay();
  // The estimate's link first, confirmed by its publisher (publisher_links.h): a subscription merely made lost the
  // first seconds of estimates under load. Then ground_truth and odom, counted by plant_sim's min_subscribers: the run
  // starts once this tester listens to both.
  ros::Subscriber est = nh.subscribe("odometry/filtered", 100000, &Recorded::onEstimate, &rec, hints);
  std::string unlinked;
  ASSERT_TRUE(waitUntilLinked({est.getTopic()}, timeout, &unlinked)) << "no publisher linked " << unlinked;
  ros::Subscriber truth = nh.subscribe("ground_truth", 100000, &Recorded::onTruth, &rec, hints);
  ros::Subscriber odom = nh.subscribe("odom", 10, &Recorded::onOdom, &rec, hints);
  const std::uint64_t last = static_cast<std::uint64_t>(sc.steps() * sc.control_period_ns);
  const ros::WallTime start = ros::WallTime::now();
  while (ros::ok() && !(rec.truth.count(last) && rec.estimate.count(last))) {
    ros::spinOnce();
    ros::WallDuration(0.001).sleep();
    ASSERT_LT((ros::WallTime::now() - start).toSec(), timeout) << "the pipeline did not finish the scenario";
  }

  // reference_generator's reference (src/ros/reference_generator.cpp reads it so): the line, or the field's plan.
  std::unique_ptr<core::ReferenceSource> source = std::make_unique<core::LineReference>(1.0, 3.0, 0.0);
  std::string type = "line";
  ros::param::get("/reference_generator/type", type);
  core::FieldSource* field_source = nullptr;
  if (type == "field") {
    // The plan from the node's parameters, read by the node's own function (component_params.h).
    ParamReader fieldp(ros::NodeHandle("/reference_generator"));
    core::FieldParams field;
    std::vector<core::Obstacle> obstacles;
    ASSERT_EQ(core::firstError({loadFieldPlan(fieldp, ros::NodeHandle(), sc.start, field, obstacles), fieldp.error()}),
              "");
    std::unique_ptr<core::FieldSource> f = core::makeFieldSource(field, obstacles);
    field_source = f.get();
    source = std::move(f);
  }
  core::ReferenceSource& ref = *source;
  double truth_diff = 0.0, estimate_diff = 0.0, fed_max = 0.0, first_stop = -1.0;
  std::int64_t compared = 0, unequal = 0, missing = 0, holding = 0;
  const core::LoopResult in_process = core::runClosedLoop(sc, cfg, ref, false, [&](const core::EstimatedSample& s) {
    const std::uint64_t k = static_cast<std::uint64_t>(std::llround(s.loop->t * 1e9));
    if (s.loop->control->holding) {  // the standstill hold at work (a stop)
      ++holding;
      if (first_stop < 0.0) first_stop = s.loop->t;
    }
    const auto t = rec.truth.find(k);
    const auto e = rec.estimate.find(k);
    if (t == rec.truth.end() || e == rec.estimate.end()) {
      ++missing;
      return;
    }
    const core::State& x = *s.loop->state;
    const double dt = std::max({std::fabs(t->second.x - x[core::X]), std::fabs(t->second.y - x[core::Y]),
                                std::fabs(t->second.theta - core::yawThroughQuaternion(x[core::THETA]))});
    const double de = std::max(
        {std::fabs(e->second.x - s.fed.x), std::fabs(e->second.y - s.fed.y), std::fabs(e->second.theta - s.fed.theta)});
    truth_diff = std::max(truth_diff, dt);
    estimate_diff = std::max(estimate_diff, de);
    fed_max = std::max(fed_max, std::hypot(s.fed.x - x[core::X], s.fed.y - x[core::Y]));
    unequal += (dt != 0.0 || de != 0.0);
    ++compared;
  });
  std::printf(
      "fused lockstep: %lld periods compared (%lld missing), %lld unequal; largest difference node - in-process: "
      "truth %.3g, estimate %.3g; estimate error %.4f m\n",
      static_cast<long long>(compared), static_cast<long long>(missing), static_cast<long long>(unequal), truth_diff,
      estimate_diff, fed_max);
  std::printf(
      "fused lockstep: in-process max |slip| %.3f, traction control cutting %.3f s, slowest governed rate %.3f\n",
      in_process.max_abs_slip, in_process.traction_control_time, in_process.governor_min_rate);
  if (field_source)
    std::printf("fused lockstep: field plan %s (%s)\n", core::AvoidanceStatus::name(field_source->status().code),
                field_source->status().reason.c_str());
  std::printf("fused lockstep: the standstill hold at work in %lld periods, from t = %.3f s\n",
              static_cast<long long>(holding), first_stop);
  bool expect_hold = false;  // ~expect_hold: the run must reach a stop, so the comparison covers the hold
  pnh.getParam("expect_hold", expect_hold);
  if (expect_hold) EXPECT_GT(holding, 1000) << "the run never held the robot at a stop for a second";
  if (expect_drive_train) {
    EXPECT_TRUE(cfg.traction && cfg.motor.enabled && cfg.traction_control.enabled && cfg.speed_governor.enabled);
    EXPECT_GT(in_process.traction_control_time, 0.0) << "the traction control never cut: the comparison misses it";
    EXPECT_LT(in_process.governor_min_rate, 1.0) << "the governor never slowed the target";
  }
  EXPECT_EQ(compared, sc.steps() + 1);
  EXPECT_EQ(unequal, 0);
  EXPECT_EQ(truth_diff, 0.0);
  EXPECT_EQ(estimate_diff, 0.0);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fused_lockstep_tester");
  return RUN_ALL_TESTS();
}
