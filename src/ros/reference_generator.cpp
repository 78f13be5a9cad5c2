#include "sowing_robot/ros/reference_generator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/coverage_follower.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/field_file/field_file.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/markers.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/reconfigure_bridge.h"

namespace sowing_robot {

ReferenceGenerator::ReferenceGenerator(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::ReferenceGeneratorSettings settings;
  loadTable(p, core::ReferenceGeneratorSettings::table(), settings);
  core::SpeedGovernorParams governor;  // speed_governor/...: off by default
  loadTable(p, core::speedGovernorTable(), governor);
  std::string error = core::firstError({settings.validate(), governor.validate()});
  // The governor acts on the traction control's verdicts: without it none would come (in lockstep the loop
  // would wait for them), so it is refused, as the in-process loop refuses it (LoopConfig::validate).
  bool traction_control = false;
  nh.param("torque_controller/traction_control/enabled", traction_control, false);
  if (error.empty() && governor.enabled && !traction_control)
    error = pnh.resolveName("speed_governor/enabled") + " needs " +
            nh.resolveName("torque_controller/traction_control/enabled") +
            " (the governor acts on the traction control's slip verdicts)";
  // The field and its obstacles are read only with type field: with type line they are refused like
  // unknown keys (a field file without `type: field` must not quietly run the line).
  using Type = core::ReferenceGeneratorSettings::Type;
  core::FieldParams field;
  std::vector<core::Obstacle> obstacles;
  core::PathParams path;
  std::vector<Eigen::Vector2d> path_points;
  CoverageRoute coverage;
  if (settings.type == Type::kPath) {
    loadTable(p, core::pathTable(), path);
    if (error.empty()) error = loadPathPoints(p, path_points);
    if (error.empty() && p.error().empty()) error = path.validate();
  }
  if (settings.type == Type::kField) {
    const std::string plan_error = loadFieldPlan(p, nh, run.start(), field, obstacles);
    if (error.empty()) error = plan_error;
  } else {
    // Said before the unknown-key list (which would only name the key): why it is not read. Type coverage reads the
    // field's speeds (its other field/ keys are refused as unknown).
    for (const char* key : {"field", "potential", "obstacles"})
      if (pnh.hasParam(key) && !(settings.type == Type::kCoverage && std::string(key) == "field"))
        p.fail(pnh.resolveName(key) +
               " is set but type is not 'field': field, potential and obstacles are read only "
               "with type: field (set " +
               pnh.resolveName("type") + ": field, or remove them)");
  }
  if (settings.type == Type::kCoverage) {
    // Planned here, before the unknown-key check ends the start-up: a field that cannot be planned is a bad
    // parameter, said in one line (the file's name and what is wrong with it).
    const std::string plan_error = loadCoverageRoute(p, nh, settings, coverage);
    if (error.empty()) error = plan_error;
  } else {
    for (const char* key : {"coverage", "field_file", "field_origin", "fleet"})
      if (pnh.hasParam(key) &&
          !(std::string(key) != "coverage" && std::string(key) != "fleet" && pnh.param<std::string>(key, "").empty()))
        p.fail(pnh.resolveName(key) + " is set but type is not 'coverage': coverage/, fleet/, field_file and " +
               "field_origin are read only with type: coverage (set " + pnh.resolveName("type") +
               ": coverage, or remove them)");
  }
  if (settings.type != Type::kPath && pnh.hasParam("path"))
    p.fail(pnh.resolveName("path") + " is set but type is not 'path': path/ is read only with type: path (set " +
           pnh.resolveName("type") + ": path, or remove it)");
  requireValid(p, error);
  odom_frame_ = run.odom_frame;
  period_ns_ = run.periodNs();
  lookahead_ = settings.lookahead;
  path_spacing_ = settings.path_spacing;
  window_ns_ = std::llround(lookahead_ * 1e9);
  lockstep_ = run.lockstep;
  logSettings("reference_generator", core::ReferenceGeneratorSettings::table(), settings);
  logSettings("reference_generator", core::speedGovernorTable(), governor);
  core::PathReference* path_source = nullptr;
  if (settings.type == Type::kLine) {
    source_ = std::make_unique<core::LineReference>(settings.line_v_r, settings.line_y, settings.line_x0);
  } else if (settings.type == Type::kPath) {
    std::unique_ptr<core::PathReference> f;
    try {
      f = std::make_unique<core::PathReference>(path, run.start(), path_points);
    } catch (const std::invalid_argument& e) {
      throw badParameter(e.what());
    }
    path_source = f.get();
    source_ = std::move(f);
    logSettings("reference_generator", core::pathTable(), path);
  } else if (settings.type == Type::kCoverage) {
    std::unique_ptr<core::PathReference> f;
    try {
      f = std::make_unique<core::PathReference>(coverage.follower, coverage.start, coverage.path.points,
                                                coverage.path.tool_down);
    } catch (const std::invalid_argument& e) {
      throw badParameter(settings.field_file + ": " + e.what());
    }
    path_source = f.get();
    const core::CoveragePlan& plan = coverage.plan;
    logSettings("reference_generator", core::coverageTable(), coverage.coverage);
    logSettings("reference_generator", coverageFieldSpeedsTable(), coverage.field);
    ROS_INFO(
        "reference_generator: %s planned: %zu swath(s) in %d part(s) at heading %.3f rad, %zu headland ring(s) "
        "with %zu headland row(s), route %.1f m (%.1f m tool up); the robot starts at (%.3f, %.3f, %.3f)%s",
        settings.field_file.c_str(), plan.swaths.size(), plan.parts, plan.heading, plan.headland_rings.size(),
        plan.headland_rows.size(), plan.path_length, plan.turn_length, coverage.start.x, coverage.start.y,
        coverage.start.theta, coverage.fleet.robots == 0 ? ", the route's start" : "");
    if (coverage.fleet.robots == 0) {
      source_ = std::move(f);
      coverage_rows_ = plan.rows();
    } else {
      logSettings("reference_generator", core::fleetShareTable(), coverage.fleet);
      const core::RobotShare& own = coverage.share.own();
      const core::FleetPlan& fleet = coverage.share.fleet;
      ROS_INFO(
          "reference_generator: robot %d of %d: share rank %d, swaths %d-%d, %zu headland loop(s), path %.1f m in "
          "%.1f s planned, after a planned wait of %.1f s; the fleet's plan: makespan %.1f s, %d wait(s) added, "
          "%s, closest planned %.2f m",
          coverage.fleet.index, coverage.fleet.robots, own.rank, own.first_swath, own.first_swath + own.swaths - 1,
          own.loops.size(), own.timed.length(), own.timed.duration(), own.wait, fleet.makespan(), fleet.waits_added,
          !coverage.fleet.keep_apart ? "not kept apart (fleet/keep_apart false)"
          : fleet.conflict_free      ? "conflict-free"
                                     : "conflicts left",
          fleet.check.min_separation);
      fleet_rank_ = own.rank;
      for (int i = 0; i < own.swaths; ++i)
        for (const core::RowSegment& r : plan.swaths[static_cast<std::size_t>(own.first_swath + i)].rows)
          coverage_rows_.push_back(r);
      auto shared = std::make_unique<core::FleetShareReference>(std::move(f), own.wait, coverage.fleet.ramp_time);
      fleet_ = shared.get();
      path_source = const_cast<core::PathReference*>(&fleet_->path());
      source_ = std::move(shared);
    }
  } else {
    std::unique_ptr<core::FieldSource> f;
    try {
      f = core::makeFieldSource(field, obstacles);
    } catch (const std::invalid_argument& e) {
      throw badParameter(e.what());
    }
    field_ = f.get();
    potential_ = dynamic_cast<core::FieldReference*>(field_);
    if (auto* as_path = dynamic_cast<core::FieldPathReference*>(field_)) path_source = &as_path->follower();
    obstacles_ = obstacles;
    source_ = std::move(f);
    logSettings("reference_generator", core::fieldTable(), field);
    ROS_INFO(
        "reference_generator: footprint circumscribed radius %.3f m (URDF collision geometry): obstacles "
        "are inflated by it + field/avoidance/safety_margin",
        field.avoidance.footprint_radius);
    ROS_INFO("reference_generator: field path %.3f m in %.3f s%s", field_->path().length(), field_->duration(),
             field.rows > 1 ? (field_->path().turn().isBulb() ? ", bulb turns" : ", rounded turns") : "");
    for (std::size_t i = 0; i < obstacles_.size(); ++i)
      ROS_INFO("reference_generator: obstacle %zu at (%.3f, %.3f), radius %.3f m", i, obstacles_[i].x, obstacles_[i].y,
               obstacles_[i].radius);
  }
  if (governor.enabled) {  // validated above: the constructor does not throw
    auto governed = std::make_unique<core::GovernedReference>(std::move(source_), governor);
    governor_ = governed.get();
    source_ = std::move(governed);
  }
  if (potential_) {
    ros::NodeHandle potential(pnh, "potential");
    reconfigure_ = std::make_unique<ReconfigureServer<ReferenceGeneratorConfig>>(potential);
    // The server would start from the .cfg defaults where a key is not set: hand it the gains in force.
    ReferenceGeneratorConfig in_force;
    toConfig(core::potentialFieldTable(), field.potential, in_force);
    reconfigure_->server.updateConfig(in_force);
    reconfigure_->server.setCallback([this](ReferenceGeneratorConfig& c, uint32_t level) { reconfigure(c, level); });
  }
  // A subscriber that connects late (a restarted controller) is sent the references already out for
  // the times still ahead: the loop may be waiting for one of them.
  ref_pub_ = nh.advertise<ReferenceState>(
      "reference", kLockstepQueue, [this](const ros::SingleSubscriberPublisher& sub) { replayTo(sub); },
      ros::SubscriberStatusCallback());
  path_pub_ = nh.advertise<nav_msgs::Path>("reference_path", 1, true);
  path_ = std::make_unique<PathBuffer>(odom_frame_, path_spacing_, 10);  // re-sent every 10th point
  plan_pub_ = nh.advertise<FieldPlan>("plan", 1, true);
  if (field_) {
    marker_pub_ = nh.advertise<visualization_msgs::MarkerArray>("field_markers", 1, true);
    obstacles_sub_ = nh.subscribe("obstacles", 10, &ReferenceGenerator::obstaclesCallback, this);
  } else if (!path_source) {
    line_ = {settings.line_x0, settings.line_y};
  }
  if (path_source)
    path_follower_ = std::make_unique<PathFollower>(nh, pnh, *path_source, odom_frame_,
                                                    field_                             ? "the field's rows and turns"
                                                    : settings.type == Type::kCoverage ? "the coverage plan"
                                                                                       : "path/points");
  // The field file's local frame is the odom frame (the world-fixed frame of this simulation: there is no map).
  if (settings.type == Type::kCoverage)
    coverage_topics_ = std::make_unique<CoverageTopics>(nh, coverage.plan, coverage.path, odom_frame_);
  publishPlan();
  std::vector<ros::Subscriber> inputs;
  if (fleet_ && coverage.fleet.yield) {
    yield_ = true;
    fleet_index_ = coverage.fleet.index;
    decision_ns_ = std::llround(coverage.fleet.decision_period * 1e9);
    if (decision_ns_ % period_ns_ != 0)
      throw badParameter(pnh.resolveName("fleet/decision_period") + " must be a multiple of the control period (" +
                         std::to_string(core::secondsFromNanos(period_ns_)) + " s)");
    status_.header.frame_id = odom_frame_;
    status_.rank = fleet_rank_;
    // Latched both ways: a verdict or a status sent before the other end had connected is not lost (the next one
    // cannot come before it has been used).
    status_pub_ = nh.advertise<FleetRobotStatus>("fleet/status", 1, true);
    verdict_sub_ = nh.subscribe("/fleet/verdict", kLockstepQueue, &ReferenceGenerator::verdictCallback, this,
                                ros::TransportHints().tcpNoDelay());
    truth_sub_ = nh.subscribe("ground_truth", kLockstepQueue, &ReferenceGenerator::truthCallback, this,
                              ros::TransportHints().tcpNoDelay());
    inputs.push_back(truth_sub_);  // the plant must not step past a state this node has not seen
    ROS_INFO(
        "reference_generator: fleet yield on: every %.3f s of simulated time the references wait for the fleet's "
        "verdict (%s) on this robot's state (%s)",
        coverage.fleet.decision_period, verdict_sub_.getTopic().c_str(), status_pub_.getTopic().c_str());
  }
  clock_sub_ = nh.subscribe("/clock", 10, &ReferenceGenerator::clockCallback, this, ros::TransportHints().tcpNoDelay());
  if (governor_) {
    traction_sub_ = nh.subscribe("traction_control/state", kLockstepQueue, &ReferenceGenerator::tractionCallback, this,
                                 ros::TransportHints().tcpNoDelay());
    ROS_INFO("reference_generator: speed governor on %s%s", traction_sub_.getTopic().c_str(),
             lockstep_ ? ": each reference waits for the verdict of the period before it" : "");
  }
  ROS_INFO(
      "reference_generator: references on a %.6f s grid (run/control_rate), sent %.3f s ahead of /clock "
      "(lookahead)",
      core::secondsFromNanos(period_ns_), lookahead_);
  // last: all subscribed (ready_roster.h). The references replay to late subscribers and the verdicts are latched:
  // only /clock's link is awaited.
  inputs.push_back(clock_sub_);
  ready_ = ReadyAnnouncer(nh, pnh, lockstep_, inputs);
}

void ReferenceGenerator::obstaclesCallback(const visualization_msgs::MarkerArray::ConstPtr& msg) {
  using visualization_msgs::Marker;
  std::vector<core::Obstacle> obstacles;
  for (const Marker& m : msg->markers) {
    if (m.type != Marker::CYLINDER || m.action != Marker::ADD) continue;
    if (!m.header.frame_id.empty() && m.header.frame_id != odom_frame_) {
      ROS_WARN_THROTTLE(1.0, "reference_generator: dropping obstacles message: marker %s/%d is in frame '%s', not %s",
                        m.ns.c_str(), m.id, m.header.frame_id.c_str(), odom_frame_.c_str());
      return;
    }
    core::Obstacle o;
    o.x = m.pose.position.x;
    o.y = m.pose.position.y;
    o.radius = 0.5 * m.scale.x;
    const std::string e = o.validate();
    if (!e.empty()) {
      ROS_WARN_THROTTLE(1.0, "reference_generator: dropping obstacles message: marker %s/%d: %s", m.ns.c_str(), m.id,
                        e.c_str());
      return;
    }
    obstacles.push_back(o);
  }
  try {
    field_->setObstacles(obstacles);
  } catch (const std::invalid_argument& e) {
    ROS_WARN_THROTTLE(1.0, "reference_generator: dropping obstacles message: %s", e.what());
    return;
  }
  obstacles_ = std::move(obstacles);
  ROS_INFO("reference_generator: %zu obstacle(s) in force now", obstacles_.size());
  if (path_follower_) path_follower_->replaced("the field re-planned round the obstacles");
  publishPlan();
}

void ReferenceGenerator::reportStatus() {
  const core::AvoidanceStatus& s = field_->status();
  if (s.code == core::AvoidanceStatus::Code::kOk)
    ROS_INFO("reference_generator: plan ok, %zu detour(s)", s.detours);
  else
    ROS_WARN("reference_generator: plan %s: %s; the reference stops at (%.3f, %.3f)",
             core::AvoidanceStatus::name(s.code), s.reason.c_str(), s.stop_point.x(), s.stop_point.y());
  if (!s.within_bounds) ROS_WARN("reference_generator: plan outside its bounds: %s", s.bounds_note.c_str());
}

void ReferenceGenerator::publishPlan() {
  if (field_) reportStatus();
  FieldPlan plan;
  plan.header.frame_id = odom_frame_;
  plan.header.stamp = ros::Time::now();
  auto point = [](const Eigen::Vector2d& p) {
    geometry_msgs::Point q;
    q.x = p.x();
    q.y = p.y();
    return q;
  };
  if (field_) {
    for (const core::RowSegment& r : core::rowsOf(field_->params())) {
      plan.row_starts.push_back(point(r.a));
      plan.row_ends.push_back(point(r.b));
    }
    for (const core::Obstacle& o : obstacles_) {
      plan.obstacle_centres.push_back(point(Eigen::Vector2d(o.x, o.y)));
      plan.obstacle_radii.push_back(o.radius);
    }
    plan.influence_distance = field_->params().potential.influence_distance;
    const core::AvoidanceStatus& s = field_->status();
    plan.status = core::AvoidanceStatus::name(s.code);
    plan.reason = s.code == core::AvoidanceStatus::Code::kOk ? s.bounds_note : s.reason;
    plan.within_bounds = s.within_bounds;
    plan.detours = static_cast<std::uint32_t>(s.detours);
  } else if (!coverage_rows_.empty()) {  // type coverage: the swaths' and headland rows; the voids are not obstacles
    for (const core::RowSegment& r : coverage_rows_) {
      plan.row_starts.push_back(point(r.a));
      plan.row_ends.push_back(point(r.b));
    }
    plan.status = "ok";
    plan.within_bounds = true;
  } else if (!path_follower_) {  // type line (type path: no rows, no obstacles)
    plan.row_starts.push_back(point(line_));
    plan.row_ends.push_back(point(line_ + Eigen::Vector2d(1e5, 0.0)));  // the thesis line, open-ended
    plan.open_ended = true;
  }
  plan_pub_.publish(plan);
  if (field_) publishMarkers();
}

void ReferenceGenerator::publishMarkers() {
  using visualization_msgs::Marker;
  visualization_msgs::MarkerArray out;
  out.markers.push_back(deleteAllMarker(odom_frame_));
  const double d = field_->params().potential.influence_distance;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const core::Obstacle& o = obstacles_[i];
    const double body_d = 2.0 * o.radius, zone_d = 2.0 * (o.radius + d);
    Marker body = rvizMarker(odom_frame_, "obstacles", static_cast<int>(i),
                             {Marker::CYLINDER, 0.55f, 0.35f, 0.17f, 1.0f, body_d, body_d, 0.5});
    body.pose.position.x = o.x;
    body.pose.position.y = o.y;
    body.pose.position.z = 0.25;
    out.markers.push_back(body);
    Marker zone = rvizMarker(odom_frame_, "influence_zones", static_cast<int>(i),
                             {Marker::CYLINDER, 1.0f, 0.6f, 0.0f, 0.25f, zone_d, zone_d, 0.02});
    zone.pose.position.x = o.x;
    zone.pose.position.y = o.y;
    zone.pose.position.z = 0.01;
    if (potential_) out.markers.push_back(zone);  // the path follower has no repulsion: no zone to show
  }
  Marker rows = rvizMarker(odom_frame_, "rows", 0, {Marker::LINE_LIST, 0.1f, 0.8f, 0.1f, 1.0f, 0.03});
  for (const core::RowSegment& r : core::rowsOf(field_->params())) {
    geometry_msgs::Point pa, pb;
    pa.x = r.a.x();
    pa.y = r.a.y();
    pb.x = r.b.x();
    pb.y = r.b.y();
    rows.points.push_back(pa);
    rows.points.push_back(pb);
  }
  out.markers.push_back(rows);
  marker_pub_.publish(out);
}

