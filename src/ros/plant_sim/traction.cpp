#include "sowing_robot/ros/plant_sim/traction.h"

#include <std_msgs/Float64MultiArray.h>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/markers.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

namespace {

std::string loadPolygon(XmlRpc::XmlRpcValue& list, const std::string& name, std::vector<Eigen::Vector2d>& out) {
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray) return name + " must be a list of [x, y] vertices";
  for (int i = 0; i < list.size(); ++i) {
    XmlRpc::XmlRpcValue& v = list[i];
    Eigen::Vector2d p;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || v.size() != 2 || !xmlNumber(v[0], p.x()) ||
        !xmlNumber(v[1], p.y()))
      return name + "[" + std::to_string(i) + "] must be a vertex [x, y] of two numbers";
    out.push_back(p);
  }
  return "";
}
}  // namespace

std::string loadSoilPatches(ParamReader& p, const std::string& key, const core::TractionParams& ground,
                            std::vector<core::SoilPatch>& out) {
  out.clear();
  const auto visit = [&ground, &out](const std::string& name, XmlRpc::XmlRpcValue& item) {
    core::SoilPatch patch;
    patch.mu_peak = ground.mu_peak;
    patch.mu_slide = ground.mu_slide;
    patch.rolling_resistance = ground.rolling_resistance;
    const MapMember polygon{"polygon", [&patch](XmlRpc::XmlRpcValue& v, const std::string& item_name) {
                              return loadPolygon(v, item_name + "/polygon", patch.polygon);
                            }};
    std::string e =
        readMembers(item, name,
                    {polygon, numberMember("mu_peak", patch.mu_peak), numberMember("mu_slide", patch.mu_slide),
                     numberMember("rolling_resistance", patch.rolling_resistance),
                     numberMember("draft_factor", patch.draft_factor)});
    if (e.empty()) e = patch.validate(name);
    if (!e.empty()) return e;
    // The patch's grip must fit the field's slip curve too (slip_stiffness >= mu_peak / slip_peak).
    core::TractionParams t = ground;
    t.mu_peak = patch.mu_peak;
    t.mu_slide = patch.mu_slide;
    t.rolling_resistance = patch.rolling_resistance;
    const std::string curve = t.validate();
    if (!curve.empty()) return name + "/mu_peak: with the field's slip curve, " + curve;
    out.push_back(patch);
    return std::string();
  };
  return forEachMap(p, key, "{polygon, mu_peak, mu_slide, rolling_resistance, draft_factor}", visit);
}

TractionModel::TractionModel(ros::NodeHandle nh, const core::RobotParams& robot,
                             const core::PlantDisturbance& disturbance, const core::State& x0, const Config& config)
    : cfg_(config),
      plant_(robot, disturbance, config.traction),
      robot_(robot),
      mass_scale_(disturbance.mass_scale),
      m0_(robot.m0() * disturbance.mass_scale),
      i0_(robot.I0() * disturbance.inertia_scale),
      tool_(config.seeding, {}) {
  plant_.setSoil(config.soil);
  plant_.setToolPoint(config.tool);
  plant_.reset(x0, 0.0);
  // The field check before the run: can each soil pull the drill at the band's shallowest depth?
  for (const core::DraftCheck& c : core::checkFieldDraft(robot, disturbance.mass_scale, config.traction,
                                                         config.soil.patches(), config.seeding.depth_min)) {
    if (c.carried)
      ROS_INFO("plant_sim: field check: %s", c.why.c_str());
    else
      ROS_WARN("plant_sim: field check: %s", c.why.c_str());
  }
  const std::string overlap = core::patchOverlapNote(config.soil.patches());
  if (!overlap.empty()) ROS_INFO("plant_sim: field check: %s", overlap.c_str());
  slip_pub_ = nh.advertise<std_msgs::Float64MultiArray>("wheel_slip", kLockstepQueue);
  soil_pub_ = nh.advertise<visualization_msgs::MarkerArray>("soil_markers", 1, true);
  publishSoil();
  if (cfg_.traction.draft_force > 0.0) plan_sub_ = nh.subscribe("plan", 1, &TractionModel::planCallback, this);
  diagnosis_pub_ = nh.advertise<std_msgs::String>("no_traction_diagnosis", 1, true);
  traction_sub_ = nh.subscribe("traction_control/state", 10, &TractionModel::tractionCallback, this);
}

