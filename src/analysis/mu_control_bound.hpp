#pragma once
// Certified bounds of R = lambda_min / lambda_max of the metric M = W^T W on a subdomain
// from the Bézier control matrices M_k of M alone (degree 2n, one product of W's control
// values), with no product of higher degree and no bisection. Internal to src/analysis;
// used by mu_metric.cpp and mu_bounds.cpp.
//
// Why it is a bound. For r >= 0, g_r(M) = lambda_min(M) - r lambda_max(M) is concave on
// symmetric matrices (lambda_min is concave, lambda_max convex: both are extrema of the
// Rayleigh quotient, linear in M). On the subdomain M(x) = sum_k B_k(x) M_k with
// B_k(x) >= 0 summing to 1 (Paper V Prop. 4 gives the M_k exactly), so by Jensen
//   g_r(M(x)) >= sum_k B_k(x) g_r(M_k) >= min_k g_r(M_k).
// With r = min_k R_lo(M_k) (R_lo a certified lower bound of lambda_min / lambda_max of
// the exact M_k, 0 unless M_k is positive definite) every g_r(M_k) >= 0, hence
// R(x) >= r on the whole subdomain. The control matrices converge to the values of M like
// h^2 under subdivision, so this bound closes the gap quadratically, as the degree-12n
// certificate of mu_metric.hpp does, at the cost of one small eigenvalue enclosure per
// control matrix.
//
// Tried and dropped: Jensen kept as a polynomial, G(x) = sum_k B_k(x) c_k with certified
// c_k <= g_r(M_k) at r = the settling target (r_target), proven G >= 0 by bisecting the
// scalar G alone (up to 8 or 16 bisections) instead of W and M. On a grid G >= 0 held for
// 64% of hex_box_N20's positive-definite roots the control bound leaves open, but once
// certified (every c_k enclosed, G's sub-box vertices checked) it settled only 34% of all
// the roots it was tried on (55% failed at a sub-box vertex where G < 0: the Jensen gap
// itself, which no bisection of G removes), and 18-29% of the curved 3D roots (warped
// tetrahedra and prisms). Cost beyond savings everywhere (per-element harness, best of 3):
// hex_box 28-32 -> 37.5 ms, warped_prism_o2 3.9 -> 4.6 ms, warped_tetrahedron_o3 9.3 ->
// 11.3 ms (root only), twice that when tried on every subdomain.
//
// Eigenvalue enclosures of one symmetric matrix known within an entrywise error e:
//   2 x 2: lambda = q +- sqrt(s^2 + t^2) in interval arithmetic (Paper V §4);
//   3 x 3: V = approximate eigenvectors (Eigen), B = V^T M V enclosed entrywise; the
//     Gershgorin discs of B bound lambda_min(B) from below and lambda_max(B) from above,
//     its diagonal (Rayleigh quotients) lambda_min(B) from above and lambda_max(B) from
//     below; Ostrowski's theorem (Horn & Johnson Thm 4.5.9) transfers them to M with
//     theta in [1 - eps, 1 + eps], eps >= |V^T V - I|_2. Every rounding is covered.

#include "analysis/lane_vector.hpp"