void ReferenceGenerator::reconfigure(ReferenceGeneratorConfig& config, uint32_t) {
  const core::PotentialFieldParams old = potential_->potentialField().params();
  try {
    potential_->setGains(config.alpha, config.beta, config.gain, config.tangential_ratio);
  } catch (const std::invalid_argument& e) {
    ROS_WARN("reference_generator: rejected gain change: %s; keeping alpha %g, beta %g, gain %g, tangential_ratio %g",
             e.what(), old.alpha, old.beta, old.gain, old.tangential_ratio);
    toConfig(core::potentialFieldTable(), old, config);  // the server then reports the values in force
    return;
  }
  ROS_INFO("reference_generator: potential gains now alpha %g, beta %g, gain %g, tangential_ratio %g", config.alpha,
           config.beta, config.gain, config.tangential_ratio);
}

void ReferenceGenerator::fill(ReferenceState& out, const ros::Time& stamp) {
  const core::Reference r = source_->next(stamp.toSec());
  out.header.stamp = stamp;
  out.header.frame_id = odom_frame_;
  out.x = r.pose.x;
  out.y = r.pose.y;
  out.theta = r.pose.theta;
  out.v = r.v;
  out.omega = r.omega;
  out.v_dot = r.v_dot;
  out.omega_dot = r.omega_dot;
  out.tool_down = r.tool_down;
  out.stop = r.stop;
}

