#include "sowing_robot/core/control/controller_factory.h"

#include <algorithm>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {

// The registered controllers: a new one is a row here (and its kind and params member in the header).
struct OuterEntry {
  const char* name;
  OuterKind kind;
  std::unique_ptr<OuterController> (*make)(const ControllerPair&);
  std::vector<ControllerParam> (*params)();
  std::string (*validate)(const ControllerPair&);  ///< its parameters' own checks beyond the table's ranges
};

struct InnerEntry {
  const char* name;  ///< the torque_controller's `inner` value
  InnerKind kind;
  std::unique_ptr<InnerController> (*make)(const ControllerPair&, const RobotParams&);
  std::vector<ControllerParam> (*params)();
  std::string (*validate)(const ControllerPair&);
};

bool always(const ControllerPair&, const std::string&) { return true; }
// nav2's RPP regulates the speed on curvature; plain pure pursuit has no minimum radius to act on.
bool ppActs(const ControllerPair& p, const std::string& key) {
  return key.rfind("regulated_", 0) != 0 || p.outer == OuterKind::rpp;
}
// The adaptation rates act only while the model estimates adapt (ATSMC, not TSMC).
bool slidingActs(const ControllerPair& p, const std::string& key) {
  return (key != "rate_m" && key != "rate_i") || p.sliding.adaptive;
}

/// `table`'s entries bound to the pair's `member`.
template <typename P>
std::vector<ControllerParam> bind(ControllerParam::Slot slot, const char* controller, const ParamTable<P>& table,
                                  P ControllerPair::*member,
                                  bool (*acts)(const ControllerPair&, const std::string&) = always) {
  std::vector<ControllerParam> out;
  for (const ParamEntry<P>& e : table.entries()) {
    const ParamEntry<P>* entry = &e;  // the tables are static
    out.push_back({slot, &e.info, controller, acts,
                   [entry, member](const ControllerPair& c) { return entry->get(c.*member); },
                   [entry, member](ControllerPair& c, const ParamValue& v) { entry->set(c.*member, v); }});
  }
  return out;
}
constexpr auto kOuterSlot = ControllerParam::Slot::outer;
constexpr auto kInnerSlot = ControllerParam::Slot::inner;
std::vector<ControllerParam> kanayamaParams() {
  return bind(kOuterSlot, "kanayama", kanayamaTable(), &ControllerPair::kanayama);
}
std::vector<ControllerParam> purePursuitParams() {
  return bind(kOuterSlot, "pure_pursuit", purePursuitTable(), &ControllerPair::pure_pursuit, ppActs);
}
std::vector<ControllerParam> slidingParams() {
  return bind(kInnerSlot, "sliding_mode", slidingModeTable(), &ControllerPair::sliding, slidingActs);
}
std::vector<ControllerParam> pidParams() { return bind(kInnerSlot, "pid", wheelPidTable(), &ControllerPair::pid); }

template <typename C, typename... Args>
std::unique_ptr<OuterController> outer(Args&&... args) {
  return std::make_unique<OuterAdapter<C>>(C(std::forward<Args>(args)...));
}
template <typename C, typename... Args>
std::unique_ptr<InnerController> inner(Args&&... args) {
  return std::make_unique<InnerAdapter<C>>(C(std::forward<Args>(args)...));
}

const OuterEntry kOuter[] = {
    {"kanayama", OuterKind::kanayama, [](const ControllerPair& p) { return outer<Kanayama>(p.kanayama); },
     kanayamaParams, [](const ControllerPair& p) { return p.kanayama.validate(); }},
    {"pure_pursuit", OuterKind::pure_pursuit,
     [](const ControllerPair& p) { return outer<PurePursuit>(p.pure_pursuit, false); }, purePursuitParams,
     [](const ControllerPair& p) { return p.pure_pursuit.validate(); }},
    {"rpp", OuterKind::rpp, [](const ControllerPair& p) { return outer<PurePursuit>(p.pure_pursuit, true); },
     purePursuitParams, [](const ControllerPair& p) { return p.pure_pursuit.validate(); }},
};

const InnerEntry kInner[] = {
    {"sliding_mode", InnerKind::sliding_mode,
     [](const ControllerPair& p, const RobotParams& r) { return inner<SlidingModeController>(p.sliding, r); },
     slidingParams, [](const ControllerPair& p) { return p.sliding.validate(); }},
    {"pid", InnerKind::pid, [](const ControllerPair& p, const RobotParams& r) { return inner<WheelPid>(p.pid, r); },
     pidParams, [](const ControllerPair& p) { return p.pid.validate(); }},
};

const OuterEntry& entry(OuterKind k) {
  for (const OuterEntry& e : kOuter)
    if (e.kind == k) return e;
  throw std::invalid_argument("outer controller kind not registered");
}
const InnerEntry& entry(InnerKind k) {
  for (const InnerEntry& e : kInner)
    if (e.kind == k) return e;
  throw std::invalid_argument("inner controller kind not registered");
}

}  // namespace

std::string ControllerPair::controllerName() const {
  return std::string(outerName(outer)) + "+" + innerName(inner, sliding.adaptive);
}

std::string ControllerPair::validateControllers() const {
  return firstError(
      {kanayama.validate(), sliding.validate(), entry(outer).validate(*this), entry(inner).validate(*this)});
}

const char* outerName(OuterKind k) {
  for (const OuterEntry& e : kOuter)
    if (e.kind == k) return e.name;
  return "?";
}

