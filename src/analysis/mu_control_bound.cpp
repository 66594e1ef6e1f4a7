// Bounds of R from the control matrices of M (see mu_control_bound.hpp for the method).
// Rounding: each short sum of products below (at most a dozen operations) is within
// gamma_16 of the exact value relative to the sum of the absolute values of its terms
// (Higham §3.1); error radii are enlarged by (1 + gamma_16) for their own rounding, and
// every final bound is stepped one ulp outward.
#include "analysis/mu_control_bound.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/bezier_basis.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

const double kGamma = rounding_gamma(16);

EigenEnclosure unknown() { return {-kInf, kInf, -kInf, kInf}; }

// theta in [1 - eps, 1 + eps]: the range of x / theta, rounded outward.
double divide_down(double x, double eps) {
  return next_down(x / next_down(x >= 0 ? 1 + eps : 1 - eps));
}
double divide_up(double x, double eps) {
  return next_up(x / next_up(x >= 0 ? 1 - eps : 1 + eps));
}

}  // namespace

double EigenEnclosure::ratio_lower() const noexcept {
  if (!(min_lo > 0) || !(max_hi < kInf)) return 0;
  return std::clamp(next_down(min_lo / max_hi), 0.0, 1.0);
}

double EigenEnclosure::ratio_upper() const noexcept {
  if (!(max_lo > 0) || !(min_hi < kInf)) return 1;
  return std::clamp(next_up(min_hi / max_lo), 0.0, 1.0);
}

template <>
EigenEnclosure symmetric_eigen_enclosure<2>(const double* m, double err) {
  // lambda = q +- d, q = (m00 + m11) / 2, d = sqrt(s^2 + t^2), s = (m00 - m11) / 2, t = m01.
  const double q = 0.5 * (m[0] + m[1]);
  const double s = 0.5 * (m[0] - m[1]);
  const double t = m[2];
  const double rq = (err + kGamma * 0.5 * (std::abs(m[0]) + std::abs(m[1]))) * (1 + kGamma);
  const double rt = err;
  const double s_hi = next_up(std::abs(s) + rq), s_lo = std::max(0.0, next_down(std::abs(s) - rq));
  const double t_hi = next_up(std::abs(t) + rt), t_lo = std::max(0.0, next_down(std::abs(t) - rt));
  const double d_hi = next_up(sqrt_rn(next_up(next_up(s_hi * s_hi) + next_up(t_hi * t_hi))));
  const double d_lo = std::max(0.0, next_down(sqrt_rn(std::max(0.0, next_down(next_down(s_lo * s_lo) + next_down(t_lo * t_lo))))));
  const double q_lo = next_down(q - rq), q_hi = next_up(q + rq);
  if (!std::isfinite(q_lo) || !std::isfinite(q_hi) || !std::isfinite(d_hi)) return unknown();
  return {next_down(q_lo - d_hi), next_up(q_hi - d_lo), next_down(q_lo + d_lo), next_up(q_hi + d_hi)};
}

