#include "sowing_robot/core/control/controllers.h"

namespace sowing_robot {
namespace core {

const char* outerName(OuterKind k) {
  switch (k) {
    case OuterKind::kanayama: return "kanayama";
    case OuterKind::pure_pursuit: return "pure_pursuit";
    case OuterKind::rpp: return "rpp";
  }
  return "?";
}

const char* innerName(InnerKind k, bool adaptive) {
  if (k == InnerKind::pid) return "pid";
  return adaptive ? "atsmc" : "tsmc";
}

std::string parseControllerPair(const std::string& name, OuterKind& outer, InnerKind& inner, bool& adaptive) {
  const std::string allowed = " (outer kanayama|pure_pursuit|rpp, inner atsmc|tsmc|pid, e.g. kanayama+atsmc)";
  const auto plus = name.find('+');
  if (plus == std::string::npos || name.find('+', plus + 1) != std::string::npos)
    return "controller '" + name + "' is not outer+inner" + allowed;
  const std::string o = name.substr(0, plus), i = name.substr(plus + 1);
  OuterKind ok;
  if (o == "kanayama")
    ok = OuterKind::kanayama;
  else if (o == "pure_pursuit" || o == "pp")
    ok = OuterKind::pure_pursuit;
  else if (o == "rpp")
    ok = OuterKind::rpp;
  else
    return "unknown outer controller '" + o + "' in '" + name + "'" + allowed;
  InnerKind ik;
  bool ad = adaptive;
  if (i == "atsmc") {
    ik = InnerKind::sliding_mode;
    ad = true;
  } else if (i == "tsmc") {
    ik = InnerKind::sliding_mode;
    ad = false;
  } else if (i == "pid") {
    ik = InnerKind::pid;
  } else {
    return "unknown inner controller '" + i + "' in '" + name + "'" + allowed;
  }
  outer = ok;
  inner = ik;
  adaptive = ad;
  return "";
}

}  // namespace core
}  // namespace sowing_robot
