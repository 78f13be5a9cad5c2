// The two controller slots of the cascade and what fills them:
//   outer (kinematic): reference + measured pose, v, omega -> VelocityCommand (v, omega, v_dot, omega_dot)
//     kanayama | pure_pursuit | rpp
//   inner (torque): desired VelocityCommand + measured v, omega + dt -> wheel torques (clipping reported)
//     atsmc | tsmc (SlidingModeController, adaptive or not) | pid (WheelPid)
// A pair is named "outer+inner", e.g. "kanayama+atsmc", "rpp+pid".
//
// OuterController / InnerController are the run-time interfaces (virtual) for code that picks a
// controller by name; OuterAdapter / InnerAdapter wrap the concrete classes. Which controllers exist,
// their names and how each is built: controller_factory.h. The in-process loop does not go through the
// interfaces for the controllers the factory hands it as concrete types, so its hot loop has no virtual call.
#pragma once

#include <string>
#include <utility>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/pure_pursuit.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/wheel_pid.h"

namespace sowing_robot {
namespace core {

/// The inner loop's output record, common to every inner controller: fields a controller has no
/// equivalent of stay 0 (the PID has no sliding variables s_v, s_omega; its u1 = u_r + u_l and
/// u2 = u_r - u_l before clipping, e_v and e_omega the body-velocity errors).
using InnerOutput = SlidingModeOutput;

class OuterController {
 public:
  virtual ~OuterController() = default;
  virtual VelocityCommand compute(const Reference& ref, const Pose2D& actual, double v, double omega) = 0;
  virtual void reset() {}
};

class InnerController {
 public:
  virtual ~InnerController() = default;
  virtual InnerOutput update(const VelocityCommand& desired, double v, double omega, double dt) = 0;
  virtual void reset() = 0;
  /// The model estimates in use [kg], [kg·m^2] (adaptive: the current estimates; otherwise nominal).
  virtual double m0Hat() const = 0;
  virtual double i0Hat() const = 0;
  /// The torques a layer after this controller sent for its last output (WheelPid::heldBack,
  /// SlidingModeController::heldBack: anti-windup against the traction control).
  virtual void heldBack(const WheelTorques& sent) = 0;
};

/// Kanayama or PurePursuit behind OuterController.
template <typename C>
class OuterAdapter final : public OuterController {
 public:
  explicit OuterAdapter(C c) : c_(std::move(c)) {}
  VelocityCommand compute(const Reference& ref, const Pose2D& actual, double v, double omega) override {
    return c_.compute(ref, actual, v, omega);
  }
  C& controller() { return c_; }

 private:
  C c_;
};

/// The PID's output in the common record.
inline InnerOutput toInnerOutput(const WheelPidOutput& p, const VelocityCommand& desired, double v, double omega) {
  InnerOutput o;
  o.torques = p.torques;
  o.e_v = desired.v - v;
  o.e_omega = desired.omega - omega;
  o.u1 = p.u_right + p.u_left;
  o.u2 = p.u_right - p.u_left;
  o.saturated = p.saturated;
  o.rejected = p.rejected;
  o.holding = p.holding;
  return o;
}

/// SlidingModeController or WheelPid behind InnerController.
template <typename C>
class InnerAdapter;

template <>
class InnerAdapter<SlidingModeController> final : public InnerController {
 public:
  explicit InnerAdapter(SlidingModeController c) : c_(std::move(c)) {}
  InnerOutput update(const VelocityCommand& d, double v, double omega, double dt) override {
    return c_.update(d, v, omega, dt);
  }
  void reset() override { c_.reset(); }
  double m0Hat() const override { return c_.m0Hat(); }
  double i0Hat() const override { return c_.i0Hat(); }
  void heldBack(const WheelTorques& sent) override { c_.heldBack(sent); }
  SlidingModeController& controller() { return c_; }

 private:
  SlidingModeController c_;
};

template <>
class InnerAdapter<WheelPid> final : public InnerController {
 public:
  explicit InnerAdapter(WheelPid c) : c_(std::move(c)) {}
  InnerOutput update(const VelocityCommand& d, double v, double omega, double dt) override {
    return toInnerOutput(c_.update(d, v, omega, dt), d, v, omega);
  }
  void reset() override { c_.reset(); }
  double m0Hat() const override { return c_.m0(); }
  double i0Hat() const override { return c_.i0(); }
  void heldBack(const WheelTorques& sent) override { c_.heldBack(sent); }
  WheelPid& controller() { return c_; }

 private:
  WheelPid c_;
};

}  // namespace core
}  // namespace sowing_robot
