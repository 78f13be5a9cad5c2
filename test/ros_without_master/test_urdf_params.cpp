// URDF -> RobotParams: the real urdf/sowing_robot.urdf must give exactly Table 5.1, and broken copies of
// it (made by editing the text) must give one line that names the broken item.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "sowing_robot/ros/common/urdf_params.h"

#ifndef SOWING_URDF_PATH
#error "compile with -DSOWING_URDF_PATH=\"/path/to/urdf/sowing_robot.urdf\""
#endif

using sowing_robot::robotParamsFromUrdf;
using sowing_robot::core::RobotParams;

namespace {

const double kTol = 1e-12;

std::string readUrdf() {
  std::ifstream f(SOWING_URDF_PATH);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Replaces the first `from` found after `anchor` (both must exist) by `to`.
std::string replaceAfter(std::string xml, const std::string& anchor, const std::string& from, const std::string& to) {
  const std::size_t a = xml.find(anchor);
  if (a == std::string::npos) throw std::runtime_error("anchor not found: " + anchor);
  const std::size_t p = xml.find(from, a);
  if (p == std::string::npos) throw std::runtime_error("text not found after anchor: " + from);
  return xml.replace(p, from.size(), to);
}

/// Error for a broken copy; asserts it is one non-empty line and that `out` was left untouched.
std::string errorFor(const std::string& xml) {
  RobotParams out;
  out.mc = -1.0;  // sentinel: must survive a failed read
  const std::string err = robotParamsFromUrdf(xml, out);
  EXPECT_FALSE(err.empty());
  EXPECT_EQ(err.find('\n'), std::string::npos) << err;
  EXPECT_EQ(out.mc, -1.0);
  return err;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

class UrdfParams : public ::testing::Test {
 protected:
  void SetUp() override {
    xml = readUrdf();
    ASSERT_FALSE(xml.empty()) << "cannot read " << SOWING_URDF_PATH;
  }
  std::string xml;
};

}  // namespace

TEST_F(UrdfParams, RealFileGivesTable51) {
  RobotParams p;
  p.mc = p.mw = p.d = p.L = p.R = p.Ic = p.Im = p.Iw = 0.0;
  const std::string err = robotParamsFromUrdf(xml, p);
  ASSERT_EQ(err, "");
  EXPECT_NEAR(p.mc, 17.0, kTol);
  EXPECT_NEAR(p.mw, 0.5, kTol);
  EXPECT_NEAR(p.d, 0.05, kTol);
  EXPECT_NEAR(p.L, 0.24, kTol);
  EXPECT_NEAR(p.R, 0.095, kTol);
  EXPECT_NEAR(p.Ic, 0.537, kTol);
  EXPECT_NEAR(p.Im, 0.0011, kTol);
  EXPECT_NEAR(p.Iw, 0.0023, kTol);
  // The defaults of RobotParams are Table 5.1 too.
  const RobotParams table;
  EXPECT_NEAR(p.m0(), table.m0(), kTol);
  EXPECT_NEAR(p.I0(), table.I0(), kTol);
  // m0 = 18 + 2 * 0.0023 / 0.095^2, I0 = 0.6393 + 2 * 0.24^2 * 0.0023 / 0.095^2
  EXPECT_NEAR(p.m0(), 18.0 + 0.0046 / 0.009025, 1e-9);
  EXPECT_NEAR(p.m0(), 18.51, 1e-3);
  EXPECT_NEAR(p.I0(), 0.6393 + 2.0 * 0.0576 * 0.0023 / 0.009025, 1e-9);
  EXPECT_NEAR(p.I0(), 0.6687, 1e-4);
}

TEST_F(UrdfParams, RigidlyRotatedChassisInertiaStillGivesIc) {
  // Yawing the chassis inertial frame by 90 deg about z leaves izz (and hence Ic) unchanged.
  const std::string edited = replaceAfter(xml, "<link name=\"chassis\">", "<origin xyz=\"0.05 0 0.03\" rpy=\"0 0 0\"/>",
                                          "<origin xyz=\"0.05 0 0.03\" rpy=\"0 0 1.5707963267948966\"/>");
  RobotParams p;
  ASSERT_EQ(robotParamsFromUrdf(edited, p), "");
  EXPECT_NEAR(p.Ic, 0.537, kTol);
  EXPECT_NEAR(p.d, 0.05, kTol);
}

TEST_F(UrdfParams, MissingRightWheelJoint) {
  const std::string edited =
      replaceAfter(xml, "<robot", "<joint name=\"right_wheel_joint\"", "<joint name=\"rw_joint\"");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "right_wheel_joint")) << err;
  EXPECT_TRUE(contains(err, "not found")) << err;
}

