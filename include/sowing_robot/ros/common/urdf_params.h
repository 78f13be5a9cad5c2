// Reads the thesis Table 5.1 parameters (core::RobotParams) from the robot's URDF, so the URDF is the
// single source of geometry and inertia. ROS-free: urdfdom only (link urdfdom_model), no roscpp.
#pragma once

#include <string>

#include "sowing_robot/core/model/footprint.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {

/// Reads Table 5.1 parameters from a URDF string. Returns "" on success or one line naming what is
/// missing/wrong; `out` is written only on success.
///
/// Mapping (all in base_link, wheel joints at zero angle; see the comment at the top of
/// urdf/sowing_robot.urdf):
///   mc = mass of link `chassis`; d = x of its centre of mass; Ic = its yaw inertia about the axle
///   midpoint (izz about the COM + mc (x^2 + y^2)); mw, Iw, Im = mass, inertia about the joint axis and
///   inertia about the vertical of link `right_wheel` (left must match); L = |y| of
///   `right_wheel_joint` (left must mirror it); R = radius of the wheel's collision cylinder, which must
///   equal the joint height.
/// Besides chassis and the two wheels no link may carry mass: Table 5.1 lumps everything else into mc.
std::string robotParamsFromUrdf(const std::string& urdf_xml, core::RobotParams& out);

/// Planar position [m] of a link's frame in base_link, through fixed joints only (e.g. `tool_link`,
/// the seed-drop point). Returns "" or one line naming what is missing.
std::string linkPositionFromUrdf(const std::string& urdf_xml, const std::string& link, double& x, double& y);

/// How far the seed drill's tool point (`tool_link`) trails the axle [m] (>= 0): a planned field's
/// FieldParams::run_out, so its last row is driven until the tool point is at the row's end. "" or one line.
std::string toolRunOutFromUrdf(const std::string& urdf_xml, const std::string& tool_link, double& run_out);

/// The robot's footprint in base_link: every link's collision geometry (box, cylinder, sphere) projected
/// onto base_link's ground plane, through the joints at zero position (the drive wheels' continuous
/// joints included: their collision cylinders are about the axle, so the projection does not depend on
/// the wheel angle), and the convex hull of it all. Cylinders and spheres are sampled at 64 points per
/// circle (inside the true outline by at most 0.12 % of the radius). Returns "" or one line naming the
/// link whose geometry cannot be used (a mesh); `out` is written only on success.
std::string footprintFromUrdf(const std::string& urdf_xml, core::Footprint& out);

}  // namespace sowing_robot
