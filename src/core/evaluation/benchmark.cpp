#include "sowing_robot/core/evaluation/benchmark.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/evaluation/bench_row.h"
#include "sowing_robot/core/evaluation/estimated_bench.h"
#include "sowing_robot/core/evaluation/run_metrics.h"

namespace sowing_robot {
namespace core {

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Draw k of run `index`, in [0, 1) with 53 bits.
double unit(std::uint64_t base_seed, std::int64_t index, int k) {
  const std::uint64_t run = splitmix64(splitmix64(base_seed) + static_cast<std::uint64_t>(index));
  return static_cast<double>(splitmix64(run + static_cast<std::uint64_t>(k)) >> 11) * 0x1.0p-53;
}

std::string checkUniform(const char* name, const Uniform& u) {
  if (!allFinite(u.lo, u.hi)) return std::string(name) + " bounds must be finite";
  if (u.lo > u.hi) return std::string(name) + ": lo " + formatNumber(u.lo) + " > hi " + formatNumber(u.hi);
  return "";
}

RunRow measure(const Scenario& sc, ReferenceSource& reference, const MonteCarloSpec& spec, const RunDraw& draw,
               const RunExtras& extras = {}) {
  RunRow row;
  row.draw = draw;
  RowMeter meter(row, sc, spec, extras);
  // Without a body or a last reference to follow, the row's per-period figures are a RunTally the loop
  // adds up itself (no callback per period); the same numbers either way.
  const RunResult r = meter.needsEveryPeriod()
                          ? runClosedLoop(sc, reference, true, [&](const LoopSample& s) { meter.add(s); })
                          : runClosedLoop(sc, reference, true, meter.tally());
  meter.finish(r);
  return row;
}

/// A parallelRows worker for seeded runs of `base` on its own clone of `reference`: run i -> its row.
auto seededRuns(const Scenario& base, const MonteCarloSpec& spec, const ReferenceSource& reference,
                const RunExtras& extras) {
  std::shared_ptr<ReferenceSource> ref = reference.clone();
  return [&base, &spec, ref, extras](std::int64_t i) {
    const RunDraw draw = drawRun(spec, base, i);
    return measure(applyDraw(base, spec, draw), *ref, spec, draw, extras);
  };
}

/// Throws std::invalid_argument naming the first of runs 0..runs-1 whose drawn scenario does not validate
/// (e.g. a mismatch outside the plant's range): checked before any run starts, so no partial result.
void refuseBadDraws(const Scenario& base, const MonteCarloSpec& spec, std::int64_t runs) {
  for (std::int64_t i = 0; i < runs; ++i) {
    const std::string e = applyDraw(base, spec, drawRun(spec, base, i)).validate();
    if (!e.empty()) throw std::invalid_argument("a drawn run does not validate: " + e);
  }
}

/// CPU time of the calling thread [s] (0 where the clock is missing: the load figures are then 0, and
/// nothing else depends on them).
double threadCpuSeconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Runs 0..runs-1 on `threads` threads: make() is called once per thread and returns that thread's
/// run(i) -> RunRow, with its own references and state. The threads take the next run as they free up; row
/// i lands at index i whatever thread ran it. loads (optional): each thread's runs and CPU time, thread t's
/// in (*loads)[t].
template <typename MakeWorker>
std::vector<RunRow> parallelRows(std::int64_t runs, int threads, const std::function<void(std::int64_t)>& progress,
                                 const MakeWorker& make, std::vector<WorkerLoad>* loads = nullptr) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::int64_t>(threads, runs));
  std::vector<WorkerLoad> load(static_cast<std::size_t>(threads));
  std::vector<RunRow> rows(static_cast<std::size_t>(runs));
  std::atomic<std::int64_t> next{0};
  std::int64_t done = 0;
  std::mutex progress_mutex;
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto worker = [&](WorkerLoad& mine) {
    const double cpu0 = threadCpuSeconds();
    try {
      auto run = make();
      for (std::int64_t i = next++; i < runs; i = next++) {
        rows[static_cast<std::size_t>(i)] = run(i);
        ++mine.runs;
        if (progress) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          progress(++done);
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = runs;  // the others stop after their current runs
    }
    mine.cpu_seconds = threadCpuSeconds() - cpu0;
  };
  if (threads == 1) {
    worker(load[0]);
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker, std::ref(load[static_cast<std::size_t>(t)]));
    for (auto& t : pool) t.join();
  }
  if (failure) std::rethrow_exception(failure);
  if (loads != nullptr) *loads = load;
  return rows;
}