template <>
EigenEnclosure symmetric_eigen_enclosure<3>(const double* m, double err) {
  Eigen::Matrix3d a;
  a << m[0], m[3], m[4], m[3], m[1], m[5], m[4], m[5], m[2];
  if (!a.allFinite()) return unknown();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(a);  // closed form: any V is sound, only the tightness depends on it
  const Eigen::Matrix3d& v = eig.eigenvectors();
  if (!v.allFinite()) return unknown();
  // eps >= |V^T V - I|_2 (max row sum of the symmetric error matrix, rounding included).
  double eps = 0;
  for (int i = 0; i < 3; ++i) {
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      const double s = v(0, i) * v(0, j) + v(1, i) * v(1, j) + v(2, i) * v(2, j);
      const double mag = std::abs(v(0, i) * v(0, j)) + std::abs(v(1, i) * v(1, j)) + std::abs(v(2, i) * v(2, j));
      row += std::abs(i == j ? s - 1 : s) + kGamma * (mag + 1);
    }
    eps = std::max(eps, row * (1 + kGamma));
  }
  if (!(eps < 0.5)) return unknown();
  // B = V^T a V computed; |B - V^T M V| <= err s_i s_j + gamma (|V|^T |a| |V|)_ij.
  const Eigen::Matrix3d t = a * v;
  const Eigen::Matrix3d b = v.transpose() * t;
  const Eigen::Matrix3d av = v.cwiseAbs();
  const Eigen::Matrix3d mag = av.transpose() * (a.cwiseAbs() * av);
  const Eigen::Vector3d s = av.colwise().sum().transpose();
  double rad[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rad[i][j] = (err * s(i) * s(j) + kGamma * mag(i, j)) * (1 + kGamma);
  double bmin_lo = kInf, bmax_hi = -kInf, bmin_hi = kInf, bmax_lo = -kInf;
  for (int i = 0; i < 3; ++i) {
    double r = rad[i][i];
    for (int j = 0; j < 3; ++j)
      if (j != i) r += std::abs(b(i, j)) + rad[i][j];
    r *= 1 + kGamma;
    bmin_lo = std::min(bmin_lo, next_down(b(i, i) - r));  // Gershgorin
    bmax_hi = std::max(bmax_hi, next_up(b(i, i) + r));
    bmin_hi = std::min(bmin_hi, next_up(b(i, i) + rad[i][i]));  // Rayleigh quotients
    bmax_lo = std::max(bmax_lo, next_down(b(i, i) - rad[i][i]));
  }
  if (!std::isfinite(bmin_lo) || !std::isfinite(bmax_hi)) return unknown();
  // Ostrowski: lambda_k(M) = lambda_k(B) / theta_k, theta_k in [1 - eps, 1 + eps].
  return {divide_down(bmin_lo, eps), divide_up(bmin_hi, eps), divide_down(bmax_lo, eps), divide_up(bmax_hi, eps)};
}

namespace {

// Sylvester's criterion for the exact symmetric floating-point matrix
// [a0 a3 a4; a3 a1 a5; a4 a5 a2]: true only if it is positive definite. Each leading minor
// is computed in at most 5 roundings deep (gamma_5 of the sum of the absolute values of its
// terms; gamma_8 and (1 + gamma_8) cover the bound's own rounding).
bool positive_definite3(const double* a) {
  static const double g = rounding_gamma(8);
  if (!(a[0] > 0)) return false;
  const double p01 = a[0] * a[1], s01 = a[3] * a[3];
  if (!(p01 - s01 > g * (std::abs(p01) + s01) * (1 + g))) return false;
  const double c0 = a[1] * a[2] - a[5] * a[5];
  const double c1 = a[3] * a[2] - a[5] * a[4];
  const double c2 = a[3] * a[5] - a[1] * a[4];
  const double det = a[0] * c0 - a[3] * c1 + a[4] * c2;
  const double mag = std::abs(a[0]) * (std::abs(a[1] * a[2]) + a[5] * a[5]) +
                     std::abs(a[3]) * (std::abs(a[3] * a[2]) + std::abs(a[5] * a[4])) +
                     std::abs(a[4]) * (std::abs(a[3] * a[5]) + std::abs(a[1] * a[4]));
  return det > g * mag * (1 + g);
}

}  // namespace

// No eigenvalue needed. By Laguerre and Samuelson, every
// eigenvalue of m lies within sqrt 2 sigma of their mean mu = tr m / 3, sigma^2 =
// tr((m - mu I)^2) / 3 <= tr((m - c I)^2) / 3 for any c (here the computed mean), so
// t = c + |mu - c| + sqrt(2/3 tr((m - c I)^2)) + 3 err >= lambda_max(M') (|E|_2 <= 3 err),
// every step rounded up; then M' - r t I > 0 (Sylvester, as in extreme_eigen_bounds3)
// gives lambda_min(M') > r t >= r lambda_max(M'). Cheap (one square root) and tight for the
// nearly isotropic control matrices of a good element; it fails, and the caller encloses
// the eigenvalues, when eigenvalues cluster at the top.
bool ratio_at_least3(const double* m, double err, double r) {
  constexpr double u = 0x1p-53;
  const double c = (m[0] + m[1] + m[2]) / 3;
  const double shift = 4 * u * (std::abs(m[0]) + std::abs(m[1]) + std::abs(m[2]));  // >= |mu - c|
  const double d0 = m[0] - c, d1 = m[1] - c, d2 = m[2] - c;
  const double sq = d0 * d0 + d1 * d1 + d2 * d2 + 2 * (m[3] * m[3] + m[4] * m[4] + m[5] * m[5]);
  if (!std::isfinite(sq)) return false;
  // sq within 8u relative of tr((m - c I)^2) (sums of squares of once-rounded terms).
  const double spread = next_up(sqrt_rn(next_up(sq * (2.0 / 3.0) * (1 + 16 * u))));
  const double t = next_up(next_up(next_up(c + shift) + spread) + next_up(3 * err * (1 + 1e-15)));
  const double sa = next_up(next_up(r * t) + next_up(3 * err * (1 + 1e-15)));
  const double s[6] = {next_down(m[0] - sa), next_down(m[1] - sa), next_down(m[2] - sa), m[3], m[4], m[5]};
  return positive_definite3(s);
}

