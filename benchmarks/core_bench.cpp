// core_bench: Google Benchmark figures of the ROS-free core. Figures only, never a pass/fail. Every run goes
// through the product's entry points (runClosedLoop, truth-fed and with a LoopConfig: the one loop of closed_loop.h).
//   core_bench [--benchmark_min_time=0.2] [--benchmark_filter=Thesis] ...
// BM_PlantRk4Step            one Plant::step (RK4, sinusoidal disturbance on)
// BM_TractionStep            one TractionPlant::step with the same torques (TractionParams defaults: 4 sub-steps)
// BM_ThesisRun25s            runClosedLoop of the 25 s thesis scenario at 1 kHz, every layer off (the no-slip
//                            plant fed its own state, no trace, keep_samples = false: the tuner's run);
//                            items/s = control steps/s
// BM_ThesisRun25sTally       the same as the benchmark command runs it: keep_samples = true and a RunTally
// BM_ThesisRun25sTimeDomain  keep_samples = true (streaming time-domain figures), no trace
// BM_ThesisRun25sEstimated   the same run through runClosedLoop, every layer off (no-slip plant, truth fed:
//                            the sensors run unused, the controllers behind their run-time interfaces)
// BM_MonteCarlo1000Runs/threads:N  runMonteCarlo of 1,000 seeded runs of the thesis line, kanayama+atsmc,
//                            every metric (the benchmark command's work without the files), N threads; wall time
// BM_ThesisRun25sTraction    runClosedLoop on the traction plant (TractionParams defaults), truth fed back
// BM_ThesisRun25sDriveTrain/layers:N  the traction run with the DC motors (1) and traction control too (2, the
//                            table's; 3, the field profile's values)
// BM_FieldProfileRun25s/feedback:F  the thesis run with config/profiles/field.yaml's layers read from the file
//                            (traction plant, motors, command limits, traction control, speed governor, hitch
//                            control) and its tuned gains; F 0: the profile's feedback (fused, slip-aware EKF),
//                            1: the truth fed back (the layers alone)
// BM_WetLineFieldProfileRow  one row of `benchmark --scenarios wet_line --profile field` (run 0): the seed
//                            drill's tool down with a 10 N draft on wet soil, so the tool rule and hitch act
// BM_ThesisRunPotentialField runClosedLoop with the potential-field reference (obstacles (20,3), (50,3), (80,3))
// BM_PsoIteration/threads:N  one PSO iteration: 20 particles evaluated on the thesis scenario (ITAE,
//                            default gain box), N evaluation threads; wall time (UseRealTime)
#include <benchmark/benchmark.h>

#include <vector>

#include "scenarios.h"
#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/estimated_bench.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/core/simulation/seed_recorder.h"

using namespace sowing_robot;
using namespace sowing_robot::core;