/// Nearest-rank quantile of sorted values.
double quantile(const std::vector<double>& sorted, double q) {
  const auto n = static_cast<double>(sorted.size());
  const auto k = static_cast<std::size_t>(std::max(1.0, std::ceil(q * n)));
  return sorted[k - 1];
}

}  // namespace

std::string csvNumber(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string shortNumber(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

const char* successRuleName(SuccessRule r) { return r == SuccessRule::tracking ? "tracking" : "sown"; }

std::string describeSuccessRule(const MonteCarloSpec& s) {
  if (s.rule == SuccessRule::tracking)
    return "finished, no contact, |cross-track| < " + shortNumber(s.cross_track_threshold) + " m from " +
           shortNumber(s.settle_time) + " s on (rule tracking)";
  return "finished, no contact, every row sown >= " + shortNumber(100.0 * s.min_sown_share) +
         " % outside obstacle stretches, quality of feed >= " + shortNumber(s.min_quality_of_feed) +
         " %, seeds' lateral offset p95 <= " + shortNumber(s.max_seed_lateral_p95) +
         " m, seed-map error RMS <= " + shortNumber(s.max_map_error_rms) +
         " m, with traction the high-slip share <= " + shortNumber(s.max_high_slip_share) +
         " (rule sown: the seed record)";
}

std::string MonteCarloSpec::validate() const {
  std::string e = firstError(
      {checkUniform("mass_scale", mass_scale), checkUniform("inertia_scale", inertia_scale),
       checkUniform("amplitude", amplitude), checkUniform("phase", phase), checkUniform("start_dx", start_dx),
       checkUniform("start_dy", start_dy), checkUniform("start_dtheta", start_dtheta),
       checkNonNegative("noise_std", noise_std, "N·m"), checkNonNegative("settle_time", settle_time, "s"),
       checkPositive("cross_track_threshold", cross_track_threshold, "m"),
       checkPositive("max_seed_lateral_p95", max_seed_lateral_p95, "m"),
       checkPositive("max_map_error_rms", max_map_error_rms, "m")});
  if (e.empty() && !(min_sown_share >= 0.0 && min_sown_share <= 1.0))
    e = "min_sown_share must be in [0, 1] (a share of each row), not " + shortNumber(min_sown_share);
  if (e.empty() && !(min_quality_of_feed >= 0.0 && min_quality_of_feed <= 100.0))
    e = "min_quality_of_feed must be in [0, 100] %, not " + shortNumber(min_quality_of_feed);
  if (e.empty() && !(max_high_slip_share >= 0.0 && max_high_slip_share <= 1.0))
    e = "max_high_slip_share must be in [0, 1] (a share of the run), not " + shortNumber(max_high_slip_share);
  if (e.empty() && !(mass_scale.lo > 0.0 && inertia_scale.lo > 0.0)) e = "mass_scale and inertia_scale must be > 0";
  if (e.empty() && amplitude.lo < 0.0) e = "amplitude must be >= 0";
  return e;
}

RunDraw drawRun(const MonteCarloSpec& spec, const Scenario& base, std::int64_t index) {
  const std::uint64_t s = spec.base_seed;
  RunDraw d;
  d.index = index;
  d.mass_scale = spec.mass_scale.at(unit(s, index, 0));
  d.inertia_scale = spec.inertia_scale.at(unit(s, index, 1));
  d.amplitude = spec.amplitude.at(unit(s, index, 2));
  d.phase = spec.phase.at(unit(s, index, 3));
  d.noise_seed = splitmix64(splitmix64(splitmix64(s) + static_cast<std::uint64_t>(index)) + 4) >>
                 33;  // noise/seed is an int parameter
  d.start_x = base.start.x + spec.start_dx.at(unit(s, index, 5));
  d.start_y = base.start.y + spec.start_dy.at(unit(s, index, 6));
  d.start_theta = wrapAngle(base.start.theta + spec.start_dtheta.at(unit(s, index, 7)));
  d.sensor_seed = splitmix64(splitmix64(splitmix64(s) + static_cast<std::uint64_t>(index)) + 8) >> 33;
  return d;
}

Scenario applyDraw(const Scenario& base, const MonteCarloSpec& spec, const RunDraw& d) {
  Scenario sc = base;
  sc.disturbance.mass_scale = d.mass_scale;
  sc.disturbance.inertia_scale = d.inertia_scale;
  sc.disturbance.sinusoidal = d.amplitude > 0.0;
  sc.disturbance.amplitude = d.amplitude;
  sc.disturbance_phase = d.phase;
  sc.disturbance.noise_std = spec.noise_std;
  sc.disturbance.seed = d.noise_seed;
  sc.start = {d.start_x, d.start_y, d.start_theta};
  return sc;
}

std::vector<RunRow> runMonteCarlo(const Scenario& base, const ReferenceSource& reference, const MonteCarloSpec& spec,
                                  std::int64_t runs, int threads, const std::function<void(std::int64_t)>& progress) {
  if (runs < 1) throw std::invalid_argument("the number of runs (seeds) must be >= 1, not " + std::to_string(runs));
  const std::string e = firstError({spec.validate(), base.validate()});
  if (!e.empty()) throw std::invalid_argument(e);
  refuseBadDraws(base, spec, runs);
  return parallelRows(runs, threads, progress, [&]() { return seededRuns(base, spec, reference, RunExtras{}); });
}

std::string BenchScenario::validate() const {
  std::string e = firstError({spec.validate(), base.validate()});
  if (!e.empty()) return e;
  if (!(envelope_period > 0.0 && std::isfinite(envelope_period))) return "envelope_period must be > 0";
  e = estimatedBenchCheck(*this);
  if (!e.empty()) return e;
  switch (track) {
    case TrackKind::line:
      if (!allFinite(line_x0, line_v_r, line_y)) return "line: x0, v_r and y must be finite";
      return "";
    case TrackKind::sine: return sine.validate();
    case TrackKind::field:
      e = field.validate();
      if (!e.empty()) return e;
      for (const Obstacle& o : obstacles) {
        e = o.validate();
        if (!e.empty()) return "obstacle: " + e;
      }
      if (!(finish_tolerance > 0.0)) return "finish_tolerance must be > 0";
      return "";
  }
  return "unknown track";
}

void checkBenchmark(const BenchScenario& bench, std::int64_t runs) {
  if (runs < 1) throw std::invalid_argument("the number of runs (seeds) must be >= 1, not " + std::to_string(runs));
  const std::string e = bench.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  refuseBadDraws(bench.base, bench.spec, runs);
}

BenchScenario withController(BenchScenario bench, const Scenario& pair) {
  bench.base.outer = pair.outer;
  bench.base.inner = pair.inner;
  bench.base.kanayama = pair.kanayama;
  bench.base.sliding = pair.sliding;
  bench.base.pure_pursuit = pair.pure_pursuit;
  bench.base.pid = pair.pid;
  return bench;
}

std::function<RunRow(std::int64_t)> benchmarkWorker(const BenchScenario& scenario) {
  auto bench = std::make_shared<const BenchScenario>(scenario);
  if (bench->realism)  // sensors, traction or an estimate in the loop: estimated_bench.h
    return [bench](std::int64_t i) { return estimatedBenchRow(*bench, i); };
  RunExtras extras;
  extras.series_every = seriesEvery(*bench);
  if (bench->track != TrackKind::field) {
    std::unique_ptr<ReferenceSource> proto;
    if (bench->track == TrackKind::line)
      proto = std::make_unique<LineReference>(bench->line_v_r, bench->line_y, bench->line_x0);
    else
      proto = std::make_unique<SineReference>(bench->sine);
    std::shared_ptr<ReferenceSource> ref = proto->clone();
    std::shared_ptr<const SeedDrill> plan;  // a line is a row to sow; the sine track has none
    if (bench->track == TrackKind::line) plan = std::make_shared<const SeedDrill>(lineSeedPlan(*bench));
    return [bench, extras, ref, plan](std::int64_t i) {
      const RunDraw draw = drawRun(bench->spec, bench->base, i);
      RunExtras e = extras;
      e.seed_plan = plan.get();
      return measure(applyDraw(bench->base, bench->spec, draw), *ref, bench->spec, draw, e);
    };
  }
  // Field: the path starts at the drawn start (the approach), so each run builds its own reference, and its
  // duration grows by the approach's extra time, as run_scenario --field does.
  return [bench, extras](std::int64_t i) {
    const MonteCarloSpec& spec = bench->spec;
    const RunDraw draw = drawRun(spec, bench->base, i);
    return fieldRow(*bench, applyDraw(bench->base, spec, draw), extras,
                    [&spec, &draw](const Scenario& sc, ReferenceSource& reference, const RunExtras& e) {
                      return measure(sc, reference, spec, draw, e);
                    });
  };
}

std::vector<RunRow> runBenchmark(const BenchScenario& bench, std::int64_t runs, int threads,
                                 const std::function<void(std::int64_t)>& progress, std::vector<WorkerLoad>* loads) {
  checkBenchmark(bench, runs);
  return parallelRows(
      runs, threads, progress, [&]() { return benchmarkWorker(bench); }, loads);
}

namespace {

template <typename T>
double bits(T v) {
  static_assert(sizeof(T) <= sizeof(double), "fits a double");
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof(T));
  double d;
  std::memcpy(&d, &u, sizeof d);
  return d;
}

template <typename T>
T fromBits(double d) {
  std::uint64_t u;
  std::memcpy(&u, &d, sizeof u);
  T v;
  std::memcpy(&v, &u, sizeof(T));
  return v;
}

constexpr double kRowMagic = 31.0;  ///< first entry of a packed row (its format's version)

}  // namespace

// The draws, then every registry metric in its order (counts and flags are exact as doubles), then what no
// metric holds: the axes' peaks, the realism flag, the failure text and the cross-track series.
std::vector<double> packRow(const RunRow& r) {
  std::vector<double> p{kRowMagic};
  const RunDraw& d = r.draw;
  p.insert(p.end(), {bits(d.index), d.mass_scale, d.inertia_scale, d.amplitude, d.phase, bits(d.noise_seed), d.start_x,
                     d.start_y, d.start_theta, bits(d.sensor_seed)});
  for (const RunMetric& m : runMetrics()) p.push_back(m.get(r));
  for (const AxisMetrics& m : r.metrics) p.push_back(m.peak);
  p.push_back(r.realism ? 1.0 : 0.0);
  p.push_back(static_cast<double>(r.failure.size()));
  for (char c : r.failure) p.push_back(static_cast<double>(static_cast<unsigned char>(c)));
  p.push_back(static_cast<double>(r.cross_track_series.size()));
  p.insert(p.end(), r.cross_track_series.begin(), r.cross_track_series.end());
  return p;
}

RunRow unpackRow(const std::vector<double>& p) {
  std::size_t k = 0;
  auto next = [&]() {
    if (k >= p.size()) throw std::invalid_argument("packed row: too short");
    return p[k++];
  };
  auto count = [&]() {
    const double n = next();
    if (!(n >= 0.0) || n > static_cast<double>(p.size())) throw std::invalid_argument("packed row: bad length");
    return static_cast<std::size_t>(n);
  };
  if (next() != kRowMagic) throw std::invalid_argument("packed row: unknown format");
  RunRow r;
  RunDraw& d = r.draw;
  d.index = fromBits<std::int64_t>(next());
  d.mass_scale = next();
  d.inertia_scale = next();
  d.amplitude = next();
  d.phase = next();
  d.noise_seed = fromBits<std::uint64_t>(next());
  d.start_x = next();
  d.start_y = next();
  d.start_theta = next();
  d.sensor_seed = fromBits<std::uint64_t>(next());
  for (const RunMetric& m : runMetrics()) m.set(r, next());
  for (AxisMetrics& m : r.metrics) m.peak = next();
  r.realism = next() != 0.0;
  r.failure.resize(count());
  for (char& c : r.failure) c = static_cast<char>(static_cast<unsigned char>(next()));
  r.cross_track_series.resize(count());
  for (double& v : r.cross_track_series) v = next();
  if (k != p.size()) throw std::invalid_argument("packed row: trailing entries");
  return r;
}

Envelope crossTrackEnvelope(const std::vector<RunRow>& rows, double period) {
  Envelope env;
  env.period = period;
  std::size_t n = 0;
  for (const RunRow& r : rows) n = std::max(n, r.cross_track_series.size());
  std::vector<double> v;
  for (std::size_t k = 0; k < n; ++k) {
    v.clear();
    double max_abs = 0.0;
    for (const RunRow& r : rows) {
      if (k >= r.cross_track_series.size()) continue;
      double x = r.cross_track_series[k];
      if (std::isnan(x)) x = std::numeric_limits<double>::infinity();
      v.push_back(x);
      max_abs = std::max(max_abs, std::fabs(x));
    }
    std::sort(v.begin(), v.end());
    env.p05.push_back(quantile(v, 0.05));
    env.p25.push_back(quantile(v, 0.25));
    env.p50.push_back(quantile(v, 0.50));
    env.p75.push_back(quantile(v, 0.75));
    env.p95.push_back(quantile(v, 0.95));
    env.max_abs.push_back(max_abs);
  }
  return env;
}

std::string envelopeCsvHeader() { return "scenario,controller,t,p05,p25,p50,p75,p95,max_abs\n"; }

std::string envelopeCsvLines(const std::string& scenario, const std::string& controller, const Envelope& e) {
  // Six digits: a figure's data (micrometres of cross-track), not a run to repeat (runs.csv has full precision).
  auto six = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return std::string(buf);
  };
  std::string out;
  for (std::size_t k = 0; k < e.p50.size(); ++k)
    out += scenario + "," + controller + "," + six(static_cast<double>(k) * e.period) + "," + six(e.p05[k]) + "," +
           six(e.p25[k]) + "," + six(e.p50[k]) + "," + six(e.p75[k]) + "," + six(e.p95[k]) + "," + six(e.max_abs[k]) +
           "\n";
  return out;
}

