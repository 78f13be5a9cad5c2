// The package's sine and cosine (core/numerics/trig.h): within 1 ulp of the true value (long double's sinl/cosl,
// 11 more bits, as the reference), odd and even to the bit, the one-function forms equal to sinCos, the
// edges (zero's sign, tiny, huge, non-finite), and no sin or cos of the library left in the sources.
#include <gtest/gtest.h>

#include <dirent.h>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "sowing_robot/core/numerics/trig.h"

using namespace sowing_robot::core;

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// |approx - exact| in units of the last place of the double nearest to exact.
double ulpError(double approx, long double exact) {
  const double nearest = static_cast<double>(exact);
  const double ulp = std::nextafter(std::fabs(nearest), std::numeric_limits<double>::infinity()) - std::fabs(nearest);
  return static_cast<double>(std::fabs(static_cast<long double>(approx) - exact) / ulp);
}

/// The arguments the package meets and the hard ones: headings and errors within a turn, disturbance
/// phases w t over long runs, the reduction's far range, and doubles next to multiples of pi/2, where the
/// reduction cancels most.
std::vector<double> arguments() {
  std::vector<double> xs;
  std::mt19937_64 rng(7);
  for (const double range : {M_PI / 4, M_PI, 10.0, 1e3, 8e5}) {
    std::uniform_real_distribution<double> u(-range, range);
    for (int i = 0; i < 200000; ++i) xs.push_back(u(rng));
  }
  const long double half_pi = 1.570796326794896619231321691639751442L;
  for (int k = -2000; k <= 2000; ++k) {
    double x = static_cast<double>(k * half_pi);
    for (int step = 0; step < 4; ++step) {
      xs.push_back(x);
      x = std::nextafter(x, std::numeric_limits<double>::infinity());
    }
  }
  for (double x = 1e-300; x < 1.0; x *= 1.37) xs.push_back(x);
  return xs;
}

}  // namespace

TEST(Trig, WithinOneUlpOfTheTrueValue) {
  double worst_sin = 0.0, worst_cos = 0.0;
  double at_sin = 0.0, at_cos = 0.0;
  for (const double x : arguments()) {
    double s, c;
    sinCos(x, s, c);
    const double es = ulpError(s, sinl(static_cast<long double>(x)));
    const double ec = ulpError(c, cosl(static_cast<long double>(x)));
    if (es > worst_sin) worst_sin = es, at_sin = x;
    if (ec > worst_cos) worst_cos = ec, at_cos = x;
  }
  EXPECT_LT(worst_sin, 1.0) << "at " << at_sin;
  EXPECT_LT(worst_cos, 1.0) << "at " << at_cos;
  std::printf("worst error: sin %.3f ulp (x = %.17g), cos %.3f ulp (x = %.17g)\n", worst_sin, at_sin, worst_cos,
              at_cos);
}

TEST(Trig, SinAndCosAloneGiveSinCosBits) {
  for (const double x : arguments()) {
    double s, c;
    sinCos(x, s, c);
    ASSERT_TRUE(sameBits(sinOf(x), s)) << x;
    ASSERT_TRUE(sameBits(cosOf(x), c)) << x;
  }
}

#if defined(__SSE2__)
#endif

// Kanayama::compute reuses cos/sin of the robot's heading for theta_e = -theta (reference heading 0):
// exact only if cos is even and sin odd to the bit. The values go through volatile so that the compiler
// cannot fold sin(-x) into -sin(x) itself.
TEST(Trig, CosIsEvenAndSinOddToTheBit) {
  for (const double x : arguments()) {
    volatile double vx = x, vneg = -x;
    double sx, cx, sn, cn;
    sinCos(vx, sx, cx);
    sinCos(vneg, sn, cn);
    ASSERT_TRUE(sameBits(cx, cn)) << "cos not even at " << x;
    ASSERT_TRUE(sameBits(-sx, sn)) << "sin not odd at " << x;
  }
}

TEST(Trig, Edges) {
  double s, c;
  sinCos(-0.0, s, c);
  EXPECT_TRUE(std::signbit(s));
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  sinCos(1e-20, s, c);
  EXPECT_EQ(s, 1e-20);
  EXPECT_EQ(c, 1.0);
  // Beyond the reduction's range: libm's own values.
  for (const double x : {823549.7, -1e6, 3.0e8, 1e300}) {
    sinCos(x, s, c);
    EXPECT_TRUE(sameBits(s, std::sin(x))) << x;
    EXPECT_TRUE(sameBits(c, std::cos(x))) << x;
  }
  for (const double x : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity()}) {
    sinCos(x, s, c);
    EXPECT_TRUE(std::isnan(s)) << x;
    EXPECT_TRUE(std::isnan(c)) << x;
    EXPECT_TRUE(std::isnan(sinOf(x))) << x;
    EXPECT_TRUE(std::isnan(cosOf(x))) << x;
  }
}

// One sine for the whole package: a std::sin or std::cos in a source would compute other bits than the
// core's in one place (a node against the in-process runner, say). trig.h's libm fallback is the only one.
TEST(Trig, NoLibrarySinOrCosInTheSources) {
  const std::string root = SOWING_SOURCE_DIR;
  const std::regex call(R"(\bstd::(sin|cos)\s*\(|\bsincos\s*\()");
  std::vector<std::string> offenders;
  int files = 0;
  const auto scan = [&](const std::string& dir, const auto& self) -> void {
    DIR* d = ::opendir(dir.c_str());
    ASSERT_NE(d, nullptr) << dir;
    while (const dirent* e = ::readdir(d)) {
      const std::string name = e->d_name, path = dir + "/" + name;
      if (name == "." || name == "..") continue;
      if (e->d_type == DT_DIR) {
        self(path, self);
        continue;
      }
      if (!std::regex_search(name, std::regex(R"(\.(h|cpp)$)")) || name == "trig.h") continue;
      ++files;
      std::ifstream in(path);
      std::string line;
      for (int n = 1; std::getline(in, line); ++n) {
        const std::string code = line.substr(0, line.find("//"));
        if (std::regex_search(code, call)) offenders.push_back(path.substr(root.size() + 1) + ":" + std::to_string(n));
      }
    }
    ::closedir(d);
  };
  for (const char* dir : {"/src", "/include"}) scan(root + dir, scan);
  EXPECT_GT(files, 50);
  std::string list;
  for (const std::string& o : offenders) list += " " + o;
  EXPECT_TRUE(offenders.empty()) << "use core::sinCos / sinOf / cosOf (core/numerics/trig.h):" << list;
}
