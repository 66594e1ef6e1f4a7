#pragma once
// The first stage of the scaled-Jacobian bounds (scaled_jacobian.hpp) on a valid element:
// sj from J and the frame columns alone, before the products of twice the degree.
//
// Where J > 0 on the element and |V_k| = J (3D, planar 2D, 1D), sj = min_k s J / prod_j
// |v_kj|. On a subdomain, J >= J_lo (its least Bézier coefficient) and |v_kj| <= the largest
// norm of its control points (the convex hull property; the norm is convex), so
//   sj >= min_k s J_lo / prod_j max_i |V_kj,i|;
// at a corner of a subdomain the coefficients are values, so sj there bounds sj(E) from
// above. The bound is exact where J and the columns are constant (straight-sided simplices,
// parallelograms, parallelepipeds), and its gap shrinks linearly with the subdomain: J and
// the columns (degree n, far smaller than the degree 2n of N and D_k) are split best-first
// by bisection, a few times at most, which settles most curved elements of real meshes.
// In 3D and planar 2D the stage also pairs J with an upper bound of the norms' product at each
// coefficient (paired_bound in the .cpp: |v| <= v . d + Q with d the mean direction of the
// column's control points and Q of the order of their spread squared), whose gap shrinks
// quadratically: it settles all 1,290 valid curved pyramids of warped_pyramid_o2 within 8
// single bisections, where the linear bound settled 163 and the others went to the
// products of (6r + 1)^3 coefficients.
// Internal to src/analysis.
//
// Tried and dropped: the same stage on elements not proven valid, with sj_k >= s J_lo /
// prod_j (lower bound of |v_kj|) where J_lo < 0 (the norm bounded below along the mean
// direction of its control points) and negative corner values as upper bounds. J_lo and the
// norms' bounds are taken at different points, so where J and the norms vary together the
// gap closes slowly: warped_prism_o2_N6_a0.25 needed 55 splits per invalid element where
// the full bounds' ratios of N and D_k need 3, and within the 4 splits used here it settled
// none of the invalid elements of the warped meshes (sj time unchanged or worse).
// What works there instead (signed_quotient_bounds): the ratios J_i / L_k,i coefficient by
// coefficient in J's space, L_k = prod_j (v_kj . d_kj) with d_kj the mean direction of the
// column's control points, so that J and the denominator are paired at the same point; it
// settles all invalid elements of warped_hexahedron_o2 and warped_prism_o2 and 540 of the
// 660 of warped_tetrahedron_o3 within 8 splits (single bisections, as the full bounds);
// used for every 3D family and for planar 2D elements (scaled_jacobian.cpp).
// Also tried there: d_kj toward the point of the control points' hull nearest to the
// origin (Gilbert's algorithm) where the mean direction leaves a projection <= 0. On the
// slow quadratic tetrahedra of mixed_h0.6_o2 (a column passing 0.004 from zero beside a
// 0.011 edge) it makes L_k positive, but the projections are then that small and the
// ratios fall below the Hadamard floor: nothing settled, sj time unchanged.
//
// Errors: every coefficient carries an a priori bound (its input's, plus the bisection's
// rounding_relative() * max|parent| + rounding_absolute() per split); a frame column is a
// sum of at most 3 columns with weights +-1, so each of its coordinates is within
// e = sum (e_c + gamma_6 m_c) of the exact one, which moves a control point's norm by at
// most sqrt(3) e; the norms' own rounding (a few ulps) is covered by a relative 1e-12, and
// every bound is rounded outward.

#include <array>
#include <span>
#include <vector>