Statistic statistic(std::vector<double> v) {
  Statistic s;
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) {
    s.mean = s.std = s.p95 = s.worst = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  const double inf = std::numeric_limits<double>::infinity();
  std::sort(v.begin(), v.end());
  s.worst = v.back();
  s.p95 = v[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1];  // nearest rank
  for (double x : v)
    if (!std::isfinite(x)) {
      s.mean = s.std = inf;
      return s;
    }
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  double sq = 0.0;
  for (double x : v) sq += (x - s.mean) * (x - s.mean);
  s.std = v.size() > 1 ? std::sqrt(sq / static_cast<double>(v.size() - 1)) : 0.0;
  return s;
}

const std::vector<std::string>& metricColumns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c;
    for (const RunMetric& m : runMetrics())
      if (m.report_table) c.push_back(m.name);
    return c;
  }();
  return columns;
}

std::vector<double> metricValues(const RunRow& r) {
  std::vector<double> v;
  v.reserve(metricColumns().size());
  for (const RunMetric& m : runMetrics())
    if (m.report_table) v.push_back(m.get(r));
  return v;
}

namespace {
/// A metric's runs.csv field: %.17g, an integer or 0/1; a realism column of a row without realism is "nan"
/// (a number) or empty.
std::string csvField(const RunMetric& m, const RunRow& r) {
  if (m.group == MetricGroup::realism && !r.realism) return m.format == MetricFormat::number ? "nan" : "";
  const double v = m.get(r);
  switch (m.format) {
    case MetricFormat::number: return csvNumber(v);
    case MetricFormat::count: return std::to_string(static_cast<long long>(v));
    case MetricFormat::flag: return v != 0.0 ? "1" : "0";
  }
  return "";
}
}  // namespace

