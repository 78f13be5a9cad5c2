#include "sowing_robot/ros/coverage_route.h"

#include <optional>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/coverage_follower.h"
#include "sowing_robot/field_file/field_file.h"
#include "sowing_robot/ros/common/component_params.h"

namespace sowing_robot {

const core::ParamTable<core::FieldParams>& coverageFieldSpeedsTable() {
  static const core::ParamTable<core::FieldParams> table = [] {
    std::vector<core::ParamEntry<core::FieldParams>> speeds;
    for (const auto& e : core::fieldTable().entries())
      if (e.info.key == "field/row_speed" || e.info.key == "field/turn_speed" || e.info.key == "field/max_accel")
        speeds.push_back(e);
    return core::ParamTable<core::FieldParams>(speeds);
  }();
  return table;
}

std::string loadCoverageRoute(ParamReader& p, const ros::NodeHandle& nh,
                              const core::ReferenceGeneratorSettings& settings, CoverageRoute& out) {
  const ros::NodeHandle& pnh = p.handle();
  loadTable(p, coverageFieldSpeedsTable(), out.field);
  loadTable(p, core::coverageTable(), out.coverage);
  loadTable(p, core::fleetShareTable(), out.fleet);
  std::string error;
  // Each swath is driven on until the tool point reaches its end (the URDF's tool offset), unless set.
  if (!pnh.hasParam("coverage/run_out")) error = loadToolRunOut(p, nh, out.coverage.run_out);
  if (!error.empty() || !p.error().empty()) return error;
  error = core::firstError({out.coverage.validate(), out.fleet.validate()});
  if (!error.empty()) return error;
  if (settings.field_file.empty())
    return pnh.resolveName("field_file") + " is not set: type coverage plans the field of a field file " +
           "(sim.launch field_file:=PATH)";
  std::optional<field_file::GeoOrigin> origin;
  if (!settings.field_origin.empty()) {
    field_file::GeoOrigin o;
    const std::string e = seed_map::parseOrigin(settings.field_origin, o);
    if (!e.empty()) return pnh.resolveName("field_origin") + " = '" + settings.field_origin + "': " + e;
    origin = o;
  }
  core::FieldBoundary boundary;
  try {
    boundary = field_file::loadFieldBoundary(settings.field_file, origin);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  try {
    out.plan = core::planCoverage(boundary, out.coverage);
    out.follower = core::coverageFollowerParams(out.field, out.coverage);
    if (out.fleet.robots == 0) {
      out.start = core::routeStart(out.plan);
      out.path = out.plan.route;
      out.wait = 0.0;
    } else {
      out.share = core::planFleetShare(out.plan, out.fleet, out.coverage, out.follower);
      out.start = out.share.own().start;
      out.path = out.share.own().path;
      out.wait = out.share.own().wait;
    }
  } catch (const std::invalid_argument& e) {
    return settings.field_file + ": " + e.what();
  }
  return "";
}

}  // namespace sowing_robot
