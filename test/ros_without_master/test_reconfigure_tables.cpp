// Every dynamic_reconfigure field is the parameter-table entry of the same key, with the table's
// default, and its range is the table's where the table's is finite (dynamic_reconfigure clamps
// silently to its own; the node's validation then has the last word). A .cfg edited out of step with
// a table fails here.
#include <gtest/gtest.h>

#include <boost/any.hpp>
#include <cmath>
#include <string>

#include "sowing_robot/KinematicControllerConfig.h"
#include "sowing_robot/PurePursuitConfig.h"
#include "sowing_robot/ReferenceGeneratorConfig.h"
#include "sowing_robot/TorqueControllerConfig.h"
#include "sowing_robot/WheelPidConfig.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/pure_pursuit.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/wheel_pid.h"
#include "sowing_robot/core/planning/potential_field.h"

using namespace sowing_robot;

namespace {
double number(const boost::any& a) {
  if (a.type() == typeid(double)) return boost::any_cast<double>(a);
  if (a.type() == typeid(int)) return boost::any_cast<int>(a);
  return NAN;
}

template <typename Config, typename S>
void expectCfgMatchesTable(const core::ParamTable<S>& table) {
  const Config def = Config::__getDefault__(), lo = Config::__getMin__(), hi = Config::__getMax__();
  int fields = 0;
  for (const auto& d : Config::__getParamDescriptions__()) {
    ++fields;
    const core::ParamEntry<S>* e = table.find(d->name);
    ASSERT_NE(e, nullptr) << d->name << " is in the .cfg but no entry of the table";
    boost::any v, vlo, vhi;
    d->getValue(def, v);
    d->getValue(lo, vlo);
    d->getValue(hi, vhi);
    const core::ParamValue& want = e->info.default_value;
    if (const std::string* s = std::get_if<std::string>(&want)) {
      EXPECT_EQ(boost::any_cast<std::string>(v), *s) << d->name << ": .cfg default";
      continue;
    }
    const double table_default = std::holds_alternative<int>(want) ? std::get<int>(want) : std::get<double>(want);
    EXPECT_EQ(number(v), table_default) << d->name << ": .cfg default";
    const core::Limits& l = e->info.limits;
    if (std::isfinite(l.lo)) EXPECT_EQ(number(vlo), l.lo) << d->name << ": .cfg min";
    if (std::isfinite(l.hi)) EXPECT_EQ(number(vhi), l.hi) << d->name << ": .cfg max";
    EXPECT_GE(number(vhi), table_default) << d->name << ": .cfg max below the default";
    EXPECT_LE(number(vlo), table_default) << d->name << ": .cfg min above the default";
  }
  EXPECT_GT(fields, 0);
}
}  // namespace

TEST(ReconfigureTables, KinematicController) {
  expectCfgMatchesTable<KinematicControllerConfig>(core::kanayamaTable());
}
TEST(ReconfigureTables, TorqueController) { expectCfgMatchesTable<TorqueControllerConfig>(core::slidingModeTable()); }
TEST(ReconfigureTables, ReferenceGenerator) {
  expectCfgMatchesTable<ReferenceGeneratorConfig>(core::potentialFieldTable());
}
TEST(ReconfigureTables, PurePursuit) { expectCfgMatchesTable<PurePursuitConfig>(core::purePursuitTable()); }
TEST(ReconfigureTables, WheelPid) { expectCfgMatchesTable<WheelPidConfig>(core::wheelPidTable()); }