TEST_F(UrdfParams, ZeroWheelRadius) {
  const std::string edited =
      replaceAfter(xml, "<link name=\"right_wheel\">", "<collision>", "<collision><!-- edited -->");
  const std::string zero = replaceAfter(edited, "<!-- edited -->", "radius=\"0.095\"", "radius=\"0.0\"");
  const std::string err = errorFor(zero);
  EXPECT_TRUE(contains(err, "right_wheel")) << err;
  EXPECT_TRUE(contains(err, "radius")) << err;
}

TEST_F(UrdfParams, WheelRadiusNotAxleHeight) {
  const std::string edited =
      replaceAfter(xml, "<link name=\"left_wheel\">", "<collision>", "<collision><!-- edited -->");
  const std::string big = replaceAfter(edited, "<!-- edited -->", "radius=\"0.095\"", "radius=\"0.1\"");
  const std::string err = errorFor(big);
  EXPECT_TRUE(contains(err, "left_wheel")) << err;
  EXPECT_TRUE(contains(err, "wheel radius ≠ axle height")) << err;
}

TEST_F(UrdfParams, AsymmetricWheelMasses) {
  const std::string edited =
      replaceAfter(xml, "<link name=\"left_wheel\">", "<mass value=\"0.5\"/>", "<mass value=\"0.6\"/>");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "mass")) << err;
  EXPECT_TRUE(contains(err, "left_wheel")) << err;
  EXPECT_TRUE(contains(err, "right_wheel")) << err;
}

TEST_F(UrdfParams, AsymmetricTrack) {
  const std::string edited =
      replaceAfter(xml, "<joint name=\"left_wheel_joint\"", "xyz=\"0 0.24 0.095\"", "xyz=\"0 0.25 0.095\"");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "left_wheel_joint")) << err;
  EXPECT_TRUE(contains(err, "half track")) << err;
}

TEST_F(UrdfParams, AxleNotUnderBaseLink) {
  const std::string edited =
      replaceAfter(xml, "<joint name=\"right_wheel_joint\"", "xyz=\"0 -0.24 0.095\"", "xyz=\"0.01 -0.24 0.095\"");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "right_wheel_joint")) << err;
  EXPECT_TRUE(contains(err, "origin x")) << err;
}

TEST_F(UrdfParams, WheelAxisNotLateral) {
  const std::string edited =
      replaceAfter(xml, "<joint name=\"right_wheel_joint\"", "<axis xyz=\"0 1 0\"/>", "<axis xyz=\"1 0 0\"/>");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "right_wheel_joint")) << err;
  EXPECT_TRUE(contains(err, "axis")) << err;
}

TEST_F(UrdfParams, MissingChassisInertial) {
  // Rename the element: urdfdom ignores unknown elements.
  const std::string edited = replaceAfter(xml, "<link name=\"chassis\">", "<inertial>", "<unused_inertial>");
  const std::string closed = replaceAfter(edited, "<unused_inertial>", "</inertial>", "</unused_inertial>");
  const std::string err = errorFor(closed);
  EXPECT_TRUE(contains(err, "chassis")) << err;
  EXPECT_TRUE(contains(err, "inertial")) << err;
}

TEST_F(UrdfParams, MassOnLumpedLinkRejected) {
  const std::string edited =
      replaceAfter(xml, "<link name=\"seed_hopper\">", ">",
                   "><inertial><mass value=\"3.0\"/>"
                   "<inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>");
  const std::string err = errorFor(edited);
  EXPECT_TRUE(contains(err, "seed_hopper")) << err;
}

TEST_F(UrdfParams, MalformedXml) {
  const std::string err = errorFor(xml.substr(0, xml.size() / 2));
  EXPECT_TRUE(contains(err, "parse")) << err;
  errorFor("");
  errorFor("<robot name=\"x\"><link name=\"base_link\"></robot>");
}

TEST_F(UrdfParams, ToolLinkIsTheSeedDropPointBehindTheAxle) {
  double x = 1.0, y = 1.0;
  ASSERT_EQ(sowing_robot::linkPositionFromUrdf(xml, "tool_link", x, y), "");
  EXPECT_NEAR(x, -0.45, 1e-12);  // on the ground behind the furrow-opener disc
  EXPECT_NEAR(y, 0.0, 1e-12);
  EXPECT_NE(sowing_robot::linkPositionFromUrdf(xml, "no_such_link", x, y).find("no_such_link"), std::string::npos);
  EXPECT_NE(sowing_robot::linkPositionFromUrdf("<robot", "tool_link", x, y).find("could not be parsed"),
            std::string::npos);
}