void ReferenceGenerator::clockCallback(const rosgraph_msgs::Clock::ConstPtr& msg) {
  const std::int64_t now = static_cast<std::int64_t>(msg->clock.toNSec());
  if (clock_seen_ && now < last_clock_ns_) {
    ROS_ERROR(
        "reference_generator: simulated time went back from %.6f s to %.6f s: references already sent are "
        "not sent again (the potential field integrates forward); restart this node with the plant",
        1e-9 * last_clock_ns_, 1e-9 * now);
    last_clock_ns_ = now;
    return;
  }
  if (now % period_ns_ != 0 && !grid_warned_) {
    grid_warned_ = true;
    ROS_ERROR(
        "reference_generator: /clock at t=%.9f s is not on the %.6f s grid of control_rate (%.3f Hz): it "
        "must equal plant_sim's, or the controllers wait for references stamped at times never sent",
        msg->clock.toSec(), core::secondsFromNanos(period_ns_), 1e9 / period_ns_);
  }
  // The window must outlast the gap to the next /clock, or the loop would wait for a reference that only
  // that /clock (which needs the loop to advance) would release: at least twice the largest gap seen.
  // (Should a gap still exceed it, plant_sim re-sends /clock with the state it is stuck at.)
  if (clock_seen_ && now > last_clock_ns_ && 2 * (now - last_clock_ns_) > window_ns_) {
    window_ns_ = 2 * (now - last_clock_ns_);
    ROS_WARN(
        "reference_generator: /clock comes every %.3f s of simulated time: references now sent %.3f s ahead "
        "(lookahead %.3f s)",
        1e-9 * (now - last_clock_ns_), 1e-9 * window_ns_, lookahead_);
  }
  clock_seen_ = true;
  last_clock_ns_ = now;
  // Forget what is behind simulated time (a late subscriber needs only the references still ahead).
  while (!sent_.empty() && static_cast<std::int64_t>(sent_.front().header.stamp.toNSec()) < now) sent_.pop_front();
  if (next_ns_ < 0 || next_ns_ < now - now % period_ns_) next_ns_ = now - now % period_ns_;  // start or jump
  sendUpTo(now + window_ns_);
}

