#pragma once
// Bounds of R = lambda_min / lambda_max of W^T W (mu = sqrt R, Paper V) for valid
// straight-sided tetrahedra, several elements at once in SIMD lanes: the closed form of
// mu_constant.hpp (W constant within delta of W_0 = [edges] Jinv), lane by lane. Each lane
// computes exactly what the element computes alone (lane_vector.hpp), so the check's
// first-order chunks (8 tetrahedra a time) and mu_bounds (one element, in two lanes) give
// bit-identical bounds. Internal to src/analysis.
//
// Per lane, as mu_constant.cpp's constant_ratio_bounds: M_0 = W_0^T W_0 with the entrywise
// error bound err of every W^T W in the box (corner_metric); lambda_min >= a and
// lambda_max <= b certified by Sylvester's criterion on M_0 - a' I and b' I - M_0 (a, b the
// trigonometric closed form, polished, widened by a margin and 3 err: extreme_eigen_bounds3);
// the upper bound from Rayleigh quotients of W with the eigenvectors of a and b (the largest
// cross product of two rows of M_0 - lambda I), their errors enclosed (corner_upper).
// Where any step fails (a certification, a non-finite value, a nearly repeated eigenvalue)
// the lane says so and the caller takes the general path.
#include <array>

#include "analysis/lane_vector.hpp"

namespace quadval {

template <int W>
struct StraightTetRatio {
  Lanes<W> lower, upper;  ///< lower <= R <= upper on the element, where ok
  unsigned ok = 0;        ///< bit l: lane l's bounds hold (else: use the general path)
};

/// a[3 c + j]: coordinate j of edge c (x_{c+1} - x_0) per lane; beta[c]: the straight-sided
/// margin of column c (0 for first-order elements); jinv: the ideal element's inverse
/// Jacobian (MuSpace::ideal_inverse, row-major c * 3 + j).
template <int W>
StraightTetRatio<W> straight_tet_ratio(const Lanes<W>* a, const Lanes<W>* beta, const std::array<double, 9>& jinv);

extern template StraightTetRatio<2> straight_tet_ratio<2>(const Lanes<2>*, const Lanes<2>*, const std::array<double, 9>&);
extern template StraightTetRatio<kNativeLanes> straight_tet_ratio<kNativeLanes>(const Lanes<kNativeLanes>*,
                                                                                const Lanes<kNativeLanes>*,
                                                                                const std::array<double, 9>&);

struct QualityBounds;
struct ElementType;

/// mu of kNativeLanes valid straight-sided tetrahedra of `type` (lanes; edges and margins as
/// straight_tet_ratio's: the straight-sided margins mu_bounds_given gets, or 0 for first
/// order), each as mu_bounds_given computes it (bit-identical): bit l of the result is set
/// where out[l] holds lane l's bounds; the other lanes need mu_bounds_given (a failed step,
/// or bounds wider than tol). Nothing while mu_use_constant_path(false).
unsigned straight_tet_mu_lanes(const ElementType& type, const Lanes<kNativeLanes>* edges,
                               const Lanes<kNativeLanes>* margins, double tol, QualityBounds* out);

}  // namespace quadval