#include "analysis/lane_vector.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// J and the columns of one element in their own Bézier spaces, with their bounds.
struct QuotientInput {
  std::span<const double> j;                 ///< J's coefficients
  const std::vector<FactorDegree>* j_degrees = nullptr;
  double j_error = 0;                        ///< |computed - exact| per coefficient
  /// Column c (c < dim), coordinate x: its coefficients.
  std::array<std::array<std::span<const double>, 3>, 3> col{};
  std::array<const std::vector<FactorDegree>*, 3> col_degrees{};
  std::array<double, 3> col_error{0, 0, 0};  ///< per column, every coordinate
  std::array<double, 3> col_magnitude{0, 0, 0};  ///< >= |every computed coefficient|
  /// Coordinates that can be nonzero: 2 where every column's z coefficients are zero (an
  /// element in a plane z = const), else 3.
  std::size_t coordinates = 3;
};

/// Per frame k of the space (at most 4): a certified lower bound of the frame's own
/// pointwise value sj_k (scaled_jacobian.hpp) over the whole element; sj = min_k sj_k.
using FrameBounds = std::array<double, 4>;

/// Certified bounds of sj(E) on an element where J > 0 is proven, refined best-first until
/// upper - lower <= tol: in 3D and planar 2D with paired_bound (scaled_jacobian_quotient.cpp)
/// by at most max_paired_splits splits, otherwise (lines) by at most max_splits. lower = -inf when the root's
/// least J coefficient is not positive (then nothing is refined); subdivisions counts the
/// splits; tolerance_met says whether the gap closed. frame_lower, where given, receives
/// each frame's lower bound (the least over the final leaves of the frame's bound there;
/// -inf where nothing was bounded), for the full bounds to leave out the frames already
/// within the tolerance.
QualityBounds quotient_bounds(const ScaledJacobianSpace& space, const QuotientInput& in, double tol,
                              int max_splits, int max_paired_splits, FrameBounds* frame_lower = nullptr);

/// J and the columns of four planar 2D elements of one space, element l in lane l of every
/// vector: what QuotientInput holds of each, with coordinates = 2 (x and y).
struct QuotientLanes {
  std::span<const Lanes<4>> j;                                  ///< J's coefficients
  const std::vector<FactorDegree>* j_degrees = nullptr;
  Lanes<4> j_error{};                                           ///< |computed - exact| per coefficient
  std::array<std::array<std::span<const Lanes<4>>, 2>, 2> col;  ///< column c, coordinate x: its coefficients
  std::array<const std::vector<FactorDegree>*, 2> col_degrees{};
  std::array<Lanes<4>, 2> col_error{};      ///< per column, both coordinates
  std::array<Lanes<4>, 2> col_magnitude{};  ///< >= |every computed coefficient|
};

/// quotient_bounds of four planar 2D elements of one space at once, in SIMD lanes, as far
/// as their roots: returns bit l where lane l's first stage meets the tolerance at the
/// root, with out[l] then exactly what quotient_bounds(space, that element's QuotientInput,
/// tol, any, any) returns (no subdivision); the other lanes' elements need quotient_bounds.
/// 0 wherever the lanes do not apply (other dimensions, a product without an entry kernel,
/// the tests' switch).
unsigned paired_quotient_roots(const ScaledJacobianSpace& space, const QuotientLanes& in, double tol,
                               std::array<QualityBounds, 4>& out);

/// The same on an element where J <= 0 was found at a point (so sj(E) <= 0), in 3D or
/// planar 2D, with the bound of signed_bound (scaled_jacobian_quotient.cpp) that keeps J's
/// signs: refined by at most max_splits best-first splits, from `upper` (a certified upper
/// bound of sj(E), at most 0). Nothing (lower = -inf, upper) where J does not lie in the
/// space of the product of the columns (none of the 2D and 3D types). floor_root_ends: no
/// split where the root's bound is at the Hadamard floor -s (a frame column turning
/// through a fold on the element), for the families where the full bounds (tetrahedra) or
/// the probe (planar triangles) settle such elements for less than these splits cost
/// (scaled_jacobian.cpp).
QualityBounds signed_quotient_bounds(const ScaledJacobianSpace& space, const QuotientInput& in, double tol,
                                     int max_splits, double upper = 0, FrameBounds* frame_lower = nullptr,
                                     bool floor_root_ends = false);

}  // namespace quadval
