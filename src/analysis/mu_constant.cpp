// Closed-form bounds of mu for constant W (see mu_constant.hpp for the method).
#include "analysis/mu_constant.hpp"
#include "analysis/mu_control_bound.hpp"
#include "analysis/mu_metric.hpp"
#include "analysis/mu_w_matrix.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"

namespace quadval {
namespace {

thread_local bool use_constant_path = true;

// Rounding margin of the short sums and products below (at most a dozen operations
// each), relative to the sum of the absolute values of their terms.
double margin() { return rounding_gamma(16); }

template <int D>
double ratio_lower(const Eigen::Matrix<double, 3, D>& w, double delta, double* eigenvectors) {
  const Eigen::Matrix<double, D, D> m = w.transpose() * w;
  if (!m.allFinite()) return 0;
  // Closed-form eigenvectors (Eigen's iterative solver took a quarter of mu's time on
  // straight tetrahedra): any V gives a sound bound below, V's accuracy only its tightness.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig;
  eig.computeDirect(m);
  const Eigen::Matrix<double, D, D>& v = eig.eigenvectors();
  if (eigenvectors != nullptr) {
    Eigen::Map<Eigen::Matrix<double, D, D>> out(eigenvectors);
    out = v;
  }
  if (!v.allFinite()) return 0;
  const double g = margin();
  // eps >= max_i sum_j |(V^T V - I)_ij|: entry errors gamma * sum_k |V_ki V_kj|.
  double eps = 0;
  for (int i = 0; i < D; ++i) {
    double row = 0;
    for (int j = 0; j < D; ++j) {
      double s = 0, mag = 0;
      for (int k = 0; k < D; ++k) {
        s += v(k, i) * v(k, j);
        mag += std::abs(v(k, i) * v(k, j));
      }
      row += std::abs(i == j ? s - 1 : s) + g * (mag + 1);
    }
    eps = std::max(eps, row * (1 + g));
  }
  if (!(eps < 0.5)) return 0;
  // Y = W V enclosed: |Y_exact - y| <= r (delta * sum_k |V_kj| for W's uncertainty plus
  // the rounding of the computed sum).
  Eigen::Matrix<double, 3, D> y, r;
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < D; ++j) {
      double s = 0, mag = 0, vs = 0;
      for (int k = 0; k < D; ++k) {
        s += w(c, k) * v(k, j);
        mag += std::abs(w(c, k) * v(k, j));
        vs += std::abs(v(k, j));
      }
      y(c, j) = s;
      r(c, j) = (delta * vs + g * mag) * (1 + g);
    }
  // Gershgorin on B = Y^T Y over the enclosure.
  double b_lo = std::numeric_limits<double>::infinity(), b_hi = 0;
  for (int i = 0; i < D; ++i) {
    double d_lo = 0, d_hi = 0, off = 0;
    for (int c = 0; c < 3; ++c) {
      const double a = std::abs(y(c, i));
      const double lo = std::max(0.0, next_down(a - r(c, i)));
      const double hi = next_up(a + r(c, i));
      d_lo += lo * lo;
      d_hi += hi * hi;
    }
    for (int j = 0; j < D; ++j) {
      if (j == i) continue;
      double s = 0, pert = 0, mag = 0;
      for (int c = 0; c < 3; ++c) {
        s += y(c, i) * y(c, j);
        mag += std::abs(y(c, i) * y(c, j));
        pert += r(c, i) * std::abs(y(c, j)) + std::abs(y(c, i)) * r(c, j) + r(c, i) * r(c, j);
      }
      off += (std::abs(s) + pert + g * mag) * (1 + g);
    }
    b_lo = std::min(b_lo, next_down(d_lo * (1 - g) - off * (1 + g)));
    b_hi = std::max(b_hi, next_up(d_hi * (1 + g) + off * (1 + g)));
  }
  if (!(b_lo > 0) || !std::isfinite(b_hi)) return 0;
  const double l_min = next_down(b_lo / next_up(1 + eps));
  const double l_max = next_up(b_hi / next_down(1 - eps));
  return std::clamp(next_down(l_min / l_max), 0.0, 1.0);
}

// An approximate unit eigenvector of the symmetric 3 x 3 matrix m for the approximate
// eigenvalue lambda (accuracy only: corner_ratio_upper_at's Rayleigh quotients are true
// bounds for any vector): the largest cross product of two rows of m - lambda I, which
// are orthogonal to it when lambda is a simple eigenvalue. False when those rows are
// nearly parallel (lambda nearly repeated).
bool eigenvector3(const double* m, double lambda, double* v) {
  const Eigen::Vector3d r0(m[0] - lambda, m[3], m[4]), r1(m[3], m[1] - lambda, m[5]), r2(m[4], m[5], m[2] - lambda);
  const Eigen::Vector3d c[3] = {r0.cross(r1), r0.cross(r2), r1.cross(r2)};
  int best = 0;
  for (int k = 1; k < 3; ++k)
    if (c[k].squaredNorm() > c[best].squaredNorm()) best = k;
  const double n2 = c[best].squaredNorm();
  const double rows = r0.squaredNorm() + r1.squaredNorm() + r2.squaredNorm();
  if (!(n2 > 1e-16 * rows * rows) || !std::isfinite(n2)) return false;
  Eigen::Map<Eigen::Vector3d> out(v);
  out = c[best] / sqrt_rn(n2);
  return true;
}

}  // namespace

