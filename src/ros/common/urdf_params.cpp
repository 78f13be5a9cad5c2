#include "sowing_robot/ros/common/urdf_params.h"

#include "sowing_robot/core/common/validation.h"

#include <urdf_parser/urdf_parser.h>
#include <algorithm>

#include <Eigen/Geometry>
#include <cmath>
#include <exception>
#include <sstream>
#include <vector>

namespace sowing_robot {

namespace {

const char* const kBaseLink = "base_link";
const char* const kChassisLink = "chassis";
const double kGeomTol = 1e-9;      ///< tolerance on lengths and unit vectors [m] / [-]
const double kInertiaTol = 1e-12;  ///< tolerance on left/right mass and inertia equality

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string quoted(const std::string& name) { return "'" + name + "'"; }

Eigen::Isometry3d toIsometry(const urdf::Pose& p) {
  Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  if (q.norm() > 0.0) q.normalize();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = q.toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

/// Inertia tensor of `in` about its COM, expressed in the frame of the link that owns it.
Eigen::Matrix3d inertiaInLinkFrame(const urdf::Inertial& in) {
  Eigen::Matrix3d i;
  i << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Eigen::Matrix3d r = toIsometry(in.origin).linear();
  return r * i * r.transpose();
}

/// Pose of the frame of `link_name`'s parent joint parent link in base_link, walking fixed joints only.
/// Returns "" or an error naming the offending link/joint.
std::string parentFrameInBase(const urdf::ModelInterface& model, const std::string& link_name, Eigen::Isometry3d& out) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  std::string name = link_name;
  for (std::size_t depth = 0; name != kBaseLink; ++depth) {
    urdf::LinkConstSharedPtr link = model.getLink(name);
    if (!link) return "link " + quoted(name) + " not found";
    if (!link->parent_joint)
      return "link " + quoted(link_name) + " is not below " + quoted(kBaseLink) + " in the URDF tree";
    if (depth > model.links_.size()) return "URDF tree has a loop above link " + quoted(link_name);
    const urdf::Joint& j = *link->parent_joint;
    if (depth > 0 && j.type != urdf::Joint::FIXED)
      return "joint " + quoted(j.name) + " between " + quoted(kBaseLink) + " and " + quoted(link_name) +
             " must be fixed";
    if (depth > 0) t = toIsometry(j.parent_to_joint_origin_transform) * t;
    name = j.parent_link_name;
  }
  out = t;
  return "";
}

/// Pose of `link_name`'s own frame in base_link (its parent joint at zero position).
std::string frameInBase(const urdf::ModelInterface& model, const std::string& link_name, bool allow_moving_own_joint,
                        Eigen::Isometry3d& out) {
  if (link_name == kBaseLink) {
    out = Eigen::Isometry3d::Identity();
    return "";
  }
  urdf::LinkConstSharedPtr link = model.getLink(link_name);
  if (!link) return "link " + quoted(link_name) + " not found";
  if (!link->parent_joint)
    return "link " + quoted(link_name) + " is not below " + quoted(kBaseLink) + " in the URDF tree";
  const urdf::Joint& j = *link->parent_joint;
  if (!allow_moving_own_joint && j.type != urdf::Joint::FIXED)
    return "joint " + quoted(j.name) + " between " + quoted(kBaseLink) + " and " + quoted(link_name) + " must be fixed";
  Eigen::Isometry3d parent;
  const std::string err = parentFrameInBase(model, link_name, parent);
  if (!err.empty()) return err;
  out = parent * toIsometry(j.parent_to_joint_origin_transform);
  return "";
}

struct Wheel {
  std::string joint, link;
  double mass = 0.0;
  double spin_inertia = 0.0;      ///< Iw: about the joint axis [kg·m^2]
  double vertical_inertia = 0.0;  ///< Im: about base_link's vertical through the wheel centre [kg·m^2]
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< joint origin in base_link [m]
  double radius = 0.0;                               ///< collision cylinder radius [m]
};

/// Reads one drive wheel. `side_sign` is -1 for the right wheel (y < 0), +1 for the left.
std::string readWheel(const urdf::ModelInterface& model, const std::string& joint_name, double side_sign, Wheel& w) {
  w.joint = joint_name;
  urdf::JointConstSharedPtr joint = model.getJoint(joint_name);
  if (!joint) return "joint " + quoted(joint_name) + " not found";
  if (joint->type != urdf::Joint::CONTINUOUS && joint->type != urdf::Joint::REVOLUTE)
    return "joint " + quoted(joint_name) + " must be continuous (or revolute)";
  w.link = joint->child_link_name;
  urdf::LinkConstSharedPtr link = model.getLink(w.link);
  if (!link) return "link " + quoted(w.link) + " (child of " + quoted(joint_name) + ") not found";

  Eigen::Isometry3d t;  // wheel (joint) frame in base_link at zero angle
  std::string err = frameInBase(model, w.link, true, t);
  if (!err.empty()) return err;

  // Axle along base_link's y.
  Eigen::Vector3d axis_local(joint->axis.x, joint->axis.y, joint->axis.z);
  if (!(axis_local.norm() > 0.0)) return "joint " + quoted(joint_name) + " has a zero axis";
  axis_local.normalize();
  const Eigen::Vector3d axis = t.linear() * axis_local;
  if (std::abs(axis.x()) > kGeomTol || std::abs(axis.z()) > kGeomTol)
    return "joint " + quoted(joint_name) + " axis must be along base_link y (it is " + num(axis.x()) + " " +
           num(axis.y()) + " " + num(axis.z()) + ")";

  w.origin = t.translation();
  if (std::abs(w.origin.x()) > kGeomTol)
    return "joint " + quoted(joint_name) + " origin x = " + num(w.origin.x()) +
           " m must be 0: base_link is under the axle midpoint";
  if (!(side_sign * w.origin.y() > 0.0))
    return "joint " + quoted(joint_name) + " origin y = " + num(w.origin.y()) + " m is on the wrong side (" +
           (side_sign < 0 ? "right wheel needs y < 0" : "left wheel needs y > 0") + ")";

  // Mass and inertia.
  if (!link->inertial) return "link " + quoted(w.link) + " has no <inertial>";
  const urdf::Inertial& in = *link->inertial;
  const Eigen::Vector3d com(in.origin.position.x, in.origin.position.y, in.origin.position.z);
  if (com.norm() > kGeomTol)
    return "link " + quoted(w.link) + " inertial origin must be at the joint origin (wheel centre)";
  const Eigen::Matrix3d inertia = inertiaInLinkFrame(in);
  const Eigen::Vector3d vertical_local = t.linear().transpose() * Eigen::Vector3d::UnitZ();
  w.mass = in.mass;
  w.spin_inertia = axis_local.dot(inertia * axis_local);
  w.vertical_inertia = vertical_local.dot(inertia * vertical_local);

  // Radius from the first collision cylinder; it must be coaxial with the joint.
  std::vector<urdf::CollisionSharedPtr> collisions = link->collision_array;
  if (collisions.empty() && link->collision) collisions.push_back(link->collision);
  const urdf::Cylinder* cyl = nullptr;
  Eigen::Isometry3d cyl_pose;
  for (const auto& c : collisions) {
    if (c && c->geometry && c->geometry->type == urdf::Geometry::CYLINDER) {
      cyl = static_cast<const urdf::Cylinder*>(c->geometry.get());
      cyl_pose = toIsometry(c->origin);
      break;
    }
  }
  if (!cyl) return "link " + quoted(w.link) + " has no <collision> cylinder (needed for the wheel radius R)";
  const Eigen::Vector3d cyl_axis = cyl_pose.linear() * Eigen::Vector3d::UnitZ();
  if (cyl_axis.cross(axis_local).norm() > kGeomTol)
    return "link " + quoted(w.link) + " collision cylinder axis is not along " + quoted(joint_name) + " axis";
  if (cyl_pose.translation().cross(axis_local).norm() > kGeomTol)
    return "link " + quoted(w.link) + " collision cylinder is not centred on the " + quoted(joint_name) + " axle";
  w.radius = cyl->radius;
  if (!(std::isfinite(w.radius) && w.radius > 0.0))
    return "link " + quoted(w.link) + " collision cylinder radius = " + num(w.radius) + " m must be > 0";
  if (std::abs(w.radius - w.origin.z()) > kGeomTol)
    return "link " + quoted(w.link) + ": wheel radius ≠ axle height (collision cylinder radius " + num(w.radius) +
           " m, " + quoted(joint_name) + " z " + num(w.origin.z()) + " m)";
  return "";
}

std::string compare(const std::string& what, double right, double left, double tol, const Wheel& r, const Wheel& l) {
  if (std::abs(right - left) <= tol) return "";
  return "wheels differ in " + what + ": " + quoted(r.link) + "/" + quoted(r.joint) + " " + num(right) + " vs " +
         quoted(l.link) + "/" + quoted(l.joint) + " " + num(left);
}

std::string fromModel(const urdf::ModelInterface& model, core::RobotParams& p) {
  if (!model.getLink(kBaseLink)) return "link " + quoted(kBaseLink) + " not found";

  // Chassis: mc, d, Ic.
  urdf::LinkConstSharedPtr chassis = model.getLink(kChassisLink);
  if (!chassis) return "link " + quoted(kChassisLink) + " not found";
  if (!chassis->inertial) return "link " + quoted(kChassisLink) + " has no <inertial>";
  Eigen::Isometry3d t_chassis;
  std::string err = frameInBase(model, kChassisLink, false, t_chassis);
  if (!err.empty()) return err;
  const urdf::Inertial& ci = *chassis->inertial;
  const Eigen::Isometry3d t_com = t_chassis * toIsometry(ci.origin);
  const Eigen::Vector3d com = t_com.translation();
  if (std::abs(com.y()) > kGeomTol)
    return "link " + quoted(kChassisLink) + " centre of mass y = " + num(com.y()) +
           " m must be 0 (the model has the COM on base_link's x axis)";
  const Eigen::Matrix3d r = t_chassis.linear();
  const Eigen::Matrix3d inertia_base = r * inertiaInLinkFrame(ci) * r.transpose();
  p.mc = ci.mass;
  p.d = com.x();
  p.Ic = inertia_base(2, 2);  // about the chassis COM: eq 3.27 adds mc d^2 itself

  // Wheels: mw, Iw, Im, L, R.
  Wheel right, left;
  err = readWheel(model, "right_wheel_joint", -1.0, right);
  if (!err.empty()) return err;
  err = readWheel(model, "left_wheel_joint", +1.0, left);
  if (!err.empty()) return err;
  if (right.link == left.link) return "right_wheel_joint and left_wheel_joint drive the same link";
  err = core::firstError(
      {compare("mass [kg]", right.mass, left.mass, kInertiaTol, right, left),
       compare("spin inertia Iw [kg·m^2]", right.spin_inertia, left.spin_inertia, kInertiaTol, right, left),
       compare("vertical inertia Im [kg·m^2]", right.vertical_inertia, left.vertical_inertia, kInertiaTol, right, left),
       compare("half track |y| [m]", -right.origin.y(), left.origin.y(), kGeomTol, right, left),
       compare("radius [m]", right.radius, left.radius, kGeomTol, right, left)});
  if (!err.empty()) return err;
  p.mw = right.mass;
  p.Iw = right.spin_inertia;
  p.Im = right.vertical_inertia;
  p.L = -right.origin.y();
  p.R = right.radius;

  // Everything else is lumped into the chassis (Table 5.1 has no term for it).
  for (const auto& kv : model.links_) {
    const std::string& name = kv.first;
    if (name == kChassisLink || name == right.link || name == left.link) continue;
    if (kv.second && kv.second->inertial && kv.second->inertial->mass != 0.0)
      return "link " + quoted(name) + " has mass " + num(kv.second->inertial->mass) + " kg; lump it into " +
             quoted(kChassisLink) + " (the model has only chassis and two wheels)";
  }
  return "";
}

}  // namespace

namespace {
/// Parses the URDF; "" or one line saying why it could not be parsed.
std::string parse(const std::string& urdf_xml, urdf::ModelInterfaceSharedPtr& model) {
  try {
    model = urdf::parseURDF(urdf_xml);
  } catch (const std::exception& e) {
    return std::string("URDF could not be parsed: ") + e.what();
  }
  return model ? "" : "URDF could not be parsed (malformed XML or invalid URDF)";
}
}  // namespace

std::string robotParamsFromUrdf(const std::string& urdf_xml, core::RobotParams& out) {
  urdf::ModelInterfaceSharedPtr model;
  std::string err = parse(urdf_xml, model);
  if (!err.empty()) return err;

  core::RobotParams p;
  err = fromModel(*model, p);
  if (!err.empty()) return "URDF " + quoted(model->getName()) + ": " + err;
  err = p.validate();
  if (!err.empty()) return "URDF " + quoted(model->getName()) + " gives an invalid parameter: " + err;
  out = p;
  return "";
}

}  // namespace sowing_robot