namespace {

constexpr int kW = kNativeLanes;
using LW = Lanes<kW>;
using lanes3::down;
using lanes3::up;

// ratio_at_least3 on kW matrices at once (lane l: entries m[i][l]), bit-identical decisions
// (symmetric3_lanes.hpp); true lanes set in the returned mask.
unsigned ratio_at_least3_lanes(const LW* m, double err, double r) {
  return lanes3::mask_bits<kW>(lanes3::ratio_at_least<kW>(m, err, r));
}

}  // namespace

// Inlined into control_ratio_lower2's loop (as a call it took 10% of quad_h0.4_o2's mu).
template <int W>
[[gnu::always_inline]] inline Lanes<W> enclosure_ratio_lower2_lanes(const Lanes<W>* m, Lanes<W> err) {
  using lanes3::down;
  using lanes3::up;
  using V = Lanes<W>;
  const V zero{}, q = 0.5 * (m[0] + m[1]), s = 0.5 * (m[0] - m[1]), t = m[2];
  const V rq = (err + kGamma * 0.5 * (vabs(m[0]) + vabs(m[1]))) * (1 + kGamma);
  const V s_hi = up<W>(vabs(s) + rq), s_lo = vmax(zero, down<W>(vabs(s) - rq));
  const V t_hi = up<W>(vabs(t) + err), t_lo = vmax(zero, down<W>(vabs(t) - err));
  V d_hi = up<W>(up<W>(s_hi * s_hi) + up<W>(t_hi * t_hi));
  V d_lo = vmax(zero, down<W>(down<W>(s_lo * s_lo) + down<W>(t_lo * t_lo)));
  for (int l = 0; l < W; ++l) {  // vsqrtpd: exact rounding, as std::sqrt
    d_hi[l] = std::sqrt(d_hi[l]);
    d_lo[l] = std::sqrt(d_lo[l]);
  }
  d_hi = up<W>(d_hi);
  d_lo = vmax(zero, down<W>(d_lo));
  const V q_lo = down<W>(q - rq), q_hi = up<W>(q + rq);
  const V min_lo = down<W>(q_lo - d_hi), max_hi = up<W>(q_hi + d_hi);
  constexpr double kMax = std::numeric_limits<double>::max();
  // An enclosure that is unknown (a non-finite step) or not positive: ratio 0.
  const auto known = (vabs(q_lo) <= kMax) & (vabs(q_hi) <= kMax) & (vabs(d_hi) <= kMax) & (min_lo > 0) & (max_hi < kInf);
  const V ratio = down<W>(min_lo / max_hi);
  return known ? vmin(vmax(ratio, zero), V{} + 1) : zero;
}
template Lanes<2> enclosure_ratio_lower2_lanes<2>(const Lanes<2>*, Lanes<2>);
template Lanes<4> enclosure_ratio_lower2_lanes<4>(const Lanes<4>*, Lanes<4>);
#if defined(__AVX512F__)  // kNativeLanes
template Lanes<8> enclosure_ratio_lower2_lanes<8>(const Lanes<8>*, Lanes<8>);
#endif

