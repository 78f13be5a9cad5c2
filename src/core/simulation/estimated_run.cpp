#include "sowing_robot/core/simulation/estimated_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/tool_engagement.h"

namespace sowing_robot {
namespace core {

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

std::string EstimatedRunConfig::validate() const {
  std::string e = firstError({sensors.validate(), estimator.validate(), traction ? traction->validate() : ""});
  if (!e.empty()) return e;
  if (!allFinite(tool.x(), tool.y())) return "the tool point must be finite";
  for (std::size_t i = 0; i < patches.size(); ++i) {
    e = patches[i].validate("field/patches[" + std::to_string(i) + "]");
    if (!e.empty()) return e;
  }
  return "";
}

namespace {

/// The two plants behind one face: reset, step, state, the wheels' slip.
struct NoSlipPlant {
  Plant plant;
  void reset(const State& x0, double t0) { plant.reset(x0, t0); }
  void step(double r, double l, double dt) { plant.step(r, l, dt); }
  const State& state() const { return plant.state(); }
  double slip(Wheel) const { return 0.0; }
  TractionPlant* traction() { return nullptr; }
};

struct SlipPlant {
  TractionPlant plant;
  void reset(const State& x0, double t0) { plant.reset(x0, t0); }
  void step(double r, double l, double dt) { plant.step(r, l, dt); }
  const State& state() const { return plant.state(); }
  double slip(Wheel w) const { return plant.slipRatio(w); }
  TractionPlant* traction() { return &plant; }
};

Pose2D truePose(const State& s) { return {s[X], s[Y], s[THETA]}; }

/// The loop (see the header for its order); P: NoSlipPlant or SlipPlant.
template <typename P>
EstimatedRunResult loop(const Scenario& sc, const EstimatedRunConfig& cfg, P& plant, ReferenceSource& reference,
                        bool keep_samples, const std::function<void(const EstimatedSample&)>& trace) {
  std::unique_ptr<OuterController> outer = makeOuterController(sc);
  std::unique_ptr<InnerController> inner = makeInnerController(sc);
  plant.reset(startState(sc), phaseStartTime(sc));
  reference.reset();
  const std::int64_t n = sc.steps();
  const double dt = secondsFromNanos(sc.control_period_ns);

  // plant_sim's sensors (PlantSensors' constructor): encoders and gyro at the start state, the first fix
  // sampled at t = 0, the yaw rate measured once before the first period.
  EncoderOdometry encoders(cfg.sensors, sc.robot.R, sc.robot.L);
  YawRateSensor gyro(cfg.sensors);
  PositionFixSensor fix_sensor(cfg.sensors);
  {
    const State& s = plant.state();
    encoders.reset(truePose(s), s[PHI_R], s[PHI_L]);
    gyro.reset();
    fix_sensor.reset(0.0);
    fix_sensor.sample(0.0, truePose(s));
  }
  double yaw_rate = gyro.measure(plant.state()[OMEGA]);
  // What the messages carry: the gyro's variance (sensor_msgs/Imu), the fix's (PoseWithCovarianceStamped).
  const double rate_variance = cfg.sensors.imu.noise > 0.0 ? cfg.sensors.imu.noise * cfg.sensors.imu.noise : 0.0;
  const double fix_variance = cfg.sensors.fix.sigma * cfg.sensors.fix.sigma;
  // state_estimator's increment_covariance_: the encoders' quantisation per step, with the nominal half track.
  const Eigen::Matrix2d increment_covariance = encoderIncrementCovariance(cfg.estimator.increment_sigma, sc.robot.L);

  const bool fused = cfg.feedback == Feedback::fused;
  std::unique_ptr<Ekf> ekf;
  if (fused) ekf = std::make_unique<Ekf>(cfg.estimator);
  FixQueue queue(cfg.estimator.fix_delay);
  Pose2D last_odom;  // state_estimator's last_odom_, as poseOf reads it

  TractionPlant* traction = plant.traction();
  const bool draft = traction && cfg.traction && cfg.traction->draft_force > 0.0;
  ToolEngagement tool_rule(cfg.seeding, cfg.tool_rows, cfg.tool_rows_open_ended);

  MetricsAccumulator metrics(keep_samples);
  metrics.reserve(static_cast<std::size_t>(n + 1));
  EstimatedRunResult out;
  RunResult& result = out.run;
  double fed_sq = 0.0;
  std::int64_t fed_count = 0;

  for (std::int64_t k = 0; k <= n; ++k) {
    const double t = secondsFromNanos(k * sc.control_period_ns);
    const State& s = plant.state();
    if (!finiteSum(s)) {
      result.diverged = true;
      break;
    }
    const Pose2D truth{s[X], s[Y], yawThroughQuaternion(s[THETA])};
    // odom as published (the encoders' last update) and as a subscriber reads it back.
    const Odometry2D& odom = encoders.last();
    const Pose2D odom_pose{odom.pose.x, odom.pose.y, yawThroughQuaternion(odom.pose.theta)};
    out.odometry_error_final = std::hypot(odom.pose.x - s[X], odom.pose.y - s[Y]);
    out.odometry_error_max = std::max(out.odometry_error_max, out.odometry_error_final);

    Pose2D fed = truth;
    double fed_v = s[V], fed_omega = s[OMEGA];
    if (cfg.feedback == Feedback::odometry) {
      fed = odom_pose;
      fed_v = odom.v;
      fed_omega = odom.omega;
    } else if (fused) {
      // The fixes published at t_k (stamps on the nanosecond grid, as the header carries them), then
      // state_estimator's step on this period's odom and imu.
      for (const FixMeasurement& m : fix_sensor.due(t)) {
        EkfFix f;
        f.stamp = secondsFromNanos(static_cast<std::int64_t>(std::llround(m.stamp * 1e9)));
        f.xy = m.xy;
        f.covariance << fix_variance, 0.0, 0.0, fix_variance;
        queue.push(f);
      }
      if (!ekf->initialised()) {
        ekf->reset(t, odom_pose);
      } else {
        EkfStepInput in;
        in.dtheta = wrapAngle(odom_pose.theta - last_odom.theta);
        const double mid = last_odom.theta + 0.5 * in.dtheta;
        double s_mid, c_mid;
        s_mid = std::sin(mid);
        c_mid = std::cos(mid);
        in.distance = (odom_pose.x - last_odom.x) * c_mid + (odom_pose.y - last_odom.y) * s_mid;
        in.covariance = increment_covariance;
        in.has_rate = true;
        in.rate = yaw_rate;
        in.rate_variance = rate_variance;
        ekf->predict(t, in);  // refused only for a non-finite input: the estimate then stays
      }
      for (const EkfFix& f : queue.due(ekf->time())) ekf->fuse(f);
      last_odom = odom_pose;
      const Ekf::Vector& m = ekf->mean();
      fed = {m(Ekf::X), m(Ekf::Y), yawThroughQuaternion(m(Ekf::THETA))};
      fed_v = odom.v;
      fed_omega = yaw_rate - m(Ekf::BIAS);
    }
    const double fed_error = std::hypot(fed.x - s[X], fed.y - s[Y]);
    fed_sq += fed_error * fed_error;
    ++fed_count;
    out.fed_error_max = std::max(out.fed_error_max, fed_error);
    out.fed_heading_error_max = std::max(out.fed_heading_error_max, std::fabs(wrapAngle(fed.theta - s[THETA])));

    const Reference& ref = reference.next(t);
    double ex, ey, eth;
    worldErrors(ref, truth, ex, ey, eth);
    metrics.add(t, ex, ey, eth);
    const VelocityCommand cmd = outer->compute(ref, fed, fed_v, fed_omega);
    const InnerOutput u = inner->update(cmd, fed_v, fed_omega, dt);
    if (u.saturated) ++result.saturated_steps;
    // The plant's tool rule on the true tool point of the state this step starts from (TractionModel::step).
    bool tool_down = false;
    if (draft && k < n) {
      double sn, c;
      sn = std::sin(s[THETA]);
      c = std::cos(s[THETA]);
      const Eigen::Vector2d p(s[X] + c * cfg.tool.x() - sn * cfg.tool.y(), s[Y] + sn * cfg.tool.x() + c * cfg.tool.y());
      tool_down = tool_rule.update(p);
      traction->setToolDown(tool_down);
      if (tool_down) out.tool_down_time += dt;
    }
    if (trace) {
      const LoopSample sample{t, &s, &ref, &cmd, &u, inner->m0Hat(), inner->i0Hat(), ex, ey, eth};
      trace({&sample, fed, fed_v, fed_omega, plant.slip(RIGHT), plant.slip(LEFT), tool_down});
    }
    result.periods = k;
    if (k < n) {
      plant.step(u.torques.right, u.torques.left, dt);
      out.max_abs_slip = std::max({out.max_abs_slip, std::fabs(plant.slip(RIGHT)), std::fabs(plant.slip(LEFT))});
      // SimulatedPlant::step: the sensors on the new state, stamped on the grid.
      const State& s1 = plant.state();
      if (std::isfinite(s1.sum())) {
        encoders.update(s1[PHI_R], s1[PHI_L], dt);
        yaw_rate = gyro.measure(s1[OMEGA]);
        fix_sensor.sample(secondsFromNanos((k + 1) * sc.control_period_ns), truePose(s1));
      }
    }
  }
  closeRun(result, plant.state(), metrics);
  if (result.diverged) {
    const double inf = std::numeric_limits<double>::infinity();
    out.fed_error_rms = out.fed_error_max = inf;
  } else {
    out.fed_error_rms = fed_count > 0 ? std::sqrt(fed_sq / static_cast<double>(fed_count)) : 0.0;
  }
  if (ekf) out.fixes = ekf->counts();
  out.fixes_lost_from_queue = queue.dropped();
  return out;
}

}  // namespace

EstimatedRunResult runEstimatedLoop(const Scenario& sc, const EstimatedRunConfig& cfg, ReferenceSource& reference,
                                    bool keep_samples, const std::function<void(const EstimatedSample&)>& trace) {
  const std::string e = firstError({sc.validate(), cfg.validate()});
  if (!e.empty()) throw std::invalid_argument(e);
  if (!cfg.traction) {
    NoSlipPlant plant{Plant(sc.robot, sc.disturbance)};
    return loop(sc, cfg, plant, reference, keep_samples, trace);
  }
  SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, *cfg.traction)};
  plant.plant.setSoil(SoilMap(cfg.patches));
  plant.plant.setToolPoint(cfg.tool);
  return loop(sc, cfg, plant, reference, keep_samples, trace);
}

}  // namespace core
}  // namespace sowing_robot
