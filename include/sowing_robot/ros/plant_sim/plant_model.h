// The model behind plant_sim's SimulatedPlant: today's no-slip core::Plant (the default) or the traction
// plant with soil patches and the tool's draft (plant_traction.h, traction/enabled). SimulatedPlant
// steps and publishes through this interface only, so the messages are the same code for both.
#pragma once

#include <ros/time.h>

#include <string>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/plant.h"

namespace sowing_robot {

class PlantModel {
 public:
  virtual ~PlantModel() = default;
  /// One control period of dt [s] with the commanded wheel torques [N·m].
  virtual void step(double tau_right, double tau_left, double dt) = 0;
  virtual const core::State& state() const = 0;
  virtual double time() const = 0;
  /// The wheels' spin rates [rad/s] (joint_states velocity).
  virtual void wheelRates(double& right, double& left) const = 0;
  /// The drive motors (core/model/motor.h) between the commanded torques and the wheels, from the next step on.
  /// Throws std::invalid_argument when the parameters do not validate.
  virtual void setMotor(const core::MotorParams& motor) = 0;
  /// The torques [N·m] the motors applied over the last step (the traction plant: its last sub-step), before
  /// the disturbance and the noise; with the motors off, the commanded ones.
  virtual void appliedTorques(double& right, double& left) const = 0;
  /// The plant's true m0 [kg] and I0 [kg m^2] (the controllers' model times the mismatch), for the log.
  virtual double trueM0() const = 0;
  virtual double trueI0() const = 0;
  /// Lockstep: every input a step depends on is there (the traction model with a draft needs the plan).
  virtual bool ready() const { return true; }
  /// What ready() waits for, for the stall report.
  virtual std::string waitingFor() const { return ""; }
  /// Extra messages with the visuals (publish_rate): the traction model's wheel_slip.
  virtual void publishVisuals(const ros::Time& /*stamp*/) {}
  /// The hitch control's command for the next step (WheelTorque/tool_raised): the tool held up whatever the
  /// seed drill's rule says. Only the traction plant has a tool.
  virtual void setToolRaised(bool /*raised*/) {}
  /// The depth control's depth for the next step [m] (WheelTorque/tool_depth; 0: the drill's nominal depth).
  virtual void setToolDepth(double /*depth*/) {}
  /// One line for the end-of-run report ("" for none).
  virtual std::string report() const { return ""; }
};

/// Today's plant: core::Plant (RK4, no slip), exactly as before.
class NoSlipModel : public PlantModel {
 public:
  NoSlipModel(const core::RobotParams& robot, const core::PlantDisturbance& disturbance, const core::State& x0)
      : plant_(robot, disturbance) {
    plant_.reset(x0, 0.0);
  }
  void step(double tau_right, double tau_left, double dt) override { plant_.step(tau_right, tau_left, dt); }
  const core::State& state() const override { return plant_.state(); }
  double time() const override { return plant_.time(); }
  void wheelRates(double& right, double& left) const override {
    const core::State ds = plant_.derivative(plant_.state(), 0.0, 0.0);  // wheel rates do not depend on torque
    right = ds[core::PHI_R];
    left = ds[core::PHI_L];
  }
  void setMotor(const core::MotorParams& motor) override { plant_.setMotor(motor); }
  void appliedTorques(double& right, double& left) const override {
    right = plant_.appliedTorque(0);
    left = plant_.appliedTorque(1);
  }
  double trueM0() const override { return plant_.trueM0(); }
  double trueI0() const override { return plant_.trueI0(); }

 private:
  core::Plant plant_;
};

}  // namespace sowing_robot