void mu_use_constant_path(bool on) noexcept { use_constant_path = on; }
bool mu_constant_path_enabled() noexcept { return use_constant_path; }

double constant_w_radius(const MuSpace& space, const double* w, double err, double stop_above) {
  const auto ws = static_cast<std::size_t>(space.w_size());
  double dev = 0;
  for (int j = 0; j < space.dim() * 3; ++j) {
    const double* p = w + static_cast<std::size_t>(j) * ws;
    for (std::size_t k = 1; k < ws; ++k) dev = std::max(dev, std::abs(p[k] - p[0]));
    if (dev > stop_above) return std::numeric_limits<double>::infinity();
  }
  // |w_k - w_0| rounded to nearest is within one ulp: next_up covers it (next_up of the
  // largest is the largest next_up, next_up being monotone).
  return next_up(err + next_up(dev));
}

double constant_ratio_lower(const MuSpace& space, const double* w, double delta, double* eigenvectors) {
  if (space.dim() == 2) return ratio_lower<2>(w_at<2>(space, w, 0), delta, eigenvectors);
  return ratio_lower<3>(w_at<3>(space, w, 0), delta, eigenvectors);
}

RatioBounds constant_ratio_bounds(const MuSpace& space, const double* w, double delta) {
  // M_0 and the distance of every W^T W of the box from it (corner_metric, at W_0).
  const int corner = space.w_basis().vertex_indices()[0];
  const CornerMetric cm = corner_metric(corner_w(space, w, 0), space.dim(), delta);
  const double* m = cm.m.data();
  if (space.dim() == 2) {
    const EigenEnclosure e = symmetric_eigen_enclosure<2>(m, cm.err);
    if (e.min_lo > 0 && std::isfinite(e.max_hi)) return {e.ratio_lower(), e.ratio_upper()};
  } else {
    double lo = 0, hi = 0;
    double vectors[9] = {};  // columns 0 and 2: the least and the largest eigenvalue's
    if (extreme_eigen_bounds3(m, cm.err, lo, hi) && lo > 0 && eigenvector3(m, lo, vectors) &&
        eigenvector3(m, hi, vectors + 6))
      return {std::clamp(next_down(lo / hi), 0.0, 1.0), corner_ratio_upper_at(space, w, delta, corner, vectors)};
  }
  // Not finite, or a certification failed.
  double eigenvectors[9];
  const double lower = constant_ratio_lower(space, w, delta, eigenvectors);
  return {lower, corner_ratio_upper_at(space, w, delta, corner, eigenvectors)};
}

}  // namespace quadval
