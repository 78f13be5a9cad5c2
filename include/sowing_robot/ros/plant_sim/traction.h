// plant_sim's traction model (traction/enabled): core::TractionPlant with the field's soil patches and
// the seed drill tool's draft, behind SimulatedPlant's PlantModel interface (plant_model.h).
//
// Inputs: the patches (`field/patches`, plant_sim's private parameters, loaded by loadSoilPatches) and,
// with a draft (traction/draft_force > 0), the reference generator's latched `plan`: its rows decide
// when the tool is down (core/planning/tool_engagement.h, the seed drill's own rule on the true tool point). A
// lockstep run does not start before the plan has come (ready()), so every step sees the same rows.
// Outputs: `wheel_slip` (std_msgs/Float64MultiArray, with the visuals at publish_rate; layout label
// names the entries: slip_right, slip_left [slip ratio], force_right, force_left [N, ground force on each
// wheel], draft_force [N, on v], tool_down [0/1], patch_right, patch_left [index, -1: default soil],
// stamp [s, the simulated time]) and
// `soil_markers` (visualization_msgs/MarkerArray, latched: each patch's outline and fill in odom_frame).
// No traction: on torque_controller's first `traction_control/state` with the verdict, the soil's grip budget at
// the verdict's place (core::gripDiagnosis, the in-process run's diagnosis to the character) is logged at ERROR,
// published latched on `no_traction_diagnosis` (std_msgs/String) and added to the end-of-run report: the robot
// knows it has no traction, only the simulation knows whether there was grip to be had.
#pragma once

#include <ros/ros.h>

#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "sowing_robot/FieldPlan.h"
#include "sowing_robot/TractionControlState.h"
#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/tool_engagement.h"
#include "sowing_robot/ros/common/param_reader.h"
#include "sowing_robot/ros/plant_sim/plant_model.h"

namespace sowing_robot {

/// The list `key` of {polygon: [[x, y], ...], mu_peak, mu_slide, rolling_resistance} maps (absent
/// coefficients: the traction/ value of `ground`); marks `key` as read. Returns "" or one line naming the
/// bad entry's full key (absent key: no patches).
std::string loadSoilPatches(ParamReader& p, const std::string& key, const core::TractionParams& ground,
                            std::vector<core::SoilPatch>& out);

class TractionModel : public PlantModel {
 public:
  struct Config {
    core::TractionParams traction;
    core::SoilMap soil;
    Eigen::Vector2d tool{-0.45, 0.0};  // tool point in base_link (URDF tool_link) [m]
    core::SeedingParams seeding;       // engage_distance and the depth band (depth_min): the seed drill's
    std::string odom_frame = "odom";
  };
  /// Throws std::invalid_argument when the parameters do not validate.
  TractionModel(ros::NodeHandle nh, const core::RobotParams& robot, const core::PlantDisturbance& disturbance,
                const core::State& x0, const Config& config);

  void step(double tau_right, double tau_left, double dt) override;
  void setToolRaised(bool raised) override { tool_raised_ = raised; }
  /// As the in-process loop: a depth control's depth (> 0) from this step on, clamped to the mechanical range;
  /// 0 (no depth control) or a non-finite one: the drill's nominal depth (traction/draft_depth).
  void setToolDepth(double depth) override {
    plant_.setToolDepth(depth > 0.0 && std::isfinite(depth) ? depth : cfg_.traction.draft_depth);
  }
  const core::State& state() const override { return plant_.state(); }
  double time() const override { return plant_.time(); }
  void wheelRates(double& right, double& left) const override {
    right = plant_.wheelRate(core::RIGHT);
    left = plant_.wheelRate(core::LEFT);
  }
  void setMotor(const core::MotorParams& motor) override { plant_.setMotor(motor); }
  void appliedTorques(double& right, double& left) const override {
    right = plant_.appliedTorque(core::RIGHT);
    left = plant_.appliedTorque(core::LEFT);
  }
  double trueM0() const override { return m0_; }
  double trueI0() const override { return i0_; }
  bool ready() const override;
  std::string waitingFor() const override;
  void publishVisuals(const ros::Time& stamp) override;
  std::string report() const override;
  const core::TractionPlant& plant() const { return plant_; }

 private:
  void planCallback(const FieldPlan::ConstPtr& plan);
  void tractionCallback(const TractionControlState::ConstPtr& msg);
  void publishSoil();

  Config cfg_;
  core::TractionPlant plant_;
  core::RobotParams robot_;  // nominal, with the true mass scale below: the grip budget's loads
  double mass_scale_;
  double m0_, i0_;
  mutable std::mutex mutex_;  // the plan comes on another thread than the steps
  core::ToolEngagement tool_;
  bool has_plan_ = false;
  bool tool_raised_ = false;  // the hitch control's command for the next step
  double max_slip_ = 0.0, tool_down_time_ = 0.0, tool_held_up_time_ = 0.0;
  double max_draft_ = 0.0;
  double min_depth_ = 0.0;  // the shallowest depth the tool was down at [m] (0: never down)
  std::int64_t steps_ = 0;
  std::string no_traction_;  // the grip diagnosis at the verdict, once it has come
  ros::Publisher slip_pub_, soil_pub_, diagnosis_pub_;
  ros::Subscriber plan_sub_, traction_sub_;
};

}  // namespace sowing_robot