template <int W>
Lanes<W> enclosure_ratio_upper2_lanes(const Lanes<W>* m, Lanes<W> err) {
  using lanes3::down;
  using lanes3::up;
  using V = Lanes<W>;
  const V zero{}, q = 0.5 * (m[0] + m[1]), s = 0.5 * (m[0] - m[1]), t = m[2];
  const V rq = (err + kGamma * 0.5 * (vabs(m[0]) + vabs(m[1]))) * (1 + kGamma);
  const V s_hi = up<W>(vabs(s) + rq), s_lo = vmax(zero, down<W>(vabs(s) - rq));
  const V t_hi = up<W>(vabs(t) + err), t_lo = vmax(zero, down<W>(vabs(t) - err));
  const V d_hi = up<W>(lanes3::root<W>(up<W>(up<W>(s_hi * s_hi) + up<W>(t_hi * t_hi))));
  const V d_lo = vmax(zero, down<W>(lanes3::root<W>(vmax(zero, down<W>(down<W>(s_lo * s_lo) + down<W>(t_lo * t_lo))))));
  const V q_lo = down<W>(q - rq), q_hi = up<W>(q + rq);
  constexpr double kMax = std::numeric_limits<double>::max();
  const auto known = (vabs(q_lo) <= kMax) & (vabs(q_hi) <= kMax) & (vabs(d_hi) <= kMax);
  const V min_hi = up<W>(q_hi - d_lo), max_lo = down<W>(q_lo + d_lo);
  // ratio_upper: 1 where unknown, max_lo not positive or min_hi not finite, else clamped.
  const V ratio = vmin(vmax(up<W>(min_hi / max_lo), zero), V{} + 1);
  return known & (max_lo > 0) & (min_hi < kInf) ? ratio : V{} + 1;
}
// Four lanes: mu_bounds.cpp; two and the native width: the closed form of straight triangles
// (straight_simplex_mu.cpp).
template Lanes<2> enclosure_ratio_upper2_lanes<2>(const Lanes<2>*, Lanes<2>);
template Lanes<4> enclosure_ratio_upper2_lanes<4>(const Lanes<4>*, Lanes<4>);
#if defined(__AVX512F__)  // kNativeLanes
template Lanes<8> enclosure_ratio_upper2_lanes<8>(const Lanes<8>*, Lanes<8>);
#endif

namespace {

// symmetric_eigen_enclosure<2>(m, err).ratio_lower() of kW matrices at once (lane l:
// entries m[i][l]), each lane with the scalar functions' operations in the same order
// (bit-identical per matrix).
LW enclosure_ratio_lower2_block(const LW* m, double err) { return quadval::enclosure_ratio_lower2_lanes<kW>(m, LW{} + err); }

// cos(acos(c) / 3) for c in [-1, 1], without trigonometric calls (acos and sincos were a
// fifth of mu's time on linear hexahedra): the largest root x in [1/2, 1] of
// 4 x^3 - 3 x = c, from a polynomial in s = sqrt((1 + c) / 2) (least squares on Chebyshev
// points, within 2.3e-8 of cos(2/3 acos s) on [0, 1]) and two Newton steps. Within a few
// ulps of the trigonometric form except close to c = -1, where both lose accuracy as
// 1 / sqrt(1 + c) (the top two eigenvalues nearly equal); the caller polishes the
// eigenvalues and certifies them whatever their accuracy.
double trisected_cosine(double c) {
  const double s = sqrt_rn(0.5 * (1 + c));
  double x = 0x1.2d945fe635cc5p-10;
  for (const double a : {-0x1.945b176bae327p-8, 0x1.08c20eb3ca04dp-6, -0x1.f0a66ec75bf0ap-6, 0x1.b11a9b6a6b367p-5,
                         -0x1.c6d5485f6740bp-4, 0x1.279a0e23f9291p-1, 0x1.000000c367160p-1})
    x = x * s + a;
  for (int step = 0; step < 2; ++step) {
    const double slope = 12 * x * x - 3;
    if (!(slope > 0)) break;
    x -= ((4 * x * x - 3) * x - c) / slope;
  }
  return std::clamp(x, 0.5, 1.0);
}

}  // namespace

