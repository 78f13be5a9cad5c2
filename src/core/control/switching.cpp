#include "sowing_robot/core/control/switching.h"

#include <cmath>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<SwitchFunction>& switchingTable() {
  using F = SwitchFunction;
  static const ParamTable<F> table({
      choice("switching", &F::type, SwitchType::Sign,
             {{"sign", SwitchType::Sign},
              {"sat", SwitchType::Saturation},
              {"relay", SwitchType::Relay},
              {"atan", SwitchType::Atan},
              {"tanh", SwitchType::Tanh}},
             "switching function of the reaching law (eqs 4.46-4.48)"),
      number("switch_width", &F::width, 0.01, Limits::positive(), "",
             "boundary layer phi (sat, tanh) / relay delta / atan width; unused by sign"),
  });
  return table;
}

SwitchFunction::SwitchFunction() { switchingTable().applyDefaults(*this); }

std::string SwitchFunction::validate() const { return switchingTable().checkRanges(*this); }

bool SwitchFunction::parse(const std::string& n, SwitchType& t) {
  for (SwitchType c :
       {SwitchType::Sign, SwitchType::Saturation, SwitchType::Relay, SwitchType::Atan, SwitchType::Tanh}) {
    if (n == name(c)) {
      t = c;
      return true;
    }
  }
  return false;
}

const char* SwitchFunction::name(SwitchType t) {
  switch (t) {
    case SwitchType::Sign: return "sign";
    case SwitchType::Saturation: return "sat";
    case SwitchType::Relay: return "relay";
    case SwitchType::Atan: return "atan";
    case SwitchType::Tanh: return "tanh";
  }
  return "?";
}

}  // namespace core
}  // namespace sowing_robot