// The columns: who ran and what was drawn, the metrics of every run, the failure, then (realism) the sensors'
// seed and the realism metrics (runsCsvIdentityColumns() lists the ones that are not metrics).
std::string runsCsvHeader(bool realism) {
  std::string h =
      "scenario,set,controller,seed,mass_scale,inertia_scale,amplitude,phase,noise_seed,start_x,start_y,start_theta";
  for (const RunMetric& m : runMetrics())
    if (m.group == MetricGroup::always) h += "," + m.name;
  h += ",failure";
  if (realism) {
    h += ",sensor_seed";
    for (const RunMetric& m : runMetrics())
      if (m.group == MetricGroup::realism) h += "," + m.name;
  }
  return h + "\n";
}

std::string runsCsvLines(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows,
                         bool realism, const std::string& set) {
  std::string out;
  for (const RunRow& r : rows) {
    const RunDraw& d = r.draw;
    out += scenario + "," + set + "," + controller + "," + std::to_string(d.index) + "," + csvNumber(d.mass_scale) +
           "," + csvNumber(d.inertia_scale) + "," + csvNumber(d.amplitude) + "," + csvNumber(d.phase) + "," +
           std::to_string(d.noise_seed) + "," + csvNumber(d.start_x) + "," + csvNumber(d.start_y) + "," +
           csvNumber(d.start_theta);
    for (const RunMetric& m : runMetrics())
      if (m.group == MetricGroup::always) out += "," + csvField(m, r);
    out += "," + r.failure;
    if (realism) {
      out += "," + (r.realism ? std::to_string(d.sensor_seed) : std::string());
      for (const RunMetric& m : runMetrics())
        if (m.group == MetricGroup::realism) out += "," + csvField(m, r);
    }
    out += "\n";
  }
  return out;
}