void TractionModel::tractionCallback(const TractionControlState::ConstPtr& msg) {
  if (!msg->no_traction) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!no_traction_.empty()) return;  // the verdict is latched: every later message repeats it
  const Eigen::Vector2d where(msg->no_traction_where.x, msg->no_traction_where.y);
  no_traction_ = core::gripDiagnosis(robot_, mass_scale_, cfg_.traction, cfg_.soil, where);
  ROS_ERROR("plant_sim: no traction at (%.2f %.2f): %s", where.x(), where.y(), no_traction_.c_str());
  std_msgs::String out;
  out.data = no_traction_;
  diagnosis_pub_.publish(out);
}

void TractionModel::planCallback(const FieldPlan::ConstPtr& plan) {
  const std::size_t n = std::min(plan->row_starts.size(), plan->row_ends.size());
  std::vector<core::RowSegment> rows(n);
  for (std::size_t i = 0; i < n; ++i)
    rows[i] = {Eigen::Vector2d(plan->row_starts[i].x, plan->row_starts[i].y),
               Eigen::Vector2d(plan->row_ends[i].x, plan->row_ends[i].y)};
  std::lock_guard<std::mutex> lock(mutex_);
  tool_.setPlan(std::move(rows), plan->open_ended);
  has_plan_ = true;
}

bool TractionModel::ready() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return has_plan_ || cfg_.traction.draft_force <= 0.0;
}

std::string TractionModel::waitingFor() const { return ready() ? "" : "the plan (traction/draft_force > 0)"; }

void TractionModel::step(double tau_right, double tau_left, double dt) {
  if (cfg_.traction.draft_force > 0.0) {
    // The tool point of the state the torque answers (t_k): the same rows and pose in every run.
    const core::State& s = plant_.state();
    double sn, c;
    sn = std::sin(s[core::THETA]);
    c = std::cos(s[core::THETA]);
    const Eigen::Vector2d p(s[core::X] + c * cfg_.tool.x() - sn * cfg_.tool.y(),
                            s[core::Y] + sn * cfg_.tool.x() + c * cfg_.tool.y());
    std::lock_guard<std::mutex> lock(mutex_);
    // The rule runs every step (its state must not depend on the hitch), as the in-process loop's
    // (closed_loop.h): the hitch only holds up a tool the rule would lower.
    const bool down = tool_.update(p);
    plant_.setToolDown(down && !tool_raised_);
    if (down && tool_raised_) tool_held_up_time_ += dt;
  }
  plant_.step(tau_right, tau_left, dt);
  ++steps_;
  max_slip_ = std::max({max_slip_, std::fabs(plant_.slipRatio(core::RIGHT)), std::fabs(plant_.slipRatio(core::LEFT))});
  max_draft_ = std::max(max_draft_, std::fabs(plant_.draftForce()));
  if (plant_.toolDown()) {
    tool_down_time_ += dt;
    min_depth_ = min_depth_ > 0.0 ? std::min(min_depth_, plant_.toolDepth()) : plant_.toolDepth();
  }
}

void TractionModel::publishVisuals(const ros::Time& stamp) {
  std_msgs::Float64MultiArray m;
  m.layout.dim.resize(1);
  // the stamp last (message_stamp.h): a deterministic bag records the array at it
  m.layout.dim[0].label =
      "slip_right,slip_left,force_right,force_left,draft_force,tool_down,patch_right,patch_left,stamp";
  m.layout.dim[0].size = 9;
  m.layout.dim[0].stride = 9;
  m.data = {plant_.slipRatio(core::RIGHT),
            plant_.slipRatio(core::LEFT),
            plant_.groundForce(core::RIGHT),
            plant_.groundForce(core::LEFT),
            plant_.draftForce(),
            plant_.toolDown() ? 1.0 : 0.0,
            static_cast<double>(plant_.patchUnder(core::RIGHT)),
            static_cast<double>(plant_.patchUnder(core::LEFT)),
            stamp.toSec()};
  slip_pub_.publish(m);
}