void ReferenceGenerator::tractionCallback(const TractionControlState::ConstPtr& msg) {
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  if (stamp <= verdict_ns_) return;  // a repeat (the latched one again) or older: already reported
  if (lockstep_ && verdict_ns_ >= 0 && stamp != verdict_ns_ + period_ns_)
    ROS_ERROR(
        "reference_generator: traction-control verdicts missing between t = %.6f s and %.6f s: the governed "
        "reference no longer repeats the in-process loop's",
        1e-9 * verdict_ns_, 1e-9 * stamp);
  governor_->report(msg->slipping, msg->limiting, core::secondsFromNanos(period_ns_));
  verdict_ns_ = stamp;
  if (clock_seen_) sendUpTo(last_clock_ns_ + window_ns_);
}

void ReferenceGenerator::sendUpTo(std::int64_t end) {
  // The governed reference at t_{k+1} needs the verdict of period k (lockstep: wait for it, never guess).
  if (governor_ && lockstep_) end = std::min(end, verdict_ns_ < 0 ? 0 : verdict_ns_ + period_ns_);
  // The references after a decision stamp wait for the fleet's verdict on it (lockstep and realtime alike: the
  // verdict needs every robot's state at the stamp, which needs no reference past it).
  if (yield_) end = std::min(end, fleet_verdict_ns_ < 0 ? 0 : fleet_verdict_ns_ + decision_ns_);
  for (; next_ns_ <= end; next_ns_ += period_ns_) {
    ros::Time stamp;
    stamp.fromNSec(static_cast<std::uint64_t>(next_ns_));
    sent_.emplace_back();
    ReferenceState& r = sent_.back();
    fill(r, stamp);
    if (path_follower_) path_follower_->referenceSent(next_ns_);
    if (yield_ && next_ns_ % decision_ns_ == 0) {
      if (status_ns_ != next_ns_) {
        status_ns_ = next_ns_;
        status_truth_ = false;
      }
      status_ref_ = true;
      status_.header.stamp = stamp;
      status_.progress = fleet_->progress();
      status_.started = fleet_->started();
      status_.standing = fleet_->standing();
      publishStatus();
    }
    publishShared(ref_pub_, r);
    geometry_msgs::PoseStamped p;
    p.header = r.header;
    p.pose.position.x = r.x;
    p.pose.position.y = r.y;
    p.pose.orientation = yawQuaternion(r.theta);
    if (path_->add(p)) path_pub_.publish(path_->path());
  }
}