namespace quadval {

/// Tests and benchmarks: how mu_bounds bounds a subdomain in the calling thread:
/// 0 the degree-12n certificate of mu_metric.hpp alone, 1 the control-matrix bound alone,
/// 2 (default) the control-matrix bound, then, once an element has been split 24 times,
/// the certificate where the control bound falls short. Types without the certificate
/// (order above mu_certificate_max_order, mu_space.hpp) use 1 whatever the mode.
void mu_use_control_bound(int mode) noexcept;

/// Certified enclosure of the extreme eigenvalues of a symmetric matrix:
/// min_lo <= lambda_min <= min_hi and max_lo <= lambda_max <= max_hi.
struct EigenEnclosure {
  double min_lo, min_hi, max_lo, max_hi;
  /// Certified lower bound of lambda_min / lambda_max in [0, 1] (0 unless min_lo > 0).
  double ratio_lower() const noexcept;
  /// Certified upper bound of lambda_min / lambda_max in [0, 1] (1 when unknown).
  double ratio_upper() const noexcept;
};

/// Enclosure for the exact symmetric D x D matrix M (D = 2 or 3) with
/// |M_ij - m_ij| <= err for every entry.
/// @param m  the entries m00, m11, (m22,) m01, (m02, m12)  (3 for D = 2, 6 for D = 3)
/// @pre err >= 0, entries finite
template <int D>
EigenEnclosure symmetric_eigen_enclosure(const double* m, double err);

/// Faster certified bounds min_lo <= lambda_min and lambda_max <= max_hi of the exact
/// symmetric 3 x 3 matrix M with |M_ij - m_ij| <= err (entries as above), without
/// eigenvectors: approximate eigenvalues from the trigonometric closed form of the
/// characteristic polynomial of M - q I (Smith 1961; Paper V App. A), each polished by one
/// Newton step, then each bound certified by Sylvester's criterion on a shifted matrix
/// (M - a I, resp. b I - M, minus 3 err I for the entry errors, |E|_2 <= 3 err), its
/// leading minors evaluated in floating point with a priori error bounds.
/// @return false when a certification fails (nearly repeated or tiny eigenvalues relative
///         to rounding): use symmetric_eigen_enclosure then.
bool extreme_eigen_bounds3(const double* m, double err, double& min_lo, double& max_hi);

/// True when lambda_min >= r lambda_max is certified for every exact symmetric 2 x 2
/// matrix M with |M_ij - m_ij| <= err (entries m00, m11, m01), without square roots: the
/// test by which corner_ratio_upper (mu_metric.cpp) skips the corners certified above its
/// least bound so far (control_ratio_lower<2> encloses every matrix instead: the closed
/// form costs about what this test does).
/// @pre 0 <= r < 1
bool ratio_at_least2(const double* m, double err, double r);

/// The same for a symmetric 3 x 3 matrix (entries m00, m11, m22, m01, m02, m12), with one
/// square root (Laguerre-Samuelson bound of lambda_max, then Sylvester's criterion on
/// M - r lambda_max I); fails when eigenvalues cluster at the top. Used there too, and by
/// control_ratio_lower<3> before enclosing a matrix's eigenvalues.
/// @pre 0 <= r < 1
bool ratio_at_least3(const double* m, double err, double r);

/// A cheap estimate of the ratio lambda_min / lambda_max of a symmetric 3 x 3 matrix
/// (entries as above), not certified: it only orders matrices so that the least ratio is
/// usually met first. det M / (tr M / 3)^3: 1 for a multiple of I, at most 0 for an
/// indefinite M, -1 when tr M <= 0 or the quotient is not finite.
double ratio_estimate3(const double* m);

/// Certified lower bound of min R over a subdomain (the concavity argument above): the
/// least certified ratio over the control matrices. 2D: every matrix's closed-form
/// enclosure. 3D: a matrix whose ratio is certified to be at least the least one so far
/// without eigenvalues (Laguerre-Samuelson bound of lambda_max, then Sylvester's criterion
/// on M - r lambda_max I) skips its enclosure.
/// @param entries  D (D + 1) / 2 coefficient vectors of `size` control values each, in the
///                 order of symmetric_eigen_enclosure (m00, m11, (m22,) m01, ...)
/// @param err      per entry vector, |exact control value - computed| <= err[i]
/// @param size     control values per entry (>= 1)
/// @param enough   3D: a lower bound the caller needs no more than (its r_target); the
///                 result is at most this, and matrices the cheap test certifies at
///                 least this are not enclosed (2D encloses every matrix anyway)
template <int D>
double control_ratio_lower(const double* const* entries, const double* err, int size, double enough = 1);

/// symmetric_eigen_enclosure<2>(m_l, err_l).ratio_lower() of W matrices at once, matrix l
/// in lane l (entries m[i][l]): the scalar function's operations lane by lane, the same bits.
template <int W>
Lanes<W> enclosure_ratio_lower2_lanes(const Lanes<W>* m, Lanes<W> err);

/// symmetric_eigen_enclosure<2>(m_l, err_l).ratio_upper() of W matrices at once, matrix
/// l in lane l: the same bits lane by lane.
template <int W>
Lanes<W> enclosure_ratio_upper2_lanes(const Lanes<W>* m, Lanes<W> err);

}  // namespace quadval
