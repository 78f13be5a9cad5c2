// Soil patches: the patch lookup, the patches' validation naming the key, and the
// traction plant taking each wheel's grip from the patch under it; the tool's rule (tool_engagement.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/tool_engagement.h"

using namespace sowing_robot::core;

namespace {
SoilPatch box(double x0, double y0, double x1, double y1, double mu) {
  SoilPatch p;
  p.polygon = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  p.mu_peak = mu;
  p.mu_slide = 0.75 * mu;
  p.rolling_resistance = 0.05;
  return p;
}
}  // namespace

TEST(SoilMap, FindsThePatchAndTheLastListedWinsWhereTheyOverlap) {
  const SoilMap map({box(0, 0, 10, 10, 0.2), box(5, 5, 20, 20, 0.35)});
  EXPECT_EQ(map.patchAt({1, 1}), 0);
  EXPECT_EQ(map.patchAt({7, 7}), 1);  // both: the last one
  EXPECT_EQ(map.patchAt({15, 15}), 1);
  EXPECT_EQ(map.patchAt({-1, 1}), -1);
  EXPECT_EQ(map.patchAt({15, 2}), -1);  // in neither (inside the union's bounding box)
  EXPECT_EQ(SoilMap().patchAt({0, 0}), -1);
}

TEST(SoilMap, NonConvexPolygonUsesTheEvenOddRule) {
  // An L shape: the notch (upper right) is outside.
  SoilPatch l;
  l.polygon = {{0, 0}, {4, 0}, {4, 2}, {2, 2}, {2, 4}, {0, 4}};
  const SoilMap map({l});
  EXPECT_EQ(map.patchAt({1, 3}), 0);
  EXPECT_EQ(map.patchAt({3, 1}), 0);
  EXPECT_EQ(map.patchAt({3, 3}), -1);
}

TEST(SoilMap, BadPatchesAreRefusedNamingTheKey) {
  auto refused = [](SoilPatch p, const std::string& needle) {
    const std::string e = p.validate("field/patches[0]");
    EXPECT_NE(e.find(needle), std::string::npos) << "'" << e << "' should name " << needle;
    EXPECT_THROW(SoilMap({box(0, 0, 1, 1, 0.2), p}), std::invalid_argument) << needle;
    try {
      SoilMap({box(0, 0, 1, 1, 0.2), p});
    } catch (const std::invalid_argument& ex) {
      EXPECT_NE(std::string(ex.what()).find("field/patches[1]"), std::string::npos) << ex.what();
    }
  };
  EXPECT_EQ(box(0, 0, 1, 1, 0.2).validate("k"), "");
  SoilPatch p = box(0, 0, 1, 1, 0.2);
  p.polygon.resize(2);
  refused(p, "at least 3");
  p = box(0, 0, 1, 1, 0.2);
  p.polygon[1].x() = std::nan("");
  refused(p, "field/patches[0]/polygon[1]");
  p = box(0, 0, 1, 1, 0.2);
  p.mu_peak = -0.1;
  refused(p, "field/patches[0]/mu_peak");
  p = box(0, 0, 1, 1, 0.2);
  p.mu_slide = 0.3;  // above mu_peak
  refused(p, "field/patches[0]/mu_slide");
  p = box(0, 0, 1, 1, 0.2);
  p.rolling_resistance = std::numeric_limits<double>::infinity();
  refused(p, "field/patches[0]/rolling_resistance");
  p = box(0, 0, 1, 1, 0.2);
  p.rolling_resistance = -0.01;
  refused(p, "field/patches[0]/rolling_resistance");
}

