// The chi-square bounds the EKF consistency tests (test_ekf, test_ekf_slip) hold the mean NEES to.
#pragma once

#include <cmath>
#include <cstddef>

namespace sowing_robot::test {

/// Quantile of chi-square with k dof at the standard normal quantile z (Wilson-Hilferty; within 0.1 % for k >= 50).
inline double chi2Quantile(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

/// The interval of the mean NEES over M independent runs at one time: chi2(4 M) / M, two-sided at z (1.96: 95 %).
struct NeesBounds {
  double lo, hi;
};
inline NeesBounds neesBounds(std::size_t runs, double z = 1.96) {
  const double k = 4.0 * runs;
  return {chi2Quantile(k, -z) / runs, chi2Quantile(k, z) / runs};
}

}  // namespace sowing_robot::test
