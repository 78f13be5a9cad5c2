// The controller factory: which controllers fill the cascade's two slots (outer: kinematic, inner:
// torque), their parameters, their names, and how each is built. Every place that builds or names a
// controller goes through here: the in-process loop (simulation/), the kinematic_controller and
// torque_controller nodes, the tuner, the scenario-file loader and the node settings' choice lists.
//
// A new controller: its own files in control/ (the class, its params struct and parameter table), and
// its registration here: a kind, a params member of ControllerPair, and its row in the table of
// controller_factory.cpp (name, build, parameter binding, validate). withControllers() hands the in-process loop the
// concrete types it knows (direct calls); any other registered controller reaches the loop through the
// run-time interfaces of controllers.h, so it runs without touching the loop.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/control/controllers.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/pure_pursuit.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/wheel_pid.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

enum class OuterKind { kanayama, pure_pursuit, rpp };
enum class InnerKind { sliding_mode, pid };  ///< sliding_mode: atsmc or tsmc by SlidingModeParams::adaptive

/// The pair in the cascade and every controller's parameters (only the chosen pair's are used).
struct ControllerPair {
  OuterKind outer = OuterKind::kanayama;      ///< which outer controller the loop builds
  InnerKind inner = InnerKind::sliding_mode;  ///< which inner controller (atsmc/tsmc: sliding.adaptive)
  KanayamaGains kanayama;
  PurePursuitParams pure_pursuit;  ///< outer = pure_pursuit or rpp
  SlidingModeParams sliding;       ///< inner = sliding_mode; its max_torque is the motors' limit for the hold
  WheelPidParams pid;              ///< inner = pid

  /// "kanayama+atsmc", "rpp+pid", ...
  std::string controllerName() const;
  /// "" or the first bad parameter: Kanayama's and the sliding mode's always (the thesis pair's), the
  /// others' when chosen.
  std::string validateControllers() const;
  /// The chosen inner controller's per-wheel torque limit [N·m] (the standstill hold brakes up to it): the
  /// PID's, else the sliding mode's, which torque_controller's one max_torque key sets for every controller.
  double innerMaxTorque() const { return inner == InnerKind::pid ? pid.max_torque : sliding.max_torque; }
};

/// "kanayama", "pure_pursuit", "rpp".
const char* outerName(OuterKind k);
/// "atsmc", "tsmc" (sliding_mode by `adaptive`), "pid".
const char* innerName(InnerKind k, bool adaptive);
/// Parse "outer+inner". On success sets outer, inner and adaptive (untouched for pid) and returns "";
/// otherwise one line naming what is wrong and the allowed names.
std::string parseControllerPair(const std::string& name, OuterKind& outer, InnerKind& inner, bool& adaptive);
/// The values a node's `outer` / `inner` parameter takes, in the factory's order.
std::vector<std::pair<std::string, OuterKind>> outerChoices();
std::vector<std::pair<std::string, InnerKind>> innerChoices();

/// One parameter of a registered controller, reached through the pair: its table entry (key, default,
/// range, unit, tunable) and access to the member it sets.
struct ControllerParam {
  enum class Slot { outer, inner };
  Slot slot;               ///< read by kinematic_controller (outer) or torque_controller (inner)
  const ParamInfo* info;   ///< the controller's table entry (static: outlives every pair)
  const char* controller;  ///< the registered name it belongs to ("kanayama", "sliding_mode", ...)
  /// Whether it acts in `pair` (the adaptation rates only in ATSMC, the minimum radius only in RPP).
  bool (*acts)(const ControllerPair& pair, const std::string& key);
  std::function<ParamValue(const ControllerPair&)> get;
  std::function<void(ControllerPair&, const ParamValue&)> set;  ///< unchecked: check with info->check first
};
/// The parameters of the pair's chosen outer controller, then of its inner, each in its table's order.
std::vector<ControllerParam> chosenControllerParams(const ControllerPair& pair);
/// Every registered controller's parameters in one slot (a table shared by two entries listed once).
std::vector<ControllerParam> slotParams(ControllerParam::Slot slot);
/// The registered names of the slot whose controller reads `info` and in which it acts ("pure_pursuit", "rpp").
std::vector<std::string> controllersActingOn(ControllerParam::Slot slot, const ParamInfo* info);
/// "" or the first bad parameter of any registered controller of the slot (chosen or not).
std::string validateSlot(const ControllerPair& pair, ControllerParam::Slot slot);
/// The slot's choice and every registered controller's parameters of that slot, copied from `from`.
void copySlot(ControllerPair& to, const ControllerPair& from, ControllerParam::Slot slot);

/// The pair's outer / inner controller behind the run-time interfaces. Throws std::invalid_argument when
/// its parameters do not validate. `nominal`: the robot model the inner controller assumes.
std::unique_ptr<OuterController> makeOuterController(const ControllerPair& pair);
std::unique_ptr<InnerController> makeInnerController(const ControllerPair& pair, const RobotParams& nominal);

/// Calls f(outer, inner) with the pair's controllers as concrete types, so that a loop templated on them
/// makes direct calls (the hot loop: simulation/runner.cpp); returns what f returns. A registered controller
/// without a case here is handed over behind its run-time interface (virtual calls, same numbers).
template <typename F>
decltype(auto) withControllers(const ControllerPair& pair, const RobotParams& nominal, F&& f) {
  auto with_inner = [&](auto& outer) -> decltype(auto) {
    switch (pair.inner) {
      case InnerKind::pid: {
        InnerAdapter<WheelPid> pid{WheelPid(pair.pid, nominal)};
        return f(outer, pid);
      }
      case InnerKind::sliding_mode: {
        SlidingModeController smc(pair.sliding, nominal);
        return f(outer, smc);
      }
      default:  // registered without a case here
        break;
    }
    const std::unique_ptr<InnerController> inner = makeInnerController(pair, nominal);
    return f(outer, *inner);
  };
  switch (pair.outer) {
    case OuterKind::kanayama: {
      Kanayama kanayama(pair.kanayama);
      return with_inner(kanayama);
    }
    case OuterKind::pure_pursuit:
    case OuterKind::rpp: {
      PurePursuit pursuit(pair.pure_pursuit, pair.outer == OuterKind::rpp);
      return with_inner(pursuit);
    }
    default:  // registered without a case here
      break;
  }
  const std::unique_ptr<OuterController> outer = makeOuterController(pair);
  return with_inner(*outer);
}

}  // namespace core
}  // namespace sowing_robot
