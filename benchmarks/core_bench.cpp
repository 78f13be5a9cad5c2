// core_bench: Google Benchmark figures of the ROS-free core (issue 8). Figures only, never a pass/fail.
//   core_bench [--benchmark_min_time=0.2] [--benchmark_filter=Thesis] ...
// BM_PlantRk4Step            one Plant::step (RK4, sinusoidal disturbance on)
// BM_ControlStep             one period of runClosedLoop's loop: reference next + Kanayama + SMC + plant
// BM_ThesisRun25s            runClosedLoop of the 25 s thesis scenario at 1 kHz (keep_samples = false);
//                            items/s = control steps/s
// BM_ThesisRun25sTimeDomain  same with the time-domain figures (keep_samples = true: streaming, O(1) memory)
// BM_MonteCarlo1000Runs/threads:N  runMonteCarlo of 1,000 seeded runs of the thesis line, kanayama+atsmc,
//                            every metric (mc_benchmark's work without the files), N threads; wall time
// BM_ThesisRun25sTraction    same with the traction plant (TractionParams defaults), issue 16's cost case
// BM_ThesisRun25sDriveTrain/layers:N  the traction run with the DC motors (1) and traction control too (2)
// BM_ThesisRunPotentialField same with the potential-field reference (obstacles (20,3), (50,3), (80,3))
// BM_PsoIteration/threads:N  one PSO iteration: 20 particles evaluated on the thesis scenario (ITAE,
//                            default gain box), N evaluation threads; wall time (UseRealTime)
#include <benchmark/benchmark.h>

#include <optional>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/simulation/closed_loop.h"
#include "sowing_robot/core/simulation/runner.h"
#include "thesis_scenario.h"

using namespace sowing_robot;
using namespace sowing_robot::core;

