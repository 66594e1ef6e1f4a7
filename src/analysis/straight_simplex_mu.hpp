#pragma once
// Bounds of R = lambda_min / lambda_max of W^T W (mu = sqrt R, Paper V) for valid
// straight-sided tetrahedra and planar triangles, several elements at once in SIMD lanes:
// the closed form of mu_constant.hpp (W constant within delta of W_0 = [edges] Jinv), lane
// by lane. Each lane computes exactly what the element computes alone (lane_vector.hpp), so
// the check's first-order chunks (kNativeLanes elements at a time) and mu_bounds (one
// element, in two lanes) give bit-identical bounds. Internal to src/analysis.
//
// Triangles (in a plane z = const), as constant_ratio_bounds's 2D branch: M_0 = W_0^T W_0
// (2 x 2) with the same error bound, and its eigenvalues q +- sqrt(s^2 + t^2) enclosed in
// interval arithmetic (symmetric_eigen_enclosure<2>).
//
// Tetrahedra, per lane, as constant_ratio_bounds: M_0 = W_0^T W_0 with the entrywise
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
struct StraightSimplexRatio {
  Lanes<W> lower, upper;  ///< lower <= R <= upper on the element, where ok
  unsigned ok = 0;        ///< bit l: lane l's bounds hold (else: use the general path)
};

/// a[3 c + j]: coordinate j of edge c (x_{c+1} - x_0) per lane; beta[c]: the straight-sided
/// margin of column c (0 for first-order elements); jinv: the ideal element's inverse
/// Jacobian (MuSpace::ideal_inverse, row-major c * 3 + j).
template <int W>
StraightSimplexRatio<W> straight_tet_ratio(const Lanes<W>* a, const Lanes<W>* beta, const std::array<double, 9>& jinv);

/// The same for triangles in a plane z = const: a[3 c + j] for edges c = 0, 1 (their z
/// differences +0), beta[0], beta[1].
template <int W>
StraightSimplexRatio<W> straight_triangle_ratio(const Lanes<W>* a, const Lanes<W>* beta,
                                                const std::array<double, 9>& jinv);

extern template StraightSimplexRatio<2> straight_tet_ratio<2>(const Lanes<2>*, const Lanes<2>*, const std::array<double, 9>&);
extern template StraightSimplexRatio<kNativeLanes> straight_tet_ratio<kNativeLanes>(const Lanes<kNativeLanes>*,
                                                                                const Lanes<kNativeLanes>*,
                                                                                const std::array<double, 9>&);
extern template StraightSimplexRatio<2> straight_triangle_ratio<2>(const Lanes<2>*, const Lanes<2>*,
                                                                   const std::array<double, 9>&);
extern template StraightSimplexRatio<kNativeLanes> straight_triangle_ratio<kNativeLanes>(
    const Lanes<kNativeLanes>*, const Lanes<kNativeLanes>*, const std::array<double, 9>&);

struct QualityBounds;
struct ElementType;

/// mu of kNativeLanes valid straight-sided tetrahedra, or triangles in a plane z = const, of
/// `type` (lanes; edges and margins as straight_tet_ratio's and straight_triangle_ratio's:
/// the straight-sided margins mu_bounds_given gets, or 0 for first order), each as
/// mu_bounds_given computes it (bit-identical): bit l of the result is set where out[l]
/// holds lane l's bounds; the other lanes need mu_bounds_given (a failed step, or bounds
/// wider than tol). Nothing while mu_use_constant_path(false).
unsigned straight_simplex_mu_lanes(const ElementType& type, const Lanes<kNativeLanes>* edges,
                                   const Lanes<kNativeLanes>* margins, double tol, QualityBounds* out);

}  // namespace quadval
