// Physical parameters of the sowing DDMR (thesis Table 5.1) and the terms derived from them
// (eqs 3.27 and 3.54-3.55). ROS-free: Eigen and the standard library only.
#pragma once

#include <string>

namespace sowing_robot {
namespace core {

/// Geometry and inertia of the robot. Names follow the thesis: L is half the track (the thesis's D),
/// d is the centre-of-mass offset ahead of the axle (the thesis's a).
struct RobotParams {
  double mc = 17.0;    ///< chassis mass without wheels and rotors [kg] (Table 5.1 swaps mc and mw)
  double mw = 0.5;     ///< mass of one wheel with its motor rotor [kg]
  double d = 0.05;     ///< centre of mass ahead of the axle midpoint [m]
  double L = 0.24;     ///< half track: axle midpoint to each wheel [m]
  double R = 0.095;    ///< drive wheel radius [m]
  double Ic = 0.537;   ///< chassis yaw inertia about its own centre of mass [kg·m^2] (see I())
  double Im = 0.0011;  ///< one wheel's inertia about a vertical (diameter) axis [kg·m^2]
  double Iw = 0.0023;  ///< one wheel's spin inertia about its axle [kg·m^2]

  /// Total mass m = mc + 2 mw [kg] (eq 3.27).
  double m() const { return mc + 2.0 * mw; }
  /// Total yaw inertia I = 2 mw L^2 + mc d^2 + 2 Im + Ic [kg·m^2] (eq 3.27).
  double I() const { return 2.0 * mw * L * L + mc * d * d + 2.0 * Im + Ic; }
  /// Effective translational inertia m0 = m + 2 Iw / R^2 [kg] (eq 3.55).
  double m0() const { return m() + 2.0 * Iw / (R * R); }
  /// Effective rotational inertia I0 = I + 2 L^2 Iw / R^2 [kg·m^2] (eq 3.55; 3.54 prints 2L^2/(2R^2)).
  double I0() const { return I() + 2.0 * L * L * Iw / (R * R); }

  /// Empty when every value is finite and physically possible, else one line naming the bad parameter.
  std::string validate() const;
};

}  // namespace core
}  // namespace sowing_robot
