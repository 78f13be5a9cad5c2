// pso_tuner: offline PSO tuning of the controller gains (thesis eqs 4.26-4.31, Table 5.4). Reads the
// base scenario from the nodes' own namespaces (/plant_sim, /kinematic_controller, /torque_controller,
// /reference_generator) so a tuned gain means the same thing in the nodes, scores every particle with
// the in-process closed loop, reports progress on the console and on pso/progress, writes the best
// gains as a YAML that sim.launch's gains:=FILE loads, then exits.
#pragma once

#include <ros/ros.h>

#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {

class PsoTuner {
 public:
  /// Reads and checks every parameter; refuses to start (exit 1) on the first problem.
  PsoTuner(ros::NodeHandle nh, ros::NodeHandle pnh);

  /// Tunes and writes ~output. Returns the process exit code (0 done, 1 failed or interrupted).
  int run();

 private:
  void onProgress(const core::PsoProgress& p);
  std::string scenarioText() const;
  std::string adaptationText() const;
  std::string loadArgs() const;

  core::Scenario base_;
  core::LineReference reference_;
  double line_v_ = 1.0, line_y_ = 3.0, line_x0_ = 0.0;
  std::vector<core::GainBounds> gains_;
  core::TuningObjective objective_;
  core::PsoParams pso_;
  std::string output_;
  double initial_best_ = 0.0;
  ros::Publisher progress_pub_;
};

/// Writes the gains YAML (core::gainsYaml: every tunable gain of the pair under kinematic_controller /
/// torque_controller, the tuned ones marked with their bounds) after `header` (lines already starting with '#').
/// Written to a temporary file and renamed, so a reader never sees half a file. "" on success, else the reason.
std::string writeGainsYaml(const std::string& path, const std::string& header, const core::Scenario& tuned,
                           const std::vector<core::GainBounds>& searched);

/// Shortest round-trip decimal form of v that YAML 1.1 (rosparam) reads as a float (always has a '.').
std::string yamlFloat(double v);

}  // namespace sowing_robot
