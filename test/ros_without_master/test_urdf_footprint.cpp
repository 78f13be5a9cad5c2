// URDF -> footprint: the real urdf/sowing_robot.urdf's collision geometry, projected to base_link.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "sowing_robot/ros/common/urdf_params.h"

#ifndef SOWING_URDF_PATH
#error "compile with -DSOWING_URDF_PATH=\"/path/to/urdf/sowing_robot.urdf\""
#endif

using sowing_robot::footprintFromUrdf;
using sowing_robot::core::Footprint;

namespace {
std::string readUrdf() {
  std::ifstream f(SOWING_URDF_PATH);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
}  // namespace

TEST(UrdfFootprint, RealUrdfGivesTheChassisAndWheelOutline) {
  Footprint f;
  ASSERT_EQ(footprintFromUrdf(readUrdf(), f), "");
  EXPECT_EQ(f.validate(), "");
  double x_min = 1e9, x_max = -1e9, y_max = -1e9, y_min = 1e9;
  for (const auto& v : f.vertices()) {
    x_min = std::min(x_min, v.x());
    x_max = std::max(x_max, v.x());
    y_min = std::min(y_min, v.y());
    y_max = std::max(y_max, v.y());
  }
  // Chassis collision box 0.62 x 0.38 centred 0.05 m ahead of the axle: x in [-0.26, 0.36] (the
  // front bumper at 0.38 is a visual only); wheel collision cylinders r 0.095, 0.05 wide at |y| 0.24:
  // outer faces at |y| = 0.265, x in [-0.095, 0.095].
  EXPECT_NEAR(x_min, -0.26, 1e-12);
  EXPECT_NEAR(x_max, 0.36, 1e-12);
  EXPECT_NEAR(y_max, 0.265, 1e-12);
  EXPECT_NEAR(y_min, -0.265, 1e-12);
  EXPECT_NEAR(f.circumscribedRadius(), std::hypot(0.36, 0.19), 1e-12);  // the front corners
  EXPECT_NEAR(f.inscribedRadius(), 0.26, 1e-12);                        // the rear edge
  // The wheel's outer face spans x = +-0.095 (sampled circle: exact at the extremes).
  EXPECT_NEAR(f.signedDistance({0.095, 0.265}), 0.0, 1e-12);
  EXPECT_NEAR(f.signedDistance({0.0, 0.3}), 0.035, 1e-12);
}

TEST(UrdfFootprint, MeshGeometryIsNamed) {
  std::string xml = readUrdf();
  const std::string from = "<geometry><sphere radius=\"0.035\"/></geometry>\n    </collision>";
  const std::size_t p = xml.find(from);
  ASSERT_NE(p, std::string::npos);
  xml.replace(p, from.size(), "<geometry><mesh filename=\"package://x/ball.stl\"/></geometry>\n    </collision>");
  Footprint f;
  const std::string err = footprintFromUrdf(xml, f);
  EXPECT_NE(err.find("'caster'"), std::string::npos) << err;
  EXPECT_TRUE(f.empty());
  EXPECT_NE(footprintFromUrdf("<robot", f), "");
}
