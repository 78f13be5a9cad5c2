#include "sowing_robot/core/simulation/loop_types.h"

#include <cmath>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::string Scenario::validate() const {
  return firstError({checkPositive("duration", duration, "s"),
                     control_period_ns > 0 ? "" : "control_period must be > 0",
                     allFinite(start.x, start.y, start.theta) ? "" : "start pose must be finite",
                     std::isfinite(disturbance_phase) ? "" : "disturbance_phase must be finite", robot.validate(),
                     disturbance.validate(), validateControllers(), hold.validate()});
}

std::int64_t Scenario::steps() const {
  return static_cast<std::int64_t>(std::llround(duration * 1e9 / static_cast<double>(control_period_ns)));
}

const char* feedbackName(Feedback f) {
  switch (f) {
    case Feedback::ground_truth: return "ground_truth";
    case Feedback::odometry: return "odometry";
    case Feedback::fused: return "fused";
  }
  return "?";
}

std::string parseFeedback(const std::string& name, Feedback& out) {
  for (Feedback f : {Feedback::ground_truth, Feedback::odometry, Feedback::fused})
    if (name == feedbackName(f)) {
      out = f;
      return "";
    }
  return "feedback '" + name + "' is none of ground_truth, odometry, fused";
}

std::string LoopConfig::validate() const {
  std::string e =
      firstError({sensors.validate(), estimator.validate(), traction ? traction->validate() : "", motor.validate(),
                  traction_control.validate(), speed_governor.validate(), hitch_control.validate()});
  if (!e.empty()) return e;
  if (speed_governor.enabled && !traction_control.enabled)
    return "speed_governor/enabled needs traction_control/enabled (the governor acts on its slip verdict)";
  if (hitch_control.enabled && !traction_control.enabled)
    return "hitch_control/enabled needs traction_control/enabled (the hitch acts on its grip verdict)";
  if (hitch_control.enabled && hitch_control.depth_control) {
    e = seeding.validate();
    if (!e.empty()) return e;
    const HitchControlParams& h = hitch_control;
    if (h.depth_shallowest < seeding.depth_min || h.depth_nominal > seeding.depth_max)
      return "hitch_control/depth_shallowest = " + formatNumber(h.depth_shallowest) +
             " and depth_nominal = " + formatNumber(h.depth_nominal) + " must lie in the agronomic band [" +
             formatNumber(seeding.depth_min) + ", " + formatNumber(seeding.depth_max) +
             "] (seed_drill/depth_min, depth_max)";
    if (traction && (h.depth_shallowest < traction->tool_depth_min || h.depth_nominal > traction->tool_depth_max))
      return "hitch_control/depth_shallowest .. depth_nominal must lie in the drill's mechanical range [" +
             formatNumber(traction->tool_depth_min) + ", " + formatNumber(traction->tool_depth_max) +
             "] (traction/tool_depth_min, max)";
  }
  if (!allFinite(tool.x(), tool.y())) return "the tool point must be finite";
  for (std::size_t i = 0; i < patches.size(); ++i) {
    e = patches[i].validate("field/patches[" + std::to_string(i) + "]");
    if (!e.empty()) return e;
  }
  return "";
}

}  // namespace core
}  // namespace sowing_robot
