// Soil patches of a field: polygons with their own grip and rolling resistance. The
// traction plant (traction.h) looks up each wheel's and the caster's contact point here every step; a
// point in no patch is on the field's default soil (the traction/ parameters).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sowing_robot {
namespace core {

/// One patch: a simple polygon (vertices in order, either sense, not closed: the last joins the first)
/// in the odom frame [m], and its soil.
struct SoilPatch {
  std::vector<Eigen::Vector2d> polygon;
  double mu_peak = 0.2;              ///< peak friction coefficient (as traction/mu_peak)
  double mu_slide = 0.15;            ///< sliding friction coefficient, <= mu_peak (as traction/mu_slide)
  double rolling_resistance = 0.05;  ///< rolling-resistance coefficient (as traction/rolling_resistance)
  /// The seed drill's draft here against the field's soil at the same depth and speed (the texture factor F_i of
  /// ASABE D497's draft law, traction.h's toolDraft). 1: a patch pulls as the field. Why 1 is the default for a
  /// wet patch: D497 gives seeding implements the same constant in every texture, and wetting a soil pulls both
  /// ways (a weaker soil cuts more easily, a sticky one adheres to the opener), so without a measurement of the
  /// patch the field's draft is the best guess; a sticky clay patch takes more (e.g. 1.2), a loose sand less.
  double draft_factor = 1.0;

  /// "" or one line naming `key` (e.g. "field/patches[1]") and what is wrong: fewer than 3 vertices, a
  /// non-finite vertex, a polygon that is not simple (crosses itself, zero area: common/polygon.h), a negative or
  /// non-finite coefficient (draft_factor included), mu_slide > mu_peak, rolling_resistance > 1.
  std::string validate(const std::string& key) const;
};

/// One line for the field check when some patches overlap, naming the pairs (`key` "field/patches":
/// "soil patches overlap (field/patches[0] and [2]): where they do, the one listed last holds"), or "". Overlap is
/// allowed, as layers: a wet strip drawn over a larger patch lists it after that patch.
std::string patchOverlapNote(const std::vector<SoilPatch>& patches, const std::string& key = "field/patches");

/// The patches of a field. Where patches overlap, the one listed last wins (patchOverlapNote says where).
class SoilMap {
 public:
  SoilMap() = default;
  /// Throws std::invalid_argument (the first SoilPatch::validate() text, keys "field/patches[i]").
  explicit SoilMap(std::vector<SoilPatch> patches);

  /// Index of the patch holding p (even-odd rule; a point on an edge may fall either side), or -1.
  int patchAt(const Eigen::Vector2d& p) const;
  const std::vector<SoilPatch>& patches() const { return patches_; }
  bool empty() const { return patches_.empty(); }

 private:
  struct Box {
    Eigen::Vector2d lo, hi;
  };
  std::vector<SoilPatch> patches_;
  std::vector<Box> boxes_;  // bounding boxes: most lookups end there
};

/// True when p lies inside `polygon` (even-odd rule).
bool insidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

}  // namespace core
}  // namespace sowing_robot
