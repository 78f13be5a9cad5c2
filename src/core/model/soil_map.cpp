#include "sowing_robot/core/model/soil_map.h"

#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/polygon.h"
#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::string SoilPatch::validate(const std::string& key) const {
  if (polygon.size() < 3)
    return key + "/polygon has " + std::to_string(polygon.size()) + " vertices; a patch needs at least 3";
  for (std::size_t i = 0; i < polygon.size(); ++i)
    if (!polygon[i].allFinite()) return key + "/polygon[" + std::to_string(i) + "] must be finite";
  // A bow-tie or a patch drawn as a line: the even-odd lookup would give it a shape nobody meant.
  const std::string shape = ringProblem(polygon);
  if (!shape.empty()) return key + "/polygon " + shape + "; a patch must be a simple polygon";
  const struct {
    const char* name;
    double value;
  } coefficients[] = {{"mu_peak", mu_peak},
                      {"mu_slide", mu_slide},
                      {"rolling_resistance", rolling_resistance},
                      {"draft_factor", draft_factor}};
  for (const auto& c : coefficients)
    if (!std::isfinite(c.value) || c.value < 0.0)
      return key + "/" + c.name + " = " + formatNumber(c.value) + " must be finite and >= 0";
  if (mu_slide > mu_peak)
    return key + "/mu_slide = " + formatNumber(mu_slide) + " must be <= " + key + "/mu_peak = " + formatNumber(mu_peak);
  if (rolling_resistance > 1.0)
    return key + "/rolling_resistance = " + formatNumber(rolling_resistance) + " must be <= 1";
  return "";
}

bool insidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d &a = polygon[i], &b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
      inside = !inside;
  }
  return inside;
}

SoilMap::SoilMap(std::vector<SoilPatch> patches) : patches_(std::move(patches)) {
  for (std::size_t i = 0; i < patches_.size(); ++i) {
    const std::string e = patches_[i].validate("field/patches[" + std::to_string(i) + "]");
    if (!e.empty()) throw std::invalid_argument(e);
    Box b{patches_[i].polygon[0], patches_[i].polygon[0]};
    for (const Eigen::Vector2d& v : patches_[i].polygon) {
      b.lo = b.lo.cwiseMin(v);
      b.hi = b.hi.cwiseMax(v);
    }
    boxes_.push_back(b);
  }
}

std::string patchOverlapNote(const std::vector<SoilPatch>& patches, const std::string& key) {
  std::string pairs;
  for (std::size_t i = 0; i < patches.size(); ++i)
    for (std::size_t j = i + 1; j < patches.size(); ++j)
      if (ringsOverlap(patches[i].polygon, patches[j].polygon))
        pairs += (pairs.empty() ? "" : ", ") + key + "[" + std::to_string(i) + "] and [" + std::to_string(j) + "]";
  if (pairs.empty()) return "";
  return "soil patches overlap (" + pairs + "): where they do, the one listed last holds";
}

int SoilMap::patchAt(const Eigen::Vector2d& p) const {
  for (std::size_t k = patches_.size(); k-- > 0;) {
    const Box& b = boxes_[k];
    if (p.x() < b.lo.x() || p.x() > b.hi.x() || p.y() < b.lo.y() || p.y() > b.hi.y()) continue;
    if (insidePolygon(patches_[k].polygon, p)) return static_cast<int>(k);
  }
  return -1;
}

}  // namespace core
}  // namespace sowing_robot
