// The approach from the robot's start pose to the first row: without it the field's target
// starts on the row while the robot stands elsewhere (thesis: 3 m off it), and the controllers close
// that error at once (4.35 rad/s, 3.61 m/s^2). The approach is a lateral offset of the row line,
// y(x) a septic in the along-row position x from the start (offset l0, slope tan(psi0), y'' = y''' = 0)
// to the join point (y = y' = y'' = y''' = 0): position, heading, curvature and its rate are continuous
// at both ends (the curvature is 0 there, as on the row and as for a robot that is not turning). Its
// length is the shortest for which the curvature and its rate stay within bounds at the speed it is
// driven at; where the row leaves no room for that, a shorter one is driven slower.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/planning/potential_field.h"

namespace sowing_robot {
namespace core {

/// One approach curve in world coordinates, parametrised by its arc length. Evaluation does not allocate.
class ApproachCurve {
 public:
  ApproachCurve() = default;
  /// Row from p0 along `heading`; start at along-row a0, lateral l0 (+ left), relative heading psi0
  /// (|psi0| < pi/2); joins the row at along-row a0 + span (span > 0).
  ApproachCurve(const Eigen::Vector2d& p0, double heading, double a0, double l0, double psi0, double span);

  double length() const { return length_; }              ///< arc length [m]
  double joinAlong() const { return a0_ + span_; }       ///< along-row position of the join [m]
  double peakCurvature() const { return peak_k_; }       ///< max |kappa| [1/m]
  double peakCurvatureRate() const { return peak_dk_; }  ///< max |dkappa/ds| [1/m^2]
  /// Position [m], heading [rad], curvature [1/m] and dkappa/ds [1/m^2] at arc length s (clamped).
  void evaluate(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const;

 private:
  /// Lateral offset and its derivatives with respect to the along-row position x in [0, span].
  void lateral(double x, double& y, double& y1, double& y2, double& y3) const;
  double arcIntegral(double xa, double xb) const;  ///< int sqrt(1 + y'^2) dx

  Eigen::Vector2d p0_ = Eigen::Vector2d::Zero(), u_ = Eigen::Vector2d::UnitX(), n_ = Eigen::Vector2d::UnitY();
  double heading_ = 0.0, a0_ = 0.0, l0_ = 0.0, m0_ = 0.0, span_ = 0.0;
  double length_ = 0.0, peak_k_ = 0.0, peak_dk_ = 0.0;
  double node_step_ = 0.0;   ///< along-row spacing of the arc-length table [m]
  std::vector<double> arc_;  ///< arc length at x = i node_step_
};

/// Bounds and room for planning an approach.
struct ApproachLimits {
  double max_curvature = 2.0;        ///< [1/m]
  double max_curvature_rate = 10.0;  ///< [1/m^2]
  double max_yaw_rate = 1.125;       ///< what the reference may use (after the tracking reserve) [rad/s]
  double max_lateral_accel = 1.125;  ///< [m/s^2]
  double row_speed = 1.0;            ///< the approach is driven at most at this speed [m/s]
  double join_limit = 0.0;           ///< the join must lie at or before this along-row position [m]
  double clearance = 0.0;            ///< distance the curve keeps from every obstacle surface [m]
};

struct ApproachPlan {
  bool needed = false;  ///< false: the start is on the row (at its start, heading along it)
  bool ok = false;      ///< false (with needed): no approach fits, see why
  std::string why;
  ApproachCurve curve;
  double speed = 0.0;  ///< speed it is driven at, <= row_speed; lower where the room is short [m/s]
};

/// Plans the approach from `start` to the row from p0 along `heading`. Starts within 1 mm and 1 mrad of
/// the row's start give no approach (needed false).
ApproachPlan planApproach(const Eigen::Vector2d& p0, double heading, const Pose2D& start, const ApproachLimits& lim,
                          const std::vector<Obstacle>& obstacles);

}  // namespace core
}  // namespace sowing_robot
