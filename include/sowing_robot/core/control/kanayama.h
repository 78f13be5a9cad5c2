// Kanayama kinematic tracking controller (eqs 4.1-4.2) with analytic desired accelerations.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges and units: kanayamaTable().
struct KanayamaGains {
  KanayamaGains();
  KanayamaGains(double kx_, double ky_, double ktheta_) : kx(kx_), ky(ky_), ktheta(ktheta_) {}
  double kx, ky, ktheta;  ///< [1/s], [1/m^2], [1/m]
  std::string validate() const;
};
/// kx, ky, ktheta (Table 5.3).
const ParamTable<KanayamaGains>& kanayamaTable();

/// Posture error in the robot frame (eq 4.1).
struct PostureError {
  double xe = 0.0, ye = 0.0, thetae = 0.0;
};

class Kanayama {
 public:
  /// Throws std::invalid_argument when the gains do not validate.
  explicit Kanayama(const KanayamaGains& gains = {});

  /// eq 4.1: e_p = T(theta)^T (P_r - P_A), with theta_e wrapped to (-pi, pi].
  static PostureError postureError(const Pose2D& reference, const Pose2D& actual);

  /// eq 4.2 for the velocities. The accelerations are the exact time derivatives of eq 4.2 along the
  /// error dynamics (eq 4.15) evaluated with the measured velocities v, omega, so no numerical
  /// differentiation (and no filter lag) enters the inner loop. A non-finite input gives the stop
  /// command (all zero), never a NaN: the safe output of a stateless controller. A stop hold in the
  /// reference (ref.stop) gives holdCommand(): at rest the pose is not chased.
  VelocityCommand compute(const Reference& ref, const Pose2D& actual, double v, double omega) const;

  /// eq 4.14: L0 = (xe^2 + ye^2)/2 + (1 - cos thetae)/ky.
  double lyapunov(const PostureError& e) const;

  const KanayamaGains& gains() const { return gains_; }
  /// Throws std::invalid_argument (gains kept) when g does not validate.
  void setGains(const KanayamaGains& g);

 private:
  KanayamaGains gains_;
};

}  // namespace core
}  // namespace sowing_robot
