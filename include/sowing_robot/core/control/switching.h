// The robustness term's switching function: sign and its chattering remedies (eqs 4.46-4.48).
#pragma once

#include <cmath>
#include <string>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {
namespace core {

enum class SwitchType { Sign, Saturation, Relay, Atan, Tanh };

/// Defaults, ranges and units: switchingTable().
struct SwitchFunction {
  SwitchFunction();
  SwitchFunction(SwitchType t, double w) : type(t), width(w) {}
  SwitchType type;
  /// Width of the smoothing: boundary layer phi of sat(S/phi) and tanh(S/phi), delta of the relay
  /// S/(|S|+delta), and 1/Delta of the normalised arctangent (2/pi) atan(S/width).
  double width;

  /// Value in [-1, 1]; odd in s; tends to sign(s) as |s| grows. Inline: the sliding-mode controller
  /// calls it twice every period.
  double operator()(double s) const {
    switch (type) {
      case SwitchType::Sign: return s > 0.0 ? 1.0 : (s < 0.0 ? -1.0 : 0.0);
      case SwitchType::Saturation: {  // eq 4.47
        const double r = s / width;
        return r > 1.0 ? 1.0 : (r < -1.0 ? -1.0 : r);
      }
      case SwitchType::Relay:  // eq 4.46
        return s / (std::fabs(s) + width);
      case SwitchType::Atan:  // eq 4.48, scaled by 2/pi so that eta keeps its meaning as the switching gain
        return M_2_PI * std::atan(s / width);
      case SwitchType::Tanh: return std::tanh(s / width);
    }
    return 0.0;
  }

  std::string validate() const;
  /// "sign", "sat", "relay", "atan", "tanh" -> type; false on an unknown name.
  static bool parse(const std::string& name, SwitchType& type);
  static const char* name(SwitchType type);
};
/// switching, switch_width (eqs 4.46-4.48).
const ParamTable<SwitchFunction>& switchingTable();

}  // namespace core
}  // namespace sowing_robot