void ReferenceGenerator::truthCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  if (stamp % decision_ns_ != 0 || stamp < status_ns_ || (stamp == status_ns_ && status_truth_)) return;
  if (stamp != status_ns_) {  // the state came before its reference was sent
    status_ns_ = stamp;
    status_ref_ = false;
  }
  status_truth_ = true;
  status_.x = msg->pose.pose.position.x;
  status_.y = msg->pose.pose.position.y;
  publishStatus();
}

void ReferenceGenerator::publishStatus() {
  if (!status_ref_ || !status_truth_) return;
  status_pub_.publish(status_);
  status_ref_ = status_truth_ = false;
}

void ReferenceGenerator::verdictCallback(const FleetVerdict::ConstPtr& msg) {
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  if (stamp <= fleet_verdict_ns_) return;  // the latched one again, or older
  if (static_cast<std::size_t>(fleet_index_) >= msg->hold.size()) {
    ROS_ERROR_THROTTLE(1.0, "reference_generator: fleet verdict at t = %.3f s has %zu robot(s), not robot %d: ignored",
                       msg->header.stamp.toSec(), msg->hold.size(), fleet_index_);
    return;
  }
  if (fleet_verdict_ns_ >= 0 && stamp != fleet_verdict_ns_ + decision_ns_)
    ROS_ERROR("reference_generator: fleet verdicts missing between t = %.3f s and %.3f s", 1e-9 * fleet_verdict_ns_,
              1e-9 * stamp);
  const bool hold = msg->hold[static_cast<std::size_t>(fleet_index_)];
  if (hold != fleet_->hold())
    ROS_INFO("reference_generator: the fleet says %s at t = %.3f s", hold ? "hold (yield)" : "go on",
             msg->header.stamp.toSec());
  fleet_->setHold(hold);
  fleet_verdict_ns_ = stamp;
  if (clock_seen_) sendUpTo(last_clock_ns_ + window_ns_);
}

void ReferenceGenerator::replayTo(const ros::SingleSubscriberPublisher& sub) {
  for (const ReferenceState& r : sent_) sub.publish(r);
}

}  // namespace sowing_robot