bool extreme_eigen_bounds3(const double* m, double err, double& min_lo, double& max_hi) {
  // Eigenvalues q + y of M: y^3 - 3 p^2 y - e3 = 0 with D = M - q I, p^2 = tr D^2 / 6,
  // e3 = det D; y = 2 p cos(theta + 2 pi k / 3), cos(3 theta) = e3 / (2 p^3).
  const double q = (m[0] + m[1] + m[2]) / 3;
  const double d0 = m[0] - q, d1 = m[1] - q, d2 = m[2] - q;
  const double off = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
  const double p2 = (d0 * d0 + d1 * d1 + d2 * d2 + 2 * off) / 6;
  const double scale = std::abs(q) + 2 * sqrt_rn(p2);
  if (!std::isfinite(scale) || !(scale > 0)) return false;
  double y_min = 0, y_max = 0;
  if (p2 > 1e-30 * q * q) {
    const double p = sqrt_rn(p2);
    const double e3 = d0 * (d1 * d2 - m[5] * m[5]) - m[3] * (m[3] * d2 - m[5] * m[4]) + m[4] * (m[3] * m[5] - d1 * m[4]);
    const double c = std::clamp(e3 / (2 * p2 * p), -1.0, 1.0);
    const double ct = trisected_cosine(c);
    const double st = sqrt_rn((1 - ct) * (1 + ct));
    y_max = 2 * p * ct;
    y_min = 2 * p * (-0.5 * ct - 0.8660254037844386 * st);  // cos(theta + 2 pi / 3)
    // One Newton step each on y^3 - 3 p^2 y - e3 (accuracy only, not soundness).
    for (double* y : {&y_min, &y_max}) {
      const double f = (*y * *y - 3 * p2) * *y - e3, fp = 3 * (*y * *y - p2);
      if (std::abs(fp) > 1e-3 * p2) {
        const double step = f / fp;
        if (std::abs(step) < 1e-3 * p) *y -= step;
      }
    }
  }
  // Margins: rounding of the approximations and the minors' error bounds (relative to the
  // matrix's scale), plus the entry errors.
  const double margin = 1e-12 * scale + 3 * err;
  const double a = next_down(q + y_min - margin);
  const double b = next_up(q + y_max + margin);
  // M - a I - 3 err I >= S (S's diagonal rounded down) and b I - M - 3 err I >= T.
  const double e3x = next_up(3 * err * (1 + 1e-15));
  const double sa = next_up(a + e3x), sb = next_down(b - e3x);
  const double s[6] = {next_down(m[0] - sa), next_down(m[1] - sa), next_down(m[2] - sa), m[3], m[4], m[5]};
  const double t[6] = {next_down(sb - m[0]), next_down(sb - m[1]), next_down(sb - m[2]), -m[3], -m[4], -m[5]};
  if (!positive_definite3(s) || !positive_definite3(t)) return false;
  min_lo = a;
  max_hi = b;
  return true;
}

bool ratio_at_least2(const double* m, double err, double r) {
  // lambda = q -+ d as in symmetric_eigen_enclosure<2>, with the same radius rq of q and s
  // over the error box; with q > 0, (q - d) >= r (q + d) iff q (1 - r) >= d (1 + r) iff
  // q^2 (1 - r)^2 >= (s^2 + t^2) (1 + r)^2.
  const double q = 0.5 * (m[0] + m[1]), s = 0.5 * (m[0] - m[1]);
  const double rq = (err + kGamma * 0.5 * (std::abs(m[0]) + std::abs(m[1]))) * (1 + kGamma);
  const double q_lo = next_down(q - rq);
  if (!(q_lo > 0)) return false;
  const double s_hi = next_up(std::abs(s) + rq), t_hi = next_up(std::abs(m[2]) + err);
  // Each side, its factor (1 -+ kGamma) included, is within 8 roundings of its exact
  // value: gamma_16 on both sides covers them.
  const double lhs = q_lo * q_lo * ((1 - r) * (1 - r));
  const double rhs = (s_hi * s_hi + t_hi * t_hi) * ((1 + r) * (1 + r));
  return lhs * (1 - kGamma) > rhs * (1 + kGamma);
}

double ratio_estimate3(const double* m) {
  const double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5];
  const double t = (a + b + c) / 3;
  const double det = a * (b * c - f * f) - d * (d * c - f * e) + e * (d * f - b * e);
  const double est = det / (t * t * t);
  return t > 0 && std::isfinite(est) ? est : -1.0;
}