namespace {

volatile double g_sink = 0.0;  // keeps results alive (see BM_ThesisRun25s)

// One plant step per iteration: small alternating torques that keep the state bounded over any number of
// steps, the plant reset every 25,000 steps.
template <typename PlantT>
void stepLoop(benchmark::State& state, PlantT& plant) {
  State x0 = State::Zero();
  x0[X] = -1.0;
  x0[V] = 1.0;
  plant.reset(x0, 0.0);
  const double dt = 1e-3;
  std::int64_t k = 0;
  for (auto _ : state) {
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

void BM_PlantRk4Step(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  Plant plant(sc.robot, sc.disturbance);
  stepLoop(state, plant);
}
BENCHMARK(BM_PlantRk4Step);

// The traction plant's step beside BM_PlantRk4Step (the figure test_traction's CostBesidePlant printed):
// the same torques and resets, the thesis scenario's disturbance, TractionParams defaults.
void BM_TractionStep(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  TractionPlant plant(sc.robot, sc.disturbance, TractionParams{});
  stepLoop(state, plant);
}
BENCHMARK(BM_TractionStep);

// Runs `run` (one whole run, returning the figure kept as a counter) per iteration; items = control steps.
template <typename Run>
void wholeRuns(benchmark::State& state, const Scenario& sc, const char* counter, Run&& run) {
  // A volatile sink, not DoNotOptimize(double&): libbenchmark 1.7's "+m,r" constraint can corrupt a
  // double under GCC -O3 (fixed upstream in 1.8).
  volatile double figure = 0.0;
  for (auto _ : state) figure = run();
  // States are evaluated at k = 0..steps(); steps() plant steps per run.
  state.SetItemsProcessed(state.iterations() * sc.steps());
  state.counters[counter] = benchmark::Counter(figure, benchmark::Counter::kDefaults);
}

// A benchmark that reads config files: one that does not read skips the benchmark with its message.
template <typename Body>
void guarded(benchmark::State& state, Body&& body) {
  try {
    body();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void BM_ThesisRun25s(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  wholeRuns(state, sc, "itae_y", [&] { return runClosedLoop(sc, ref, false).metrics[AXIS_Y].itae; });
}
BENCHMARK(BM_ThesisRun25s)->Unit(benchmark::kMillisecond);

void BM_ThesisRun25sTally(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  wholeRuns(state, sc, "worst_cross_track", [&] {
    RunTally tally;  // as the benchmark command's RowMeter sets it for the thesis line (settle 15 s, no series)
    tally.dt = secondsFromNanos(sc.control_period_ns);
    tally.settle_time = 15.0;
    runClosedLoop(sc, ref, true, tally);
    return tally.worst_cross_track;
  });
}
BENCHMARK(BM_ThesisRun25sTally)->Unit(benchmark::kMillisecond);

void BM_ThesisRun25sTimeDomain(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  wholeRuns(state, sc, "settling_y", [&] { return runClosedLoop(sc, ref, true).metrics[AXIS_Y].settling_time; });
}
BENCHMARK(BM_ThesisRun25sTimeDomain)->Unit(benchmark::kMillisecond);

void BM_ThesisRun25sEstimated(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  const LoopConfig cfg;  // no-slip plant, truth fed back, every layer off
  wholeRuns(state, sc, "itae_y", [&] { return runClosedLoop(sc, cfg, ref, false).run.metrics[AXIS_Y].itae; });
}
BENCHMARK(BM_ThesisRun25sEstimated)->Unit(benchmark::kMillisecond);

// The Monte-Carlo runner's own scenario (Scenario defaults: the thesis line, start (-1, 0, 0)) and spec
// (MonteCarloSpec defaults: mismatch, disturbance, noise and start drawn per run), as
// `benchmark --scenarios thesis_line --controllers kanayama+atsmc --seeds 1000` runs it.
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

// The thesis run on the traction plant (default soil: loose moist soil, mu 0.6, 4 sub-steps, rolling
// resistance 0.05; the thesis start's 100 N·m spins the wheels), the truth fed back: target at most 2x
// BM_ThesisRun25s.
void BM_ThesisRun25sTraction(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  LoopConfig cfg;
  cfg.traction = TractionParams();
  wholeRuns(state, sc, "itae_y", [&] { return runClosedLoop(sc, cfg, ref, false).run.metrics[AXIS_Y].itae; });
}
BENCHMARK(BM_ThesisRun25sTraction)->Unit(benchmark::kMillisecond);

// The drive train's cost (target: motor model and traction control at most 20 % of a traction-plant run):
// BM_ThesisRun25sTraction with the DC motors (arg 1), and with the traction control too (arg 2: the table's
// defaults; arg 3: the field profile's traction_control block, read from the file); arg 0 is
// BM_ThesisRun25sTraction itself, so the ratios come from one program run.
void BM_ThesisRun25sDriveTrain(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  LineReference ref = bench::thesisLine();
  LoopConfig cfg;
  cfg.traction = TractionParams();
  cfg.motor.enabled = state.range(0) >= 1;
  cfg.traction_control.enabled = state.range(0) >= 2;
  guarded(state, [&] {
    if (state.range(0) >= 3) cfg.traction_control = bench::fieldProfileConfig().traction_control;
    wholeRuns(state, sc, "itae_y", [&] { return runClosedLoop(sc, cfg, ref, false).run.metrics[AXIS_Y].itae; });
  });
}
BENCHMARK(BM_ThesisRun25sDriveTrain)->ArgName("layers")->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

void BM_FieldProfileRun25s(benchmark::State& state) {
  guarded(state, [&] {
    const Scenario sc = bench::fieldProfileScenario();
    LineReference ref = bench::thesisLine();
    LoopConfig cfg = bench::fieldProfileConfig();
    if (state.range(0) == 1) cfg.feedback = Feedback::ground_truth;
    double periods = 0.0;  // the periods run (the traction control's no-traction verdict could end a run early)
    wholeRuns(state, sc, "itae_y", [&] {
      const LoopResult r = runClosedLoop(sc, cfg, ref, false);
      periods = static_cast<double>(r.run.periods);
      return r.run.metrics[AXIS_Y].itae;
    });
    state.counters["periods"] = periods;
  });
}
BENCHMARK(BM_FieldProfileRun25s)->ArgName("feedback")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The seed record's cost (its target: at most 15 % more per run): the field profile's run on the line without a
// trace (record 0) against the same run with the benchmark's SeedRecorder in the trace (record 1).
void BM_FieldProfileSeedRecord(benchmark::State& state) {
  guarded(state, [&] {
    Scenario sc = bench::fieldProfileScenario();
    sc.start = {0.0, 3.0, 0.0};  // on the row from the start, so that the drill sows the whole run
    LineReference ref = bench::thesisLine();
    const LoopConfig cfg = bench::fieldProfileConfig();
    const SeedDrill row(cfg.seeding, {RowSegment{Eigen::Vector2d(0.0, 3.0), Eigen::Vector2d(sc.duration, 3.0)}}, {},
                        0.0);
    double seeds = 0.0;
    wholeRuns(state, sc, "itae_y", [&] {
      if (state.range(0) == 0) return runClosedLoop(sc, cfg, ref, false).run.metrics[AXIS_Y].itae;
      SeedRecorder record(row, cfg.tool);
      const LoopResult r = runClosedLoop(sc, cfg, ref, false, [&record](const EstimatedSample& s) { record.add(s); });
      seeds = static_cast<double>(record.seeds().size());
      return r.run.metrics[AXIS_Y].itae;
    });
    state.counters["seeds"] = seeds;
  });
}
BENCHMARK(BM_FieldProfileSeedRecord)->ArgName("record")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_WetLineFieldProfileRow(benchmark::State& state) {
  guarded(state, [&] {
    BenchScenario wet = scenario_file::loadScenario("wet_line", bench::sourcePath("config/scenarios"),
                                                    bench::sourcePath("config/profiles/field.yaml"));
    wet = withController(wet, bench::fieldProfileScenario());
    wholeRuns(state, wet.base, "unsown_distance", [&] { return estimatedBenchRow(wet, 0).unsown_distance; });
  });
}
BENCHMARK(BM_WetLineFieldProfileRow)->Unit(benchmark::kMillisecond);

void BM_ThesisRunPotentialField(benchmark::State& state) {
  const Scenario sc = bench::thesisScenario();
  PotentialField ref = bench::thesisPotentialField();
  wholeRuns(state, sc, "itae_y", [&] { return runClosedLoop(sc, ref, false).metrics[AXIS_Y].itae; });
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
