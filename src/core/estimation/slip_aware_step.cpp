#include "sowing_robot/core/estimation/slip_aware_step.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "sowing_robot/core/estimation/ekf.h"

namespace sowing_robot {
namespace core {
namespace {

using Vector10 = Eigen::Matrix<double, 10, 1>;
using Matrix10 = Eigen::Matrix<double, 10, 10>;
enum Augmented { DW = 7, NU = 8, ND = 9 };

// Up to three linear measurements of the augmented vector in one step (two wheels and the gyro), sized
// at run time within fixed bounds (no allocation per step).
using Rows = Eigen::Matrix<double, Eigen::Dynamic, 10, Eigen::RowMajor, 3, 10>;
using Column = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;

/// One exact Kalman update of the augmented vector by the linear measurements z = H a + e, e ~ N(0, R),
/// with the optimal gain: P - K S K^T, symmetrised (the cheaper form; the fix update, whose gain may be
/// a consider gain, keeps Joseph's).
void kalmanUpdate(Vector10& a, Matrix10& p, const Rows& h, const Column& z, const Square& r) {
  const Eigen::Matrix<double, 10, Eigen::Dynamic, 0, 10, 3> ph = p * h.transpose();
  const Square s = h * ph + r;
  const Eigen::Matrix<double, 10, Eigen::Dynamic, 0, 10, 3> k = ph * s.inverse();
  a += k * (z - h * a);
  p -= k * ph.transpose();
  p = 0.5 * (p + p.transpose()).eval();
}

}  // namespace

SlipVector slipAwareMotion(const Vector10& a, double dt) {
  const double u = a(kSpeed) * dt + a(NU), d = a(DW) + a(ND), mid = a(Ekf::THETA) + 0.5 * d;
  SlipVector s = a.head<7>();
  s(Ekf::X) += u * std::cos(mid);
  s(Ekf::Y) += u * std::sin(mid);
  s(Ekf::THETA) = wrapAngle(a(Ekf::THETA) + d);
  return s;
}

Eigen::Matrix<double, 7, 10> slipAwareJacobian(const Vector10& a, double dt) {
  const double u = a(kSpeed) * dt + a(NU), d = a(DW) + a(ND), mid = a(Ekf::THETA) + 0.5 * d;
  const double s = std::sin(mid), c = std::cos(mid);
  Eigen::Matrix<double, 7, 10> f = Eigen::Matrix<double, 7, 10>::Zero();
  f.leftCols<7>().setIdentity();
  f(Ekf::X, Ekf::THETA) = -u * s;
  f(Ekf::X, kSpeed) = dt * c;
  f(Ekf::X, DW) = f(Ekf::X, ND) = -0.5 * u * s;
  f(Ekf::X, NU) = c;
  f(Ekf::Y, Ekf::THETA) = u * c;
  f(Ekf::Y, kSpeed) = dt * s;
  f(Ekf::Y, DW) = f(Ekf::Y, ND) = 0.5 * u * c;
  f(Ekf::Y, NU) = s;
  f(Ekf::THETA, DW) = f(Ekf::THETA, ND) = 1.0;
  return f;
}

void slipAwarePropagate(const EkfParams& p, double L, double dt, const EkfStepInput& in, unsigned loose,
                        SlipVector& mean, SlipMatrix& cov) {
  const SlipParams& sp = p.slip;
  Vector10 a = Vector10::Zero();
  a.head<7>() = mean;
  a(DW) = in.dtheta;
  Matrix10 pa = Matrix10::Zero();
  pa.topLeftCorner<7, 7>() = cov;
  // d_w: wide (ten times the turn of a wheel at the largest ground speed), so the measurements decide it.
  const double wide = 10.0 * sp.max_ground_speed * dt / L;
  pa(DW, DW) = wide * wide;
  const double rolled = std::fabs(mean(kSpeed)) * dt;
  pa(NU, NU) = p.distance_noise * p.distance_noise * rolled;
  pa(ND, ND) = p.heading_noise * p.heading_noise * rolled;
  // The encoders' noise on the wheels' travels: s_R = distance + L dtheta, s_L = distance - L dtheta.
  Eigen::Matrix2d t;
  t << 1.0, L, 1.0, -L;
  const Eigen::Matrix2d w = t * in.covariance * t.transpose();
  const double travel[2] = {in.distance + L * in.dtheta, in.distance - L * in.dtheta};
  const bool use[2] = {!(loose & SLIP_RIGHT), !(loose & SLIP_LEFT)};
  const int rows = int(use[0]) + int(use[1]) + int(in.has_rate);
  if (rows > 0) {
    Rows h = Rows::Zero(rows, 10);
    Column z(rows);
    Square r = Square::Zero(rows, rows);
    int row = 0, wheel_row[2] = {-1, -1};
    for (int i : {0, 1}) {
      if (!use[i]) continue;
      h(row, kSpeed) = dt;
      h(row, i == 0 ? kSlipRight : kSlipLeft) = dt;
      h(row, DW) = i == 0 ? L : -L;
      z(row) = travel[i];
      wheel_row[i] = row++;
    }
    for (int i : {0, 1})
      for (int j : {0, 1})
        if (use[i] && use[j]) r(wheel_row[i], wheel_row[j]) = w(i, j);
    if (in.has_rate) {  // r dt = d_w + n_d + b dt + noise
      h(row, DW) = h(row, ND) = 1.0;
      h(row, Ekf::BIAS) = dt;
      z(row) = in.rate * dt;
      r(row, row) = in.rate_variance * dt * dt;
    }
    kalmanUpdate(a, pa, h, z, r);
  }
  const Eigen::Matrix<double, 7, 10> f = slipAwareJacobian(a, dt);
  mean = slipAwareMotion(a, dt);
  cov = f * pa * f.transpose();
  if (p.estimate_bias) cov(Ekf::BIAS, Ekf::BIAS) += p.bias_walk * p.bias_walk * dt;
  cov(kSpeed, kSpeed) += sp.speed_walk * sp.speed_walk * dt;
  // A large slip changes fast (a spinning wheel is out of the soil's grip): the slip's walk grows with it.
  for (int i : {kSlipRight, kSlipLeft})
    cov(i, i) += (sp.slip_walk * sp.slip_walk + sp.slip_rate * sp.slip_rate * mean(i) * mean(i)) * dt;
  cov = 0.5 * (cov + cov.transpose());
  mean(kSpeed) = std::clamp(mean(kSpeed), -sp.max_ground_speed, sp.max_ground_speed);
}

double slipAwareUpdate(const EkfFix& fix, SlipVector& mean, SlipMatrix& cov, bool apply, double* along,
                       bool keep_heading) {
  const Eigen::Vector2d nu = fix.xy - mean.head<2>();
  const Eigen::Matrix2d s = cov.topLeftCorner<2, 2>() + fix.covariance;
  const Eigen::Matrix2d s_inv = s.inverse();
  const double d2 = nu.dot(s_inv * nu);
  if (along) {
    const double sign = mean(kSpeed) < 0.0 ? -1.0 : 1.0;
    const Eigen::Vector2d dir(sign * std::cos(mean(Ekf::THETA)), sign * std::sin(mean(Ekf::THETA)));
    *along = dir.dot(nu) / std::sqrt(dir.dot(s * dir));
  }
  if (!apply) return d2;
  Eigen::Matrix<double, 7, 2> k = cov.leftCols<2>() * s_inv;
  if (keep_heading) k.middleRows<2>(Ekf::THETA).setZero();  // a consider update; Joseph's form holds for any gain
  mean += k * nu;
  mean(Ekf::THETA) = wrapAngle(mean(Ekf::THETA));
  SlipMatrix ikh = SlipMatrix::Identity();
  ikh.leftCols<2>() -= k;
  cov = ikh * cov * ikh.transpose() + k * fix.covariance * k.transpose();
  cov = 0.5 * (cov + cov.transpose());
  return d2;
}

void slipAwareReanchor(const EkfFix& fix, SlipVector& mean, SlipMatrix& cov) {
  mean.head<2>() = fix.xy;
  cov.topRows<2>().setZero();
  cov.leftCols<2>().setZero();
  cov.topLeftCorner<2, 2>() = fix.covariance;
}

}  // namespace core
}  // namespace sowing_robot