namespace sowing_robot {

std::string toolRunOutFromUrdf(const std::string& urdf_xml, const std::string& tool_link, double& run_out) {
  double x = 0.0, y = 0.0;
  const std::string e = linkPositionFromUrdf(urdf_xml, tool_link, x, y);
  if (!e.empty()) return "the seed drill's tool point (seed_drill/tool_link): " + e;
  run_out = std::max(0.0, -x);
  return "";
}

std::string linkPositionFromUrdf(const std::string& urdf_xml, const std::string& link, double& x, double& y) {
  urdf::ModelInterfaceSharedPtr model;
  std::string err = parse(urdf_xml, model);
  if (!err.empty()) return err;
  Eigen::Isometry3d pose;
  err = frameInBase(*model, link, false, pose);
  if (!err.empty()) return "URDF " + quoted(model->getName()) + ": " + err;
  x = pose.translation().x();
  y = pose.translation().y();
  return "";
}

}  // namespace sowing_robot

namespace sowing_robot {

namespace {
/// Ground-plane points of one collision shape whose frame is `t` in base_link (appended to `pts`).
std::string projectGeometry(const urdf::Geometry& g, const Eigen::Isometry3d& t, const std::string& link,
                            std::vector<Eigen::Vector2d>& pts) {
  const int kCircle = 64;
  auto add = [&](const Eigen::Vector3d& local) {
    const Eigen::Vector3d w = t * local;
    pts.emplace_back(w.x(), w.y());
  };
  auto circle = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2, double r) {
    for (int k = 0; k < kCircle; ++k) {
      const double a = 2.0 * M_PI * k / kCircle;
      double s, c;
      s = std::sin(a);
      c = std::cos(a);
      add(centre + r * (c * e1 + s * e2));
    }
  };
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const urdf::Vector3& s = static_cast<const urdf::Box&>(g).dim;
      for (int i = 0; i < 8; ++i)
        add(Eigen::Vector3d((i & 1 ? 0.5 : -0.5) * s.x, (i & 2 ? 0.5 : -0.5) * s.y, (i & 4 ? 0.5 : -0.5) * s.z));
      return "";
    }
    case urdf::Geometry::CYLINDER: {  // axis along the shape's local z
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      for (const double z : {-0.5 * c.length, 0.5 * c.length})
        circle(Eigen::Vector3d(0, 0, z), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), c.radius);
      return "";
    }
    case urdf::Geometry::SPHERE: {  // its ground-plane outline is the horizontal great circle
      const double r = static_cast<const urdf::Sphere&>(g).radius;
      const Eigen::Matrix3d back = t.linear().transpose();  // base_link x, y in the shape frame
      circle(Eigen::Vector3d::Zero(), back * Eigen::Vector3d::UnitX(), back * Eigen::Vector3d::UnitY(), r);
      return "";
    }
    default:
      return "link " + quoted(link) + " has a mesh collision geometry; the footprint needs box, cylinder or sphere";
  }
}
}  // namespace