namespace {
const char* const kFailureReasons[] = {"diverged", "contact", "not finished", "cross-track", "no traction"};
/// The reasons always listed in a report section; "no traction" (the traction control's) only when a row has it.
constexpr std::size_t kListedReasons = 4;

/// Whether row r failed for `reason` (a failure text starts with its reason: "no traction at (x y): ...").
bool failedFor(const RunRow& r, const char* reason) { return r.failure.rfind(reason, 0) == 0; }

double successRate(const std::vector<RunRow>& rows) {
  std::int64_t ok = 0;
  for (const RunRow& r : rows) ok += r.success;
  return rows.empty() ? 0.0 : 100.0 * static_cast<double>(ok) / static_cast<double>(rows.size());
}

std::vector<double> column(const std::vector<RunRow>& rows, const std::function<double(const RunRow&)>& f) {
  std::vector<double> v;
  v.reserve(rows.size());
  for (const RunRow& r : rows) v.push_back(f(r));
  return v;
}
}  // namespace

std::string reportSection(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows) {
  std::int64_t ok = 0;
  for (const RunRow& r : rows) ok += r.success;
  std::string out = "## " + scenario + " / " + controller + "\n\n";
  out += "runs " + std::to_string(rows.size()) + ", success " + std::to_string(ok) + " (" +
         shortNumber(successRate(rows)) + " %); failures:";
  bool first = true;
  std::size_t listed = 0;
  for (const char* reason : kFailureReasons) {
    std::int64_t n = 0;
    for (const RunRow& r : rows) n += failedFor(r, reason);
    if (listed++ >= kListedReasons && n == 0) continue;
    out += std::string(first ? " " : ", ") + reason + " " + std::to_string(n);
    first = false;
  }
  out += "\n\n";
  const std::vector<double> clearance = column(rows, [](const RunRow& r) { return r.min_clearance; });
  if (std::any_of(clearance.begin(), clearance.end(), [](double c) { return !std::isnan(c); })) {
    std::int64_t touched = 0;
    double lowest = std::numeric_limits<double>::infinity();
    for (const RunRow& r : rows) {
      touched += r.contacts > 0;
      if (!std::isnan(r.min_clearance)) lowest = std::min(lowest, r.min_clearance);
    }
    out += "body against the obstacles: runs with a contact " + std::to_string(touched) + ", smallest body clearance " +
           shortNumber(lowest) + " m\n\n";
  }
  if (!rows.empty() && rows.front().realism) out += estimatedReportLine(rows);
  out += "| metric | mean | std | p95 | worst |\n|---|---:|---:|---:|---:|\n";
  for (const RunMetric& m : runMetrics()) {
    if (!m.report_table) continue;
    const Statistic s = statistic(column(rows, m.get));
    out += "| " + m.name + " | " + shortNumber(s.mean) + " | " + shortNumber(s.std) + " | " + shortNumber(s.p95) +
           " | " + shortNumber(s.worst) + " |\n";
  }
  return out + "\n";
}

