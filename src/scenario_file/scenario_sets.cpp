#include "sowing_robot/scenario_file/scenario_sets.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace sowing_robot {
namespace scenario_file {

namespace {

/// 17 significant digits: two numbers that print the same are the same double.
std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

std::string range(const core::Uniform& u) { return "[" + num(u.lo) + " " + num(u.hi) + "]"; }

bool isDirectory(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// Entries of `dir` (names only, sorted), without "." and "..".
std::vector<std::string> entriesOf(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool endsWithYaml(const std::string& n) { return n.size() > 5 && n.compare(n.size() - 5, 5, ".yaml") == 0; }

/// A field config (reference_generator:, plant_sim:) rather than a scenario file.
bool isFieldConfig(const std::string& path) {
  try {
    const YAML::Node root = YAML::LoadFile(path);
    return root.IsMap() && root["reference_generator"];
  } catch (const YAML::Exception&) {
    return false;  // loadScenarioFile reports the file's error
  }
}

const char* trackName(core::TrackKind t) {
  return t == core::TrackKind::line ? "line" : t == core::TrackKind::field ? "field" : "sine";
}

const CatalogEntry* findByName(const std::vector<CatalogEntry>& catalog, const std::string& name) {
  for (const CatalogEntry& c : catalog)
    if (c.scenario.name == name) return &c;
  return nullptr;
}

}  // namespace

const std::vector<std::string>& scenarioSets() {
  static const std::vector<std::string> sets{"training", "validation", "test"};
  return sets;
}

std::string checkScenarioSet(const std::string& set) {
  const auto& sets = scenarioSets();
  if (std::find(sets.begin(), sets.end(), set) != sets.end()) return "";
  return "set '" + set + "' is none of training, validation, test";
}

std::string ScenarioFingerprint::digest() const {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a 64: a stable digest, not a secure one
  for (const std::string* part : {&layout, &soil, &draws})
    for (const char c : *part + '\n') {
      h ^= static_cast<unsigned char>(c);
      h *= 1099511628211ULL;
    }
  char b[20];
  std::snprintf(b, sizeof b, "%016" PRIx64, h);
  return b;
}

ScenarioFingerprint fingerprintOf(const core::BenchScenario& b) {
  ScenarioFingerprint f;
  std::string& l = f.layout;
  l = std::string("track ") + trackName(b.track);
  switch (b.track) {
    case core::TrackKind::line:
      l += "; line x0 " + num(b.line_x0) + " v_r " + num(b.line_v_r) + " y " + num(b.line_y);
      break;
    case core::TrackKind::sine:
      l += "; sine x0 " + num(b.sine.x0) + " y0 " + num(b.sine.y0) + " speed_x " + num(b.sine.speed_x) + " amplitude " +
           num(b.sine.amplitude) + " wavelength " + num(b.sine.wavelength);
      break;
    case core::TrackKind::field: {
      const core::FieldParams& p = b.field;
      l += "; rows " + std::to_string(p.rows) + " length " + num(p.row_length) + " spacing " + num(p.row_spacing) +
           " start " + num(p.start_x) + " " + num(p.start_y) + " heading " + num(p.heading) +
           (p.rows_to_left ? " left" : " right") + " row_speed " + num(p.row_speed);
      // The obstacles as a set: their order in the file is no difference of the field.
      std::vector<std::string> obstacles;
      for (const core::Obstacle& o : b.obstacles)
        obstacles.push_back("(" + num(o.x) + " " + num(o.y) + " " + num(o.radius) + ")");
      std::sort(obstacles.begin(), obstacles.end());
      l += "; obstacles";
      for (const auto& o : obstacles) l += " " + o;
      break;
    }
  }
  l += "; start " + num(b.base.start.x) + " " + num(b.base.start.y) + " " + num(b.base.start.theta);

  // The soil: what the wheels stand on. The tool's draft is a load, not the ground, and left out.
  if (b.realism && b.realism->traction) {
    const core::TractionParams& t = *b.realism->traction;
    f.soil = "ground mu_peak " + num(t.mu_peak) + " mu_slide " + num(t.mu_slide) + " slip_peak " + num(t.slip_peak) +
             " slip_stiffness " + num(t.slip_stiffness) + " rolling " + num(t.rolling_resistance);
    std::vector<std::string> patches;
    for (const core::SoilPatch& p : b.realism->patches) {
      std::string s = "(";
      for (const auto& v : p.polygon) s += "[" + num(v.x()) + " " + num(v.y()) + "]";
      patches.push_back(s + " mu_peak " + num(p.mu_peak) + " mu_slide " + num(p.mu_slide) + " rolling " +
                        num(p.rolling_resistance) + ")");
    }
    std::sort(patches.begin(), patches.end());
    f.soil += "; patches";
    for (const auto& p : patches) f.soil += " " + p;
  } else {
    f.soil = "no-slip plant";
  }

  const core::MonteCarloSpec& s = b.spec;
  f.draws = "base_seed " + std::to_string(s.base_seed) + " mass " + range(s.mass_scale) + " inertia " +
            range(s.inertia_scale) + " amplitude " + range(s.amplitude) + " phase " + range(s.phase) + " noise " +
            num(s.noise_std) + " start " + range(s.start_dx) + " " + range(s.start_dy) + " " + range(s.start_dtheta);
  return f;
}

Overlap overlapOf(const ScenarioFingerprint& a, const ScenarioFingerprint& b) {
  const bool world = a.layout == b.layout && a.soil == b.soil;
  const bool draws = a.draws == b.draws;
  if (world && draws) return Overlap::same_content;
  if (world) return Overlap::same_world;
  if (draws) return Overlap::same_draws;
  return Overlap::none;
}

std::string describeOverlap(Overlap o, const ScenarioFingerprint& a) {
  // The base seed is the draws' first word: "base_seed S ...".
  const std::string seed = a.draws.substr(0, a.draws.find(" mass"));
  switch (o) {
    case Overlap::none: return "";
    case Overlap::same_draws: return "same draws (" + seed + " and the same ranges)";
    case Overlap::same_world: return "same layout and soil (other draws)";
    case Overlap::same_content: return "same layout, soil and draws (" + seed + ")";
  }
  return "";
}

std::vector<CatalogEntry> scenarioCatalog(const std::string& dir) {
  std::vector<std::string> files;
  for (const std::string& n : entriesOf(dir)) {
    const std::string p = dir + "/" + n;
    if (isDirectory(p)) {
      for (const std::string& m : entriesOf(p))
        if (endsWithYaml(m) && !isDirectory(p + "/" + m)) files.push_back(p + "/" + m);
    } else if (endsWithYaml(n)) {
      files.push_back(p);
    }
  }
  std::vector<CatalogEntry> out;
  for (const std::string& f : files) {
    if (isFieldConfig(f)) continue;
    CatalogEntry e;
    e.path = f;
    e.scenario = loadScenarioFile(f);
    e.fingerprint = fingerprintOf(e.scenario);
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<std::string> testOverlaps(const core::BenchScenario& b, const std::vector<CatalogEntry>& catalog) {
  std::vector<std::string> out;
  if (b.set != "test") return out;
  const ScenarioFingerprint mine = fingerprintOf(b);
  for (const CatalogEntry& c : catalog) {
    if (c.scenario.set == "test") continue;  // compared with what was seen, not with the test set itself
    const Overlap o = overlapOf(mine, c.fingerprint);
    if (o != Overlap::none)
      out.push_back(c.scenario.name + " (" + c.scenario.set + "): " + describeOverlap(o, c.fingerprint));
  }
  return out;
}

std::string heldOutVerdict(const std::vector<TrainingRecord>& training, const core::BenchScenario& b, long long runs,
                           const std::vector<CatalogEntry>& catalog, const std::string& catalog_dir) {
  const ScenarioFingerprint mine = fingerprintOf(b);
  std::string worst;  // the strongest finding over the records
  int worst_rank = 0;
  for (const TrainingRecord& t : training) {
    const CatalogEntry* c = findByName(catalog, t.scenario);
    if (!c) return "CANNOT JUDGE: training scenario " + t.scenario + " is not in " + catalog_dir;
    core::BenchScenario trained = c->scenario;
    trained.spec.base_seed = t.base_seed;  // the tuning's draws, not the file's
    const ScenarioFingerprint theirs = fingerprintOf(trained);
    const Overlap o = overlapOf(mine, theirs);
    std::string text;
    int rank = 0;
    if (o == Overlap::same_content) {
      rank = 3;
      text = "TRAINED ON: same content as training scenario " + t.scenario + "; runs 0-" +
             std::to_string(std::min(t.runs, runs) - 1) + " are training runs";
    } else if (o == Overlap::same_world) {
      rank = 2;
      text = "SEEN IN TRAINING: same layout and soil as " + t.scenario + " (other draws)";
    } else if (o == Overlap::same_draws) {
      rank = 1;
      text = "SEEN IN TRAINING: same draws as " + t.scenario + " (" + describeOverlap(o, theirs) + "), another world";
    }
    if (rank > worst_rank) {
      worst_rank = rank;
      worst = text;
    }
  }
  return worst_rank > 0 ? worst : "held out (content differs from every training scenario)";
}

}  // namespace scenario_file
}  // namespace sowing_robot
