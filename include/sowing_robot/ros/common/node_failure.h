// Why a node cannot go on, as an exception: library and wrapper code throws it, and only a program's
// main (or a nodelet's onInit / run thread) decides what to do with it. A node's main logs the message
// as its last FATAL line and exits with exitCode(); a nodelet logs it and stops only itself, so the
// manager and the other nodelets in it keep running.
#pragma once

#include <stdexcept>
#include <string>

namespace sowing_robot {

/// The documented exit codes of every sowing_robot node.
enum class ExitCode : int {
  kOk = 0,
  kBadParameter = 1,  ///< refused to start: a parameter (or the URDF) is invalid
  kDiverged = 2,      ///< the simulated state became non-finite or too fast
  kGaveUp = 3,        ///< lockstep: an input stayed missing longer than lockstep_give_up
  // 4: the sim runner's own (--local-only refused).
  kNoTraction = 5,  ///< run_monitor: the run ended on the traction control's "no traction" verdict
  kStoppedShort =
      6,  ///< run_monitor: the run completed, but the plan stopped short of its field (stopped_short, no_safe_way)
};

class NodeFailure : public std::runtime_error {
 public:
  NodeFailure(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }
  int exitCode() const { return static_cast<int>(code_); }

 private:
  ExitCode code_;
};

/// A parameter problem found at start-up (what refuseToStart used to end the process with).
inline NodeFailure badParameter(const std::string& message) { return NodeFailure(ExitCode::kBadParameter, message); }

}  // namespace sowing_robot