std::string TractionModel::report() const {
  char text[420];
  std::snprintf(
      text, sizeof text,
      "traction: max |slip ratio| %.4f over %ld steps; %zu soil patch(es); tool down %.2f s, held up by the hitch "
      "control %.2f s, max draft %.1f N (traction/draft_force %g N at %.1f cm); shallowest depth down %.1f cm",
      max_slip_, static_cast<long>(steps_), cfg_.soil.patches().size(), tool_down_time_, tool_held_up_time_, max_draft_,
      cfg_.traction.draft_force, 100.0 * cfg_.traction.draft_depth, 100.0 * min_depth_);
  std::lock_guard<std::mutex> lock(mutex_);
  return no_traction_.empty() ? std::string(text) : std::string(text) + "; no traction: " + no_traction_;
}

void TractionModel::publishSoil() {
  visualization_msgs::MarkerArray out;
  const auto& patches = cfg_.soil.patches();
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const core::SoilPatch& patch = patches[i];
    // Darker blue for less grip: wet soil.
    const float wet =
        static_cast<float>(1.0 - std::clamp(patch.mu_peak / std::max(cfg_.traction.mu_peak, 1e-9), 0.0, 1.0));
    visualization_msgs::Marker outline =
        rvizMarker(cfg_.odom_frame, "soil_outline", static_cast<int>(i),
                   {visualization_msgs::Marker::LINE_STRIP, 0.1f, 0.3f, 0.9f, 1.0f, 0.05});
    for (std::size_t k = 0; k <= patch.polygon.size(); ++k) {
      geometry_msgs::Point pt;
      pt.x = patch.polygon[k % patch.polygon.size()].x();
      pt.y = patch.polygon[k % patch.polygon.size()].y();
      outline.points.push_back(pt);
    }
    out.markers.push_back(outline);
    // Fill: a triangle fan from the first vertex (exact for convex patches; an outline is always exact).
    visualization_msgs::Marker fill = outline;
    fill.ns = "soil_fill";
    fill.type = visualization_msgs::Marker::TRIANGLE_LIST;
    fill.scale.x = fill.scale.y = fill.scale.z = 1.0;
    fill.color.r = 0.2f * (1.0f - wet);
    fill.color.g = 0.3f + 0.2f * (1.0f - wet);
    fill.color.b = 0.5f + 0.5f * wet;
    fill.color.a = 0.35f;
    fill.points.clear();
    for (std::size_t k = 1; k + 1 < patch.polygon.size(); ++k)
      for (std::size_t v : {std::size_t(0), k, k + 1}) {
        geometry_msgs::Point pt;
        pt.x = patch.polygon[v].x();
        pt.y = patch.polygon[v].y();
        pt.z = -0.01;
        fill.points.push_back(pt);
      }
    out.markers.push_back(fill);
    visualization_msgs::Marker label = outline;
    label.ns = "soil_label";
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.points.clear();
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& v : patch.polygon) c += v;
    c /= static_cast<double>(patch.polygon.size());
    label.pose.position.x = c.x();
    label.pose.position.y = c.y();
    label.pose.position.z = 0.3;
    label.scale.z = 0.3;
    label.color.r = label.color.g = label.color.b = 1.0f;
    char text[80];
    std::snprintf(text, sizeof text, "mu %.2g/%.2g rr %.2g", patch.mu_peak, patch.mu_slide, patch.rolling_resistance);
    label.text = text;
    out.markers.push_back(label);
  }
  soil_pub_.publish(out);
}

}  // namespace sowing_robot
