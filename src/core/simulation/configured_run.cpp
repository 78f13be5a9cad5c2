#include "sowing_robot/core/simulation/runner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/tool_engagement.h"
#include "sowing_robot/core/simulation/closed_loop.h"

namespace sowing_robot {
namespace core {

namespace {

/// What the simulation knows beyond the measurements at a no-traction verdict: the grip budget of the soil
/// under the robot there (no slip: nothing to say).
template <typename PlantT>
std::string gripDiagnosis(const Scenario& sc, const LoopConfig& cfg, const PlantT& plant, const Pose2D& where) {
  if constexpr (!PlantT::kTraction) {
    return "";
  } else {
    return core::gripDiagnosis(sc.robot, sc.disturbance.mass_scale, *cfg.traction, plant.plant.soil(),
                               {where.x, where.y});
  }
}

template <typename PlantT>
LoopResult run(const Scenario& sc, const LoopConfig& cfg, PlantT& plant, ReferenceSource& reference, bool keep_samples,
               const std::function<void(const EstimatedSample&)>& trace) {
  plant.plant.setMotor(cfg.motor);
  std::unique_ptr<OuterController> outer = makeOuterController(sc);
  std::unique_ptr<InnerController> inner = makeInnerController(sc, sc.robot);
  SensorFeed feed(sc, cfg);
  ToolRule tool{PlantT::kTraction && cfg.traction && cfg.traction->draft_force > 0.0, cfg.tool,
                ToolEngagement(cfg.seeding, cfg.tool_rows, cfg.tool_rows_open_ended)};
  LoopLayers layers;
  layers.tool = &tool;
  if (cfg.traction) layers.high_slip = 2.0 * cfg.traction->slip_peak;
  std::optional<CommandLimiter> limiter;
  if (cfg.limits.enabled) {
    limiter.emplace(cfg.limits);
    layers.limiter = &*limiter;
  }
  std::optional<TractionControl> traction_control;
  std::optional<TractionMonitor> monitor;
  if (cfg.traction_control.enabled) {
    traction_control.emplace(cfg.traction_control, sc.robot.L);
    layers.traction_control = &*traction_control;
    monitor.emplace(cfg.traction_control);
    layers.monitor = &*monitor;
    layers.hold_on_wheels = cfg.feedback == Feedback::fused;
  }
  std::optional<HitchControl> hitch;
  if (cfg.hitch_control.enabled) {
    hitch.emplace(cfg.hitch_control);
    layers.hitch = &*hitch;
  }
  std::optional<GovernedReference> governed;
  if (cfg.speed_governor.enabled) {
    governed.emplace(reference, cfg.speed_governor);
    layers.governor = &*governed;
    layers.governed_time_back = cfg.governed_time_back;
  }
  LoopResult out = closedLoop(sc, plant, feed, *outer, *inner, governed ? *governed : reference, keep_samples, trace,
                              RunStop{}, layers);
  if (hitch) out.hitch_raises = hitch->raises();
  if (out.no_traction.detected) out.no_traction.diagnosis = gripDiagnosis(sc, cfg, plant, out.no_traction.where);
  return out;
}

}  // namespace

LoopResult runClosedLoop(const Scenario& sc, const LoopConfig& cfg, ReferenceSource& reference, bool keep_samples,
                         const std::function<void(const EstimatedSample&)>& trace) {
  std::string e = firstError({sc.validate(), cfg.validate()});
  if (e.empty() && cfg.traction) {  // the motors against the heaviest going: the worst soil's rolling resistance
    double rolling = cfg.traction->rolling_resistance, draft_factor = 1.0;
    for (const SoilPatch& p : cfg.patches) {
      rolling = std::max(rolling, p.rolling_resistance);
      draft_factor = std::max(draft_factor, p.draft_factor);
    }
    // The draft at the nominal depth on the stickiest soil (toolDraft: draft_force on the field's soil).
    e = checkMotorsCanMove(cfg.motor, sc.robot, sc.disturbance.mass_scale, rolling,
                           cfg.traction->draft_force * draft_factor);
  }
  if (!e.empty()) throw std::invalid_argument(e);
  if (!cfg.traction) {
    NoSlipPlant plant{Plant(sc.robot, sc.disturbance), sc.robot.L};
    return run(sc, cfg, plant, reference, keep_samples, trace);
  }
  SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, *cfg.traction), sc.robot.R};
  plant.plant.setSoil(SoilMap(cfg.patches));
  plant.plant.setToolPoint(cfg.tool);
  return run(sc, cfg, plant, reference, keep_samples, trace);
}

}  // namespace core
}  // namespace sowing_robot
