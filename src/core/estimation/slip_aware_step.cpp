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

/// S^-1 as Eigen inverts a matrix of run-time size (LU with partial pivoting), on the fixed size: the same
/// algorithm, so the same result to the bit, without the blocked triangular solves a run-time size takes.
template <int N>
Square inverseOfSize(const Square& s) {
  return Eigen::PartialPivLU<Eigen::Matrix<double, N, N>>(Eigen::Matrix<double, N, N>(s)).inverse();
}

Square inverse(const Square& s) {
  switch (s.rows()) {
    case 1: return inverseOfSize<1>(s);
    case 2: return inverseOfSize<2>(s);
    default: return inverseOfSize<3>(s);
  }
}

/// One exact Kalman update of the augmented vector by the linear measurements z = H a + e, e ~ N(0, R),
/// with the optimal gain: P - K S K^T, symmetrised (the cheaper form; the fix update, whose gain may be
/// a consider gain, keeps Joseph's).
/// P H^T and K (P H^T)^T are written out: Eigen sends these sizes to its blocked matrix product, whose
/// packing and dispatch cost more than the arithmetic. Each element is summed as that product sums it
/// (from 0.0, over the inner index in order, no FMA), so the results are the same to the bit.
void kalmanUpdate(Vector10& a, Matrix10& p, const Rows& h, const Column& z, const Square& r) {
  const Eigen::Index n = h.rows();
  Eigen::Matrix<double, 10, Eigen::Dynamic, 0, 10, 3> ph(10, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    Vector10 sum = Vector10::Zero();
    for (int m = 0; m < 10; ++m) sum += p.col(m) * h(j, m);
    ph.col(j) = sum;
  }
  const Square s = h * ph + r;
  const Eigen::Matrix<double, 10, Eigen::Dynamic, 0, 10, 3> k = ph * inverse(s);
  a += k * (z - h * a);
  for (int j = 0; j < 10; ++j) {
    Vector10 sum = Vector10::Zero();
    for (Eigen::Index m = 0; m < n; ++m) sum += k.col(m) * ph(j, m);
    p.col(j) -= sum;
  }
  p = 0.5 * (p + p.transpose()).eval();
}

/// cov := F pa F^T for F = slipAwareJacobian: its structure written out (the identity but for the rows and
/// columns of x, y and theta), each element summed as Eigen's matrix product sums it (from 0.0, over the
/// inner index in order, leaving out F's zeros, which add nothing to a sum started at 0.0), so the result
/// is the same to the bit.
void propagateCovariance(const Matrix10& pa, const Eigen::Matrix<double, 7, 10>& f, SlipMatrix& cov) {
  using Row10 = Eigen::Matrix<double, 1, 10>;
  const Row10 fx = f.row(Ekf::X), fy = f.row(Ekf::Y);
  const Row10 zero = Row10::Zero();
  Eigen::Matrix<double, 7, 10> g;  // F pa
  g.row(Ekf::X) = (((((zero + pa.row(Ekf::X)) + fx(Ekf::THETA) * pa.row(Ekf::THETA)) + fx(kSpeed) * pa.row(kSpeed)) +
                    fx(DW) * pa.row(DW)) +
                   fx(NU) * pa.row(NU)) +
                  fx(ND) * pa.row(ND);
  g.row(Ekf::Y) = (((((zero + pa.row(Ekf::Y)) + fy(Ekf::THETA) * pa.row(Ekf::THETA)) + fy(kSpeed) * pa.row(kSpeed)) +
                    fy(DW) * pa.row(DW)) +
                   fy(NU) * pa.row(NU)) +
                  fy(ND) * pa.row(ND);
  g.row(Ekf::THETA) = ((zero + pa.row(Ekf::THETA)) + pa.row(DW)) + pa.row(ND);
  for (int i = Ekf::BIAS; i < 7; ++i) g.row(i) = zero + pa.row(i);
  const SlipVector z7 = SlipVector::Zero();
  cov.col(Ekf::X) = (((((z7 + g.col(Ekf::X)) + g.col(Ekf::THETA) * fx(Ekf::THETA)) + g.col(kSpeed) * fx(kSpeed)) +
                      g.col(DW) * fx(DW)) +
                     g.col(NU) * fx(NU)) +
                    g.col(ND) * fx(ND);
  cov.col(Ekf::Y) = (((((z7 + g.col(Ekf::Y)) + g.col(Ekf::THETA) * fy(Ekf::THETA)) + g.col(kSpeed) * fy(kSpeed)) +
                      g.col(DW) * fy(DW)) +
                     g.col(NU) * fy(NU)) +
                    g.col(ND) * fy(ND);
  cov.col(Ekf::THETA) = ((z7 + g.col(Ekf::THETA)) + g.col(DW)) + g.col(ND);
  for (int j = Ekf::BIAS; j < 7; ++j) cov.col(j) = z7 + g.col(j);
}

}  // namespace

namespace {

/// What slipAwareMotion and slipAwareJacobian share: the step's travel u, heading change d, midpoint heading
/// and its sine and cosine (computed once per step).
struct MotionTerms {
  double u, d, sin_mid, cos_mid;
};

MotionTerms motionTerms(const Vector10& a, double dt) {
  const double u = a(kSpeed) * dt + a(NU), d = a(DW) + a(ND), mid = a(Ekf::THETA) + 0.5 * d;
  return {u, d, std::sin(mid), std::cos(mid)};
}

SlipVector motionOf(const Vector10& a, const MotionTerms& m) {
  SlipVector s = a.head<7>();
  s(Ekf::X) += m.u * m.cos_mid;
  s(Ekf::Y) += m.u * m.sin_mid;
  s(Ekf::THETA) = wrapAngle(a(Ekf::THETA) + m.d);
  return s;
}

Eigen::Matrix<double, 7, 10> jacobianOf(const MotionTerms& m, double dt) {
  const double u = m.u, s = m.sin_mid, c = m.cos_mid;
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

}  // namespace

SlipVector slipAwareMotion(const Vector10& a, double dt) { return motionOf(a, motionTerms(a, dt)); }

Eigen::Matrix<double, 7, 10> slipAwareJacobian(const Vector10& a, double dt) {
  return jacobianOf(motionTerms(a, dt), dt);
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
  const MotionTerms terms = motionTerms(a, dt);
  mean = motionOf(a, terms);
  propagateCovariance(pa, jacobianOf(terms, dt), cov);
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
