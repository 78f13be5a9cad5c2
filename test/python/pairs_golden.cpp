// Golden closed-loop runs of every controller pair and one PSO tuning, written by the C++ core and read by
// the Python tests (test/python/test_core_pairs.py): sowing_robot.core.run() and tune() must give these
// numbers to the last bit. This gtest checks the file against the core, so a change of the core shows up
// here first; SOWING_WRITE_GOLDEN=1 devel/lib/sowing_robot/test_pairs_golden rewrites it after a
// deliberate change.
// Format (doubles as C99 hex floats, %a, which Python's float.fromhex reads exactly):
//   case NAME PAIR               a run of 4 s on the thesis line, disturbance on, mismatch 1.2
//   param NODE KEY VALUE         a controller parameter (core::setControllerParam; VALUE hex or a word)
//   metrics AXIS ise itse iae itae rise_time settling_time overshoot peak
//   final x y theta v omega phi_r phi_l
//   counts PERIODS SATURATED_STEPS
//   end
//   tune PAIR PARTICLES ITERATIONS SEED  a tuneGains run (2 s line, same plant), default bounds of the pair
//   best COST INITIAL_BEST_COST
//   gain NAME VALUE              the best gains, in the bounds' order
//   end
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "golden_file.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {

std::string hex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

struct Param {
  std::string node, key;
  ParamValue value;
};
struct Case {
  std::string name, pair;
  std::vector<Param> params;
};

Scenario scenarioOf(const std::string& pair, double duration) {
  Scenario sc;
  sc.duration = duration;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  const std::string e = parseControllerPair(pair, sc.outer, sc.inner, sc.sliding.adaptive);
  EXPECT_EQ(e, "");
  return sc;
}

std::string golden() {
  const std::vector<Case> cases = {
      {"kanayama_atsmc", "kanayama+atsmc", {}},
      {"kanayama_tsmc", "kanayama+tsmc", {}},
      {"kanayama_pid", "kanayama+pid", {}},
      {"rpp_pid", "rpp+pid", {}},
      {"rpp_atsmc", "rpp+atsmc", {}},
      // On the thesis line RPP's regulation with nav2's 0.9 m radius never acts (plain pure pursuit gives
      // the same run); a 3 m radius makes it act.
      {"pure_pursuit_pid", "pure_pursuit+pid", {{"kinematic_controller", "lookahead_dist", 0.35}}},
      {"rpp_pid_regulated",
       "rpp+pid",
       {{"kinematic_controller", "lookahead_dist", 0.35},
        {"kinematic_controller", "regulated_linear_scaling_min_radius", 3.0}}},
      {"atsmc_eq_4_22", "kanayama+atsmc", {{"torque_controller", "adaptation", std::string("eq_4_22")}}},
      {"rpp_pid_gains",
       "rpp+pid",
       {{"kinematic_controller", "lookahead_dist", 0.45},
        {"kinematic_controller", "k_along", 2.0},
        {"torque_controller", "kp", 6.5},
        {"torque_controller", "kd", 0.05},
        {"torque_controller", "anti_windup", false}}},
      {"atsmc_rates", "kanayama+atsmc", {{"torque_controller", "rate_m", 2.5}, {"kinematic_controller", "kx", 4.0}}},
  };
  std::ostringstream out;
  out << "# Golden closed-loop runs and a PSO tuning, written by test/python/pairs_golden.cpp (format there);\n"
         "# SOWING_WRITE_GOLDEN=1 devel/lib/sowing_robot/test_pairs_golden rewrites it.\n";
  for (const Case& c : cases) {
    Scenario sc = scenarioOf(c.pair, 4.0);
    out << "case " << c.name << ' ' << c.pair << '\n';
    for (const Param& p : c.params) {
      EXPECT_EQ(setControllerParam(sc, p.node, p.key, p.value), "") << c.name;
      std::string v;
      if (std::holds_alternative<double>(p.value))
        v = hex(std::get<double>(p.value));
      else
        v = formatValue(p.value);
      out << "param " << p.node << ' ' << p.key << ' ' << v << '\n';
    }
    LineReference ref;
    const RunResult r = runClosedLoop(sc, ref);
    const char* axes[AXIS_COUNT] = {"x", "y", "theta"};
    for (int a = 0; a < AXIS_COUNT; ++a) {
      const AxisMetrics& m = r.metrics[a];
      out << "metrics " << axes[a];
      for (double v : {m.ise, m.itse, m.iae, m.itae, m.rise_time, m.settling_time, m.overshoot, m.peak})
        out << ' ' << hex(v);
      out << '\n';
    }
    out << "final";
    for (int i = 0; i < r.final_state.size(); ++i) out << ' ' << hex(r.final_state[i]);
    out << "\ncounts " << r.periods << ' ' << r.saturated_steps << "\nend\n";
  }
  // One small tuning per inner kind (2 threads: the result does not depend on them).
  for (const char* pair : {"rpp+pid", "kanayama+atsmc"}) {
    const Scenario sc = scenarioOf(pair, 2.0);
    PsoParams p;
    p.particles = 5;
    p.iterations = 3;
    p.seed = 7;
    p.threads = 2;
    p.max_velocity_fraction = 0.2;  // config/pso.yaml's, as sowing_robot.core.tune's default
    const std::vector<GainBounds> box = defaultGainBounds(sc);
    LineReference ref;
    const TuningResult r = tuneGains(sc, ref, box, TuningObjective{}, p);
    out << "tune " << pair << ' ' << p.particles << ' ' << p.iterations << ' ' << p.seed << '\n';
    out << "best " << hex(r.pso.best_cost) << ' ' << hex(r.initial_best_cost) << '\n';
    for (std::size_t d = 0; d < box.size(); ++d) out << "gain " << box[d].name << ' ' << hex(r.best_gains[d]) << '\n';
    out << "end\n";
  }
  return out.str();
}

}  // namespace

TEST(PairsGolden, FileMatchesTheCore) { expectGoldenFile(golden(), SOWING_GOLDEN_PATH, "runs"); }
