#include "sowing_robot/core/planning/approach.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sowing_robot {
namespace core {

namespace {
constexpr double kOnRowDistance = 1e-3;  ///< a start this close to the row start needs no approach [m]
constexpr double kOnRowHeading = 1e-3;   ///< ... and heading this close to the row's [rad]
constexpr double kMaxHeading = 1.4;      ///< |psi0| above this (80 deg) has no lateral-offset approach [rad]
constexpr double kMinSpan = 0.1;         ///< shortest approach along the row [m]
constexpr int kPeakSamples = 800;        ///< samples of the curvature when sizing the approach
constexpr double kNodeStep = 0.01;       ///< along-row spacing of the arc-length table [m]

// 5-point Gauss-Legendre on [0, 1].
constexpr double kGaussX[5] = {0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155, 0.95308992296933200};
constexpr double kGaussW[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444, 0.23931433524968324,
                               0.11846344252809454};

/// Septic Hermite bases on t in [0, 1] and their first three t-derivatives: h0 (value 1 -> 0), h1
/// (slope 1 -> 0), both with zero second and third derivatives at the ends, so the curvature is 0 and
/// its rate continuous (0) where the approach leaves the start and joins the row.
void bases(double t, double h0[4], double h1[4]) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t, t6 = t5 * t, t7 = t6 * t;
  h0[0] = 1.0 - 35.0 * t4 + 84.0 * t5 - 70.0 * t6 + 20.0 * t7;
  h0[1] = -140.0 * t3 + 420.0 * t4 - 420.0 * t5 + 140.0 * t6;
  h0[2] = -420.0 * t2 + 1680.0 * t3 - 2100.0 * t4 + 840.0 * t5;
  h0[3] = -840.0 * t + 5040.0 * t2 - 8400.0 * t3 + 4200.0 * t4;
  h1[0] = t - 20.0 * t4 + 45.0 * t5 - 36.0 * t6 + 10.0 * t7;
  h1[1] = 1.0 - 80.0 * t3 + 225.0 * t4 - 216.0 * t5 + 70.0 * t6;
  h1[2] = -240.0 * t2 + 900.0 * t3 - 1080.0 * t4 + 420.0 * t5;
  h1[3] = -480.0 * t + 2700.0 * t2 - 4320.0 * t3 + 2100.0 * t4;
}

void lateralOf(double l0, double m0, double span, double x, double& y, double& y1, double& y2, double& y3) {
  double h0[4], h1[4];
  bases(std::clamp(x / span, 0.0, 1.0), h0, h1);
  y = l0 * h0[0] + m0 * span * h1[0];
  y1 = (l0 * h0[1] + m0 * span * h1[1]) / span;
  y2 = (l0 * h0[2] + m0 * span * h1[2]) / (span * span);
  y3 = (l0 * h0[3] + m0 * span * h1[3]) / (span * span * span);
}

/// Curvature and dkappa/ds of the offset curve from its lateral derivatives.
void curvatureOf(double y1, double y2, double y3, double& k, double& dk) {
  const double q = 1.0 + y1 * y1, sq = std::sqrt(q);
  k = y2 / (q * sq);
  dk = (y3 / (q * sq) - 3.0 * y1 * y2 * y2 / (q * q * sq)) / sq;
}

void peaksOf(double l0, double m0, double span, double& pk, double& pdk) {
  pk = pdk = 0.0;
  for (int i = 0; i <= kPeakSamples; ++i) {
    double y, y1, y2, y3, k, dk;
    lateralOf(l0, m0, span, span * i / kPeakSamples, y, y1, y2, y3);
    curvatureOf(y1, y2, y3, k, dk);
    pk = std::max(pk, std::fabs(k));
    pdk = std::max(pdk, std::fabs(dk));
  }
}

std::string fmt(const char* f, double a, double b = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), f, a, b);
  return buf;
}
}  // namespace

ApproachCurve::ApproachCurve(const Eigen::Vector2d& p0, double heading, double a0, double l0, double psi0, double span)
    : p0_(p0),
      u_(unitVector(heading)),
      n_(-u_.y(), u_.x()),
      heading_(heading),
      a0_(a0),
      l0_(l0),
      m0_(std::tan(psi0)),
      span_(span) {
  peaksOf(l0_, m0_, span_, peak_k_, peak_dk_);
  const int nodes = std::max(1, static_cast<int>(std::ceil(span_ / kNodeStep)));
  node_step_ = span_ / nodes;
  arc_.assign(nodes + 1, 0.0);
  for (int i = 0; i < nodes; ++i) arc_[i + 1] = arc_[i] + arcIntegral(i * node_step_, (i + 1) * node_step_);
  length_ = arc_.back();
}

void ApproachCurve::lateral(double x, double& y, double& y1, double& y2, double& y3) const {
  lateralOf(l0_, m0_, span_, x, y, y1, y2, y3);
}

double ApproachCurve::arcIntegral(double xa, double xb) const {
  double sum = 0.0;
  for (int i = 0; i < 5; ++i) {
    double y, y1, y2, y3;
    lateral(xa + kGaussX[i] * (xb - xa), y, y1, y2, y3);
    sum += kGaussW[i] * std::sqrt(1.0 + y1 * y1);
  }
  return (xb - xa) * sum;
}

