// The thesis field (config/field_thesis.yaml) as the core closed-loop tests set it up: one 100 m row at
// y = 3 from x = 0, the potential field of the thesis (alpha = beta = 4, d = 0.5, k = 5, tangential 1),
// obstacles of radius 0.3 m at x = 20, 50, 80 on the row. Shared by test_approach and test_avoidance.
#pragma once

#include "sowing_robot/core/simulation/field_run.h"

namespace sowing_robot {
namespace core {
namespace test {

/// The thesis field's closed loop with the scenario's defaults (ATSMC, disturbance 2.75 N m at 3 rad/s,
/// 20 % mismatch, start (-1, 0, 0), 1 kHz): 110 s, plus the time the approach to the row adds, so the run
/// ends at the row's end as it did without the approach.
inline FieldRunSetup thesisField() {
  FieldRunSetup s;
  s.scenario.duration = 110.0;
  s.field.rows = 1;
  s.field.row_length = 100.0;
  s.field.start_x = 0.0;
  s.field.start_y = 3.0;
  s.field.potential.alpha = 4.0;
  s.field.potential.beta = 4.0;
  s.field.potential.influence_distance = 0.5;
  s.field.potential.gain = 5.0;
  s.field.potential.tangential_ratio = 1.0;
  s.obstacles = {{20.0, 3.0, 0.3}, {50.0, 3.0, 0.3}, {80.0, 3.0, 0.3}};
  s.scenario.duration += approachExtraTime(s);
  return s;
}

/// From `time` on [s] (once), `obstacle` is added at run time: to the reference (re-planned) and to the contact
/// monitor, and the seeds are scored against it; `added` says whether it was.
inline void addObstacleAtRunTime(FieldRunSetup& s, double time, const Obstacle& obstacle, bool& added) {
  s.scoring_obstacles = {obstacle};
  s.on_step = [time, obstacle, &added](double t, FieldSource& reference, ContactMonitor& contacts) {
    if (added || t < time) return;
    reference.setObstacles({obstacle});
    contacts.setObstacles({obstacle});
    added = true;
  };
}

}  // namespace test
}  // namespace core
}  // namespace sowing_robot