std::string footprintFromUrdf(const std::string& urdf_xml, core::Footprint& out) {
  urdf::ModelInterfaceSharedPtr model;
  std::string err = parse(urdf_xml, model);
  if (!err.empty()) return err;
  if (!model->getLink(kBaseLink))
    return "URDF " + quoted(model->getName()) + ": link " + quoted(kBaseLink) + " not found";
  std::vector<Eigen::Vector2d> pts;
  for (const auto& kv : model->links_) {
    const urdf::LinkConstSharedPtr link = kv.second;
    if (!link) continue;
    std::vector<urdf::CollisionSharedPtr> collisions = link->collision_array;
    if (collisions.empty() && link->collision) collisions.push_back(link->collision);
    if (collisions.empty()) continue;
    Eigen::Isometry3d frame;
    err = frameInBase(*model, kv.first, true, frame);
    if (!err.empty()) return "URDF " + quoted(model->getName()) + ": " + err;
    for (const auto& c : collisions) {
      if (!c || !c->geometry) continue;
      err = projectGeometry(*c->geometry, frame * toIsometry(c->origin), kv.first, pts);
      if (!err.empty()) return "URDF " + quoted(model->getName()) + ": " + err;
    }
  }
  core::Footprint f = core::Footprint::convexHull(pts);
  err = f.validate();
  if (!err.empty())
    return "URDF " + quoted(model->getName()) + ": collision geometry gives no usable footprint: " + err;
  out = f;
  return "";
}

}  // namespace sowing_robot