namespace {

volatile double g_sink = 0.0;  // keeps results alive (see thesisRun)

void BM_PlantRk4Step(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  Plant plant(sc.robot, sc.disturbance);
  State x0 = State::Zero();
  x0[X] = -1.0;
  x0[V] = 1.0;
  plant.reset(x0, 0.0);
  const double dt = 1e-3;
  std::int64_t k = 0;
  for (auto _ : state) {
    // Small torques that keep the state bounded over any number of steps.
    plant.step(0.5 * ((k & 1) ? 1.0 : -1.0), 0.3, dt);
    if (++k == 25000) {
      plant.reset(x0, 0.0);
      k = 0;
    }
    benchmark::DoNotOptimize(plant.state().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PlantRk4Step);

void BM_ControlStep(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  bench::ControlLoop loop(sc, ref);
  for (auto _ : state) {
    loop.step();
    benchmark::DoNotOptimize(loop.plant().state().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ControlStep);

void thesisRun(benchmark::State& state, ReferenceSource& ref) {
  const Scenario sc = bench::thesisScenario();
  // A volatile sink, not DoNotOptimize(double&): libbenchmark 1.7's "+m,r" constraint can corrupt a
  // double under GCC -O3 (fixed upstream in 1.8).
  volatile double itae = 0.0;
  for (auto _ : state) {
    const RunResult r = runClosedLoop(sc, ref, false);
    itae = r.metrics[AXIS_Y].itae;
  }
  // States are evaluated at k = 0..steps(); steps() plant steps per run.
  state.SetItemsProcessed(state.iterations() * sc.steps());
  state.counters["itae_y"] = benchmark::Counter(itae, benchmark::Counter::kDefaults);
}

void BM_ThesisRun25s(benchmark::State& state) {
  LineReference ref = bench::thesisLine();
  thesisRun(state, ref);
}
BENCHMARK(BM_ThesisRun25s)->Unit(benchmark::kMillisecond);

void BM_ThesisRun25sTimeDomain(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  volatile double settling = 0.0;
  for (auto _ : state) {
    const RunResult r = runClosedLoop(sc, ref, true);
    settling = r.metrics[AXIS_Y].settling_time;
  }
  state.SetItemsProcessed(state.iterations() * sc.steps());
  state.counters["settling_y"] = benchmark::Counter(settling, benchmark::Counter::kDefaults);
}
BENCHMARK(BM_ThesisRun25sTimeDomain)->Unit(benchmark::kMillisecond);

// The issue-17 target: 1,000 runs of the 25 s line in under 3 s wall on 2 cores, >= 1.8x from 1 to 2
// threads. The Monte-Carlo runner's own scenario (Scenario defaults: the thesis line, start (-1, 0, 0))
// and spec (MonteCarloSpec defaults: mismatch, disturbance, noise and start drawn per run), as
// `mc_benchmark --controllers kanayama+atsmc --seeds 1000` runs it.
void BM_MonteCarlo1000Runs(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const Scenario sc;
  const LineReference ref(1.0, 3.0, 0.0);
  const MonteCarloSpec spec;
  constexpr std::int64_t runs = 1000;
  volatile double ise = 0.0;
  for (auto _ : state) {
    const std::vector<RunRow> rows = runMonteCarlo(sc, ref, spec, runs, threads);
    ise = rows.back().metrics[AXIS_Y].ise;
  }
  state.SetItemsProcessed(state.iterations() * runs * sc.steps());
  state.counters["runs/s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * runs), benchmark::Counter::kIsRate);
  state.counters["ise_y_last"] = benchmark::Counter(ise, benchmark::Counter::kDefaults);
}
BENCHMARK(BM_MonteCarlo1000Runs)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// The same run with the traction plant (issue 16: at most 2x BM_ThesisRun25s). Default soil (loose moist
// soil, mu 0.6, 4 sub-steps, rolling resistance 0.05): the thesis start's 100 N·m spins the wheels.
void BM_ThesisRun25sTraction(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  const TractionParams traction;
  const std::function<void(const LoopSample&)> no_trace;
  volatile double itae = 0.0;
  for (auto _ : state) {
    // The one loop on the traction plant, fed its own state (no sensors), as runClosedLoop feeds the Plant.
    SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, traction), sc.robot.R};
    StateFeed feed;
    Kanayama outer(sc.kanayama);
    SlidingModeController inner(sc.sliding, sc.robot);
    itae = closedLoop(sc, plant, feed, outer, inner, ref, false, no_trace, RunStop{}).run.metrics[AXIS_Y].itae;
  }
  state.SetItemsProcessed(state.iterations() * sc.steps());
  state.counters["itae_y"] = benchmark::Counter(itae, benchmark::Counter::kDefaults);
}
BENCHMARK(BM_ThesisRun25sTraction)->Unit(benchmark::kMillisecond);

// The drive train's cost (issue 26: motor model and traction control at most 20 % of a traction-plant run):
// BM_ThesisRun25sTraction with the DC motors (arg 1), and with the traction control too (arg 2: the table's
// defaults; arg 3: the field profile's with the max_ground_accel option of results/drive_train.md); arg 0 is
// BM_ThesisRun25sTraction itself, so the ratios come from one program run.
void BM_ThesisRun25sDriveTrain(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  const TractionParams traction;
  MotorParams motor;
  motor.enabled = state.range(0) >= 1;
  TractionControlParams tc_params;
  tc_params.enabled = state.range(0) >= 2;
  if (state.range(0) >= 3) {  // config/profiles/field.yaml's traction control, the ground-speed option on
    tc_params.slip_target = 0.1;
    tc_params.max_ground_accel = 1.0;
    tc_params.raise_rate = 10.0;
    tc_params.speed_floor = 0.3;
    tc_params.min_torque = 1.4;
    tc_params.anti_windup = true;
  }
  const std::function<void(const LoopSample&)> no_trace;
  volatile double itae = 0.0;
  for (auto _ : state) {
    SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, traction), sc.robot.R};
    plant.plant.setMotor(motor);
    StateFeed feed;
    Kanayama outer(sc.kanayama);
    SlidingModeController inner(sc.sliding, sc.robot);
    std::optional<TractionControl> tc;
    LoopLayers layers;
    if (tc_params.enabled) layers.traction_control = &tc.emplace(tc_params, sc.robot.L);
    itae = closedLoop(sc, plant, feed, outer, inner, ref, false, no_trace, RunStop{}, layers).run.metrics[AXIS_Y].itae;
  }
  state.SetItemsProcessed(state.iterations() * sc.steps());
  state.counters["itae_y"] = benchmark::Counter(itae, benchmark::Counter::kDefaults);
}
BENCHMARK(BM_ThesisRun25sDriveTrain)->ArgName("layers")->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

void BM_ThesisRunPotentialField(benchmark::State& state) {
  PotentialField ref = bench::thesisPotentialField();
  thesisRun(state, ref);
}
BENCHMARK(BM_ThesisRunPotentialField)->Unit(benchmark::kMillisecond);

void BM_PsoIteration(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const Scenario sc = bench::thesisScenario();
  const LineReference ref = bench::thesisLine();
  const std::vector<GainBounds> bounds = defaultGainBounds();
  const TuningProblem problem(sc, ref, bounds, TuningObjective{}, threads);
  PsoParams pso;  // 20 particles, config/pso.yaml's velocity clamp
  pso.max_velocity_fraction = 0.2;
  pso.iterations = 0;  // the initial evaluation only: one iteration's worth of 20 runs
  pso.threads = threads;
  for (const auto& b : bounds) {
    pso.lower.push_back(b.lower);
    pso.upper.push_back(b.upper);
  }
  std::uint64_t seed = 1;
  long evaluations = 0;
  for (auto _ : state) {
    pso.seed = seed++;  // a fresh swarm each time, so no run is special
    const PsoResult r =
        psoMinimize(pso, [&problem](const std::vector<double>& x, int t) { return problem.evaluate(x, t).total; });
    evaluations += r.evaluations;
    g_sink = r.best_cost;
  }
  state.SetItemsProcessed(evaluations * sc.steps());
  state.counters["evaluations/s"] = benchmark::Counter(static_cast<double>(evaluations), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PsoIteration)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