void ApproachCurve::evaluate(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const {
  if (arc_.empty()) {
    p = p0_;
    theta = heading_;
    kappa = dkappa = 0.0;
    return;
  }
  s = std::clamp(s, 0.0, length_);
  // The node interval holding s, then Newton on x (ds/dx = sqrt(1 + y'^2) >= 1, so it converges fast).
  const std::size_t i = std::min<std::size_t>(
      arc_.size() - 2, static_cast<std::size_t>(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin()) - 1);
  const double xa = i * node_step_, xb = xa + node_step_;
  double x = xa + (s - arc_[i]) / (arc_[i + 1] - arc_[i]) * node_step_;
  double y, y1, y2, y3;
  for (int it = 0; it < 4; ++it) {
    lateral(x, y, y1, y2, y3);
    x = std::clamp(x - (arc_[i] + arcIntegral(xa, x) - s) / std::sqrt(1.0 + y1 * y1), xa, xb);
  }
  lateral(x, y, y1, y2, y3);
  p = p0_ + (a0_ + x) * u_ + y * n_;
  theta = heading_ + std::atan(y1);
  curvatureOf(y1, y2, y3, kappa, dkappa);
}

ApproachPlan planApproach(const Eigen::Vector2d& p0, double heading, const Pose2D& start, const ApproachLimits& lim,
                          const std::vector<Obstacle>& obstacles) {
  ApproachPlan plan;
  const Eigen::Vector2d u = unitVector(heading), n(-u.y(), u.x());
  const Eigen::Vector2d d = Eigen::Vector2d(start.x, start.y) - p0;
  const double a0 = d.dot(u), l0 = d.dot(n), psi0 = wrapAngle(start.theta - heading);
  if (d.norm() <= kOnRowDistance && std::fabs(psi0) <= kOnRowHeading) return plan;
  plan.needed = true;
  if (std::fabs(psi0) > kMaxHeading) {
    plan.why = fmt("the start heading is %.2f rad off the row's (at most %.2f for an approach)", psi0, kMaxHeading);
    return plan;
  }
  const double room = lim.join_limit - std::max(a0, 0.0);
  if (room <= kMinSpan) {
    plan.why = fmt("the start lies %.2f m along the row, with no room to join it before %.2f m", a0, lim.join_limit);
    return plan;
  }
  // Driven at row speed where the curvature allows; the shortest span that keeps it within bounds.
  const double vr = lim.row_speed;
  const double k_row = std::min({lim.max_curvature, lim.max_yaw_rate / vr, lim.max_lateral_accel / (vr * vr)});
  const double m0 = std::tan(psi0);
  auto fits = [&](double span, double k_max) {
    double pk, pdk;
    peaksOf(l0, m0, span, pk, pdk);
    return pk <= k_max && pdk <= lim.max_curvature_rate;
  };
  const double lo_span = std::max(kMinSpan, -a0);  // the join lies on the row, not before its start
  double span = lo_span;
  if (!fits(span, k_row)) {
    double lo = span, hi = 2.0 * span;
    while (!fits(hi, k_row) && hi < 1e4) lo = hi, hi *= 2.0;
    for (int it = 0; it < 60 && hi - lo > 1e-6; ++it) (fits(0.5 * (lo + hi), k_row) ? hi : lo) = 0.5 * (lo + hi);
    span = hi;
  }
  // Short of room: a shorter approach, driven slower (the curvature and its rate must still hold).
  span = std::min(span, lim.join_limit - a0);
  if (span < lo_span) {
    plan.why = fmt("no room to join the row before %.2f m", lim.join_limit);
    return plan;
  }
  plan.curve = ApproachCurve(p0, heading, a0, l0, psi0, span);
  const double pk = plan.curve.peakCurvature();
  if (pk > lim.max_curvature * (1.0 + 1e-9) || plan.curve.peakCurvatureRate() > lim.max_curvature_rate * (1.0 + 1e-9)) {
    plan.why = fmt("the approach would need curvature %.2f 1/m within %.2f m", pk, span);
    return plan;
  }
  plan.speed = pk > 0.0 ? std::min({vr, lim.max_yaw_rate / pk, std::sqrt(lim.max_lateral_accel / pk)}) : vr;
  // It must keep the plan's clearance from every obstacle.
  const int samples = std::max(2, static_cast<int>(std::ceil(plan.curve.length() / 0.02)));
  for (int i = 0; i <= samples; ++i) {
    Eigen::Vector2d p;
    double th, k, dk;
    plan.curve.evaluate(plan.curve.length() * i / samples, p, th, k, dk);
    for (std::size_t j = 0; j < obstacles.size(); ++j) {
      const double c = (p - Eigen::Vector2d(obstacles[j].x, obstacles[j].y)).norm() - obstacles[j].radius;
      if (c < lim.clearance) {
        plan.why = "the approach passes within " + fmt("%.2f m of obstacle ", c) + std::to_string(j);
        return plan;
      }
    }
  }
  plan.ok = true;
  return plan;
}

}  // namespace core
}  // namespace sowing_robot
