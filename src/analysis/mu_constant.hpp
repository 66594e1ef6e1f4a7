#pragma once
// Closed-form bounds of mu for elements whose W = J_p J_i^-1 is constant (straight-sided
// simplices, parallelograms, parallelepipeds, right prisms on a straight triangle):
// every control value of W is W itself, so R = lambda_min / lambda_max of one 2x2 or 3x3
// metric, bounded directly instead of by Bernstein products and bisection (mu_metric.hpp).
// Internal to src/analysis; used by mu_bounds.cpp.
#include <limits>

#include "analysis/mu_space.hpp"

namespace quadval {

/// Tests only: switch the constant-W path of mu_bounds off (on by default) in the calling
/// thread, with the closed forms of straight simplices and bilinear quadrangles
/// (bilinear_quad_quality.hpp), to compare them with the general path.
void mu_use_constant_path(bool on) noexcept;
bool mu_constant_path_enabled() noexcept;

/// A radius delta such that every exact control value of W lies within delta of the
/// first one (entrywise): err + max_k |w_k - w_0|, rounded up. Then W(x), a convex
/// combination of its control values, lies within delta of W_0 everywhere.
/// @param w, err  as MuMetric::lower_bound
/// @param stop_above  +inf instead as soon as max_k |w_k - w_0| exceeds this (a caller that
///                    only uses small radii: most curved elements stop at W's first entry)
double constant_w_radius(const MuSpace& space, const double* w, double err,
                         double stop_above = std::numeric_limits<double>::infinity());

/// Certified lower bound of min R = lambda_min(W^T W) / lambda_max(W^T W) over every
/// 3 x dim matrix W with |W - W_0| <= delta entrywise; 0 when none can be certified.
/// W_0 is the first control value of `w` (layout of MuMetric::lower_bound).
/// Method: V = approximate eigenvectors of W_0^T W_0 (Eigen); Y = W V is enclosed
/// entrywise (y +- r), so B = Y^T Y = V^T M V lies in an interval matrix whose Gershgorin
/// discs bound lambda_min(B) from below and lambda_max(B) from above; V is not exactly
/// orthogonal, so by Ostrowski's theorem (Horn & Johnson, Thm 4.5.9)
/// lambda_k(B) = theta_k lambda_k(M), theta_k in [1 - eps, 1 + eps] with eps a Gershgorin
/// bound of |V^T V - I|: lambda_min(M) >= lambda_min(B) / (1 + eps) and
/// lambda_max(M) <= lambda_max(B) / (1 - eps). Every operation's rounding is covered
/// (outward rounding and gamma_k margins).
/// @param eigenvectors  optional out: the approximate eigenvectors V used (dim x dim,
///                      column-major, eigenvalues ascending), for the corners' upper bound
double constant_ratio_lower(const MuSpace& space, const double* w, double delta, double* eigenvectors = nullptr);

/// Certified bounds lower <= R(W) <= upper for every W of the same box, without Eigen's
/// trigonometric eigen solve: the entries of M_0 = W_0^T W_0 are enclosed for the whole box
/// (corner_metric of mu_metric.hpp); 2D: the closed-form
/// enclosure of a 2 x 2 matrix; 3D: extreme_eigen_bounds3 (mu_control_bound.hpp) for the
/// lower bound, and for the upper the Rayleigh quotients (corner_ratio_upper_at) of
/// eigenvectors taken as cross products of rows of M_0 - lambda I. Where these fail
/// (nearly repeated or tiny eigenvalues): constant_ratio_lower and its eigenvectors.
/// Per element (random constant W, fastest of 20 passes over 4,096): triangles 214 -> 65 ns,
/// tetrahedra 456 -> 320 ns; mu on tets_h0.8_o2 (90% straight) about 10% faster.
struct RatioBounds {
  double lower, upper;
};
RatioBounds constant_ratio_bounds(const MuSpace& space, const double* w, double delta);

}  // namespace quadval