const char* innerName(InnerKind k, bool adaptive) {
  if (k == InnerKind::sliding_mode) return adaptive ? "atsmc" : "tsmc";  // one controller, two names
  for (const InnerEntry& e : kInner)
    if (e.kind == k) return e.name;
  return "?";
}

std::vector<std::pair<std::string, OuterKind>> outerChoices() {
  std::vector<std::pair<std::string, OuterKind>> out;
  for (const OuterEntry& e : kOuter) out.emplace_back(e.name, e.kind);
  return out;
}

std::vector<std::pair<std::string, InnerKind>> innerChoices() {
  std::vector<std::pair<std::string, InnerKind>> out;
  for (const InnerEntry& e : kInner) out.emplace_back(e.name, e.kind);
  return out;
}

std::string parseControllerPair(const std::string& name, OuterKind& outer, InnerKind& inner, bool& adaptive) {
  std::string outers, inners;
  for (const OuterEntry& e : kOuter) outers += (outers.empty() ? "" : "|") + std::string(e.name);
  for (const InnerEntry& e : kInner)
    inners += (inners.empty() ? "" : "|") + std::string(e.kind == InnerKind::sliding_mode ? "atsmc|tsmc" : e.name);
  const std::string allowed = " (outer " + outers + ", inner " + inners + ", e.g. kanayama+atsmc)";
  const auto plus = name.find('+');
  if (plus == std::string::npos || name.find('+', plus + 1) != std::string::npos)
    return "controller '" + name + "' is not outer+inner" + allowed;
  std::string o = name.substr(0, plus);
  const std::string i = name.substr(plus + 1);
  if (o == "pp") o = "pure_pursuit";  // the short name the benchmark's --controllers has always taken
  const OuterEntry* oe = nullptr;
  for (const OuterEntry& e : kOuter)
    if (o == e.name) oe = &e;
  if (oe == nullptr) return "unknown outer controller '" + name.substr(0, plus) + "' in '" + name + "'" + allowed;
  const InnerEntry* ie = nullptr;
  bool ad = adaptive;
  for (const InnerEntry& e : kInner) {
    if (e.kind == InnerKind::sliding_mode && (i == "atsmc" || i == "tsmc")) {
      ie = &e;
      ad = i == "atsmc";
    } else if (e.kind != InnerKind::sliding_mode && i == e.name) {
      ie = &e;
    }
  }
  if (ie == nullptr) return "unknown inner controller '" + i + "' in '" + name + "'" + allowed;
  outer = oe->kind;
  inner = ie->kind;
  adaptive = ad;
  return "";
}

std::vector<ControllerParam> chosenControllerParams(const ControllerPair& pair) {
  std::vector<ControllerParam> out = entry(pair.outer).params();
  for (ControllerParam& p : entry(pair.inner).params()) out.push_back(std::move(p));
  return out;
}

std::vector<ControllerParam> slotParams(ControllerParam::Slot slot) {
  std::vector<std::vector<ControllerParam> (*)()> lists;
  if (slot == kOuterSlot)
    for (const OuterEntry& e : kOuter) lists.push_back(e.params);
  else
    for (const InnerEntry& e : kInner) lists.push_back(e.params);
  std::vector<ControllerParam> out;
  for (std::size_t i = 0; i < lists.size(); ++i) {
    if (std::find(lists.begin(), lists.begin() + static_cast<std::ptrdiff_t>(i), lists[i]) !=
        lists.begin() + static_cast<std::ptrdiff_t>(i))
      continue;  // two entries of one table (pure_pursuit, rpp)
    for (ControllerParam& p : lists[i]()) out.push_back(std::move(p));
  }
  return out;
}

std::vector<std::string> controllersActingOn(ControllerParam::Slot slot, const ParamInfo* info) {
  std::vector<std::string> names;
  auto check = [&](const char* name, std::vector<ControllerParam> (*params)(), const ControllerPair& pair) {
    for (const ControllerParam& p : params())
      if (p.info == info && p.acts(pair, info->key)) names.push_back(name);
  };
  ControllerPair pair;
  if (slot == kOuterSlot) {
    for (const OuterEntry& e : kOuter) {
      pair.outer = e.kind;
      check(e.name, e.params, pair);
    }
  } else {
    for (const InnerEntry& e : kInner) {
      pair.inner = e.kind;
      check(e.name, e.params, pair);
    }
  }
  return names;
}

std::string validateSlot(const ControllerPair& pair, ControllerParam::Slot slot) {
  std::string e;
  if (slot == kOuterSlot)
    for (const OuterEntry& o : kOuter)
      if (e.empty()) e = o.validate(pair);
  if (slot == kInnerSlot)
    for (const InnerEntry& i : kInner)
      if (e.empty()) e = i.validate(pair);
  return e;
}

void copySlot(ControllerPair& to, const ControllerPair& from, ControllerParam::Slot slot) {
  if (slot == kOuterSlot)
    to.outer = from.outer;
  else
    to.inner = from.inner;
  for (const ControllerParam& p : slotParams(slot)) p.set(to, p.get(from));
}

std::unique_ptr<OuterController> makeOuterController(const ControllerPair& pair) {
  const std::string e = pair.validateControllers();
  if (!e.empty()) throw std::invalid_argument(e);
  return entry(pair.outer).make(pair);
}

std::unique_ptr<InnerController> makeInnerController(const ControllerPair& pair, const RobotParams& nominal) {
  const std::string e = pair.validateControllers();
  if (!e.empty()) throw std::invalid_argument(e);
  return entry(pair.inner).make(pair, nominal);
}

}  // namespace core
}  // namespace sowing_robot