// A patch's edges: a bow-tie (its edges cross, and its two lobes cancel in the signed area) and a patch drawn as
// a line are refused naming the patch; overlapping patches are allowed (the last listed holds) and noted once.
TEST(SoilMap, CrossingOrZeroAreaPatchesAreRefusedNamingThePatch) {
  SoilPatch bow = box(0, 0, 1, 1, 0.2);
  bow.polygon = {{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  std::string e = bow.validate("field/patches[1]");
  EXPECT_EQ(e.rfind("field/patches[1]/polygon crosses itself", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_THROW(SoilMap({box(0, 0, 1, 1, 0.2), bow}), std::invalid_argument);
  SoilPatch flat = box(0, 0, 1, 1, 0.2);
  flat.polygon = {{0, 0}, {1, 1}, {2, 2}};
  e = flat.validate("field/patches[0]");
  EXPECT_EQ(e.rfind("field/patches[0]/polygon has zero area", 0), 0u) << e;
  flat.polygon = {{3, 3}, {3, 3}, {3, 3}, {3, 3}};
  e = flat.validate("field/patches[0]");
  EXPECT_EQ(e.rfind("field/patches[0]/polygon has zero area", 0), 0u) << e;
  // Either sense and a non-convex shape are fine.
  SoilPatch l = box(0, 0, 1, 1, 0.2);
  l.polygon = {{0, 4}, {2, 4}, {2, 2}, {4, 2}, {4, 0}, {0, 0}};
  EXPECT_EQ(l.validate("k"), "");
}

TEST(SoilMap, OverlappingPatchesAreNotedOnceLastListedHolds) {
  EXPECT_EQ(patchOverlapNote({box(0, 0, 1, 1, 0.2), box(1, 0, 2, 1, 0.3)}), "");  // sharing an edge only
  EXPECT_EQ(patchOverlapNote({}), "");
  const std::string note = patchOverlapNote(
      {box(0, 0, 10, 10, 0.2), box(20, 0, 30, 10, 0.3), box(5, 5, 25, 8, 0.25), box(40, 0, 41, 1, 0.3)});
  EXPECT_EQ(note,
            "soil patches overlap (field/patches[0] and [2], field/patches[1] and [2]): where they do, the one listed "
            "last holds");
  // Also a patch wholly inside another (a wet strip drawn over a larger patch).
  EXPECT_NE(patchOverlapNote({box(0, 0, 10, 10, 0.2), box(2, 2, 3, 3, 0.3)}), "");
}

// A patch's grip beyond the field's slip curve (slip_stiffness 8 x slip_peak 0.15 = 1.2 < mu_peak) is
// refused by the plant naming the patch.
TEST(SoilMap, PlantRefusesAPatchTheSlipCurveCannotCarry) {
  TractionPlant plant(RobotParams{}, PlantDisturbance{}, TractionParams{});
  try {
    plant.setSoil(SoilMap({box(0, 0, 1, 1, 2.0)}));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("field/patches[0]"), std::string::npos) << e.what();
  }
}

namespace {
// Drive straight along +x with equal torques from x0 for `seconds`; returns the plant.
TractionPlant driveStraight(const SoilMap& soil, double tau, double seconds, double x0 = 0.0) {
  TractionParams t;  // mu 0.6 elsewhere
  TractionPlant plant(RobotParams{}, PlantDisturbance{}, t);
  plant.setSoil(soil);
  State s = State::Zero();
  s[X] = x0;
  plant.reset(s);
  for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) plant.step(tau, tau, 1e-3);
  return plant;
}
}  // namespace

// Torque beyond what mu 0.2 carries (0.2 x 74 N x 0.095 m = 1.4 N·m per wheel) spins the wheels on the wet
// patch, not on the default soil: the patch is where the robot is, and nowhere else.
TEST(SoilMap, WheelsSlipOnTheWetPatchOnly) {
  const double tau = 3.0;
  const SoilMap wet({box(-1, -5, 100, 5, 0.2)});
  const TractionPlant on_wet = driveStraight(wet, tau, 1.0);
  const TractionPlant on_dry = driveStraight(SoilMap(), tau, 1.0);
  const TractionPlant beside = driveStraight(SoilMap({box(-1, 10, 100, 20, 0.2)}), tau, 1.0);
  EXPECT_EQ(on_wet.patchUnder(RIGHT), 0);
  EXPECT_EQ(on_wet.patchUnder(LEFT), 0);
  EXPECT_EQ(beside.patchUnder(RIGHT), -1);
  EXPECT_GT(std::fabs(on_wet.slipRatio(RIGHT)), 0.5);  // spinning
  EXPECT_LT(std::fabs(on_dry.slipRatio(RIGHT)), 0.15);
  EXPECT_LT(on_wet.state()[V], on_dry.state()[V]);
  // The ground force is capped by the patch's grip.
  EXPECT_LE(std::fabs(on_wet.groundForce(RIGHT)), 0.2 * on_wet.normalLoads().right + 1e-9);
  // A patch nobody drives over changes nothing at all.
  EXPECT_EQ(beside.state(), on_dry.state());
}

// One wheel on the wet patch (the patch ends at y = 0, the left wheel at y = +0.24 is on it, the right
// at -0.24 is not): the left wheel slips, the right one pushes harder and turns the robot left.
TEST(SoilMap, OneWheelOnTheWetPatchTurnsTheRobot) {
  // 0.3 s: long enough to turn, short enough that the turn has not yet carried the right wheel onto it.
  const TractionPlant p = driveStraight(SoilMap({box(-1, 0, 100, 5, 0.2)}), 3.0, 0.3);
  EXPECT_EQ(p.patchUnder(LEFT), 0);
  EXPECT_EQ(p.patchUnder(RIGHT), -1);
  EXPECT_GT(std::fabs(p.slipRatio(LEFT)), std::fabs(p.slipRatio(RIGHT)));
  EXPECT_GT(p.state()[THETA], 1e-3);  // more push on the right wheel: a left turn (theta grows)
}

TEST(ToolEngagement, LowersOnTheRowRaisesBeyondItsEnds) {
  SeedingParams sp;  // engage_distance 0.01
  ToolEngagement tool(sp, {{{0.0, 3.0}, {100.0, 3.0}}});
  EXPECT_FALSE(tool.update({-1.0, 3.0}));   // before the row
  EXPECT_FALSE(tool.update({5.0, 3.5}));    // beside it, too far to lower
  EXPECT_TRUE(tool.update({5.0, 3.005}));   // within engage_distance: down (the seed drill's rule)
  EXPECT_TRUE(tool.update({50.0, 4.2}));    // a detour: stays down
  EXPECT_FALSE(tool.update({100.5, 3.0}));  // past the end (a headland turn): up
  EXPECT_FALSE(tool.update({99.0, 3.5}));   // back inside but off the row: stays up
  EXPECT_TRUE(tool.update({99.0, 3.0}));
  EXPECT_TRUE(tool.update({std::nan(""), 3.0}));  // a bad point changes nothing
  ToolEngagement line(sp, {{{0.0, 3.0}, {10.0, 3.0}}}, true);
  EXPECT_TRUE(line.update({5.0, 3.0}));
  EXPECT_TRUE(line.update({50.0, 3.0}));  // open-ended: no far end
}