namespace {
/// The metrics of the report's overview, in its column order.
std::vector<const RunMetric*> overviewMetrics() {
  std::vector<const RunMetric*> out;
  for (const RunMetric& m : runMetrics())
    if (m.overview_column > 0) out.push_back(&m);
  std::stable_sort(out.begin(), out.end(),
                   [](const RunMetric* a, const RunMetric* b) { return a->overview_column < b->overview_column; });
  return out;
}
}  // namespace

std::string summaryHeader() {
  std::string h = "| scenario | controller | runs | success % | failures |", rule = "|---|---|---:|---:|---|";
  for (const RunMetric* m : overviewMetrics()) {
    h += " " + m->label + (m->overview_p95 ? " mean / p95" : " mean") + " [" + m->unit + "] |";
    rule += "---:|";
  }
  return h + "\n" + rule + "\n";
}

std::string summaryLine(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows) {
  std::string failures;
  for (const char* reason : kFailureReasons) {
    std::int64_t n = 0;
    for (const RunRow& r : rows) n += failedFor(r, reason);
    if (n > 0) failures += (failures.empty() ? "" : ", ") + std::string(reason) + " " + std::to_string(n);
  }
  std::string line = "| " + scenario + " | " + controller + " | " + std::to_string(rows.size()) + " | " +
                     shortNumber(successRate(rows)) + " | " + (failures.empty() ? "-" : failures) + " |";
  for (const RunMetric* m : overviewMetrics()) {
    const Statistic s = statistic(column(rows, m->get));
    line += " " + shortNumber(s.mean) + (m->overview_p95 ? " / " + shortNumber(s.p95) : "") + " |";
  }
  return line + "\n";
}

}  // namespace core
}  // namespace sowing_robot