namespace {

// 2D: every matrix's enclosure, kW at a time, branch-free (the closed form is about as
// cheap as the test that would skip it; the last block repeats matrix 0 in its spare
// lanes).
double control_ratio_lower2(const double* const* entries, double e, int size) {
  double r = 1;
  for (int k = 0; k < size; k += kW) {
    LW lanes[3];
    for (int i = 0; i < 3; ++i) {
      if (size - k >= kW) {
        lanes[i] = load_lanes<kW>(entries[i] + k);
        continue;
      }
      double tail[kW];
      for (int l = 0; l < kW; ++l) tail[l] = entries[i][k + l < size ? k + l : 0];
      lanes[i] = load_lanes<kW>(tail);
    }
    r = fold_min(enclosure_ratio_lower2_block(lanes, e), r);
  }
  return r;
}

double control_ratio_lower3(const double* const* entries, double e, int size, double enough) {
  double r = std::min(1.0, enough);
  double m[6];
  const auto load = [&](int k) {
    for (int i = 0; i < 6; ++i) m[i] = entries[i][k];
  };
  const auto enclose = [&](int k) {
    load(k);
    double lo, hi;
    if (extreme_eigen_bounds3(m, e, lo, hi))
      r = std::min(r, lo > 0 ? std::clamp(next_down(lo / hi), 0.0, 1.0) : 0.0);
    else
      r = std::min(r, symmetric_eigen_enclosure<3>(m, e).ratio_lower());
  };
  // The matrix of least estimated ratio is enclosed first, so that the cheap test below
  // certifies most others against an r near the final one (hex_box: 4.8 enclosures per
  // subdomain when starting from the first matrix).
  // With a bound that suffices below 1 (a subdomain's r_target), most matrices pass the
  // cheap test against it at once, and the search is skipped.
  int first = -1;
  if (size > 1 && enough >= 1) {
    double least = kInf;
    int k = 0;
    for (; k + kW <= size; k += kW) {  // ratio_estimate3 kW at a time: the same values
      LW a[6];
      for (int i = 0; i < 6; ++i) a[i] = load_lanes<kW>(entries[i] + k);
      const LW t = (a[0] + a[1] + a[2]) / 3;
      const LW det = a[0] * (a[1] * a[2] - a[5] * a[5]) - a[3] * (a[3] * a[2] - a[5] * a[4]) +
                     a[4] * (a[3] * a[5] - a[1] * a[4]);
      const LW ratio = det / (t * t * t);
      const LW est = (t > 0) & lanes3::finite<kW>(ratio) ? ratio : LW{} - 1.0;
      for (int l = 0; l < kW; ++l)
        if (est[l] < least) least = est[l], first = k + l;
    }
    for (; k < size; ++k) {
      load(k);
      const double est = ratio_estimate3(m);
      if (est < least) least = est, first = k;
    }
    if (first >= 0) {
      load(first);
      if (!(r < 1 && ratio_at_least3(m, e, r))) enclose(first);
    }
  }
  // Once a ratio is certified, the cheap test runs on kW control matrices at once with the
  // r of the block's start; a matrix it certifies is at least that r, so at least the
  // current one, and is skipped as the scalar test would skip it (the test is monotone in
  // r). Only the others go through the scalar test below, in order; a matrix the block
  // test did not certify is tested again only if r has dropped since. Most control
  // matrices lie well above the least ratio found so far: certifying that cheaply skips
  // their eigenvalue enclosure (r stays a lower bound of their ratios).
  unsigned certified = 0;  // bit l: matrix block_start + l certified
  int block_start = 0, block_end = 0;
  double block_r = 1;
  for (int k = 0; k < size && r > 0; ++k) {
    if (k == first) continue;
    if (r < 1 && k >= block_end && size - k >= 4) {
      block_start = k;
      block_end = std::min(k + kW, size);
      block_r = r;
      Lanes<kW> lanes[6];
      for (int i = 0; i < 6; ++i)
        if (block_end - k == kW)
          lanes[i] = load_lanes<kW>(entries[i] + k);
        else
          for (int l = 0; l < kW; ++l) lanes[i][l] = k + l < block_end ? entries[i][k + l] : (i < 3 ? 1.0 : 0.0);
      certified = ratio_at_least3_lanes(lanes, e, r);
    }
    if (k < block_end && ((certified >> (k - block_start)) & 1u) != 0) continue;
    const bool tested = k < block_end && r == block_r;
    load(k);
    if (r < 1 && !tested && ratio_at_least3(m, e, r)) continue;
    enclose(k);
  }
  return r;
}

}  // namespace

template <int D>
double control_ratio_lower(const double* const* entries, const double* err, int size, double enough) {
  constexpr int kEntries = D * (D + 1) / 2;
  double e = 0;
  for (int i = 0; i < kEntries; ++i) e = std::max(e, err[i]);
  return D == 2 ? control_ratio_lower2(entries, e, size) : control_ratio_lower3(entries, e, size, enough);
}

template double control_ratio_lower<2>(const double* const*, const double*, int, double);
template double control_ratio_lower<3>(const double* const*, const double*, int, double);

}  // namespace quadval
