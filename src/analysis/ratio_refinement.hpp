#pragma once
// The minimum of a ratio b / c of two polynomials given in one Bézier basis, c > 0: the
// distortion J / J_straight (Paper III eq. 3) of elements whose straight-sided J is not
// constant (quadrangles, prisms, hexahedra, pyramids). Internal to src/analysis.

#include "quadval/bezier_basis.hpp"

namespace quadval {

struct RatioRefinement {
  double lower = 0;  ///< certified: lower <= min b / c over the element
  double upper = 0;  ///< certified: min b / c <= upper (a value of b / c, rounded up)
  int subdivisions = 0;
  bool tolerance_met = false;
  bool positive = true;  ///< false: c not proven positive (then lower = -inf, upper = +inf)
};

/// Refines min b / c best-first until upper - lower <= max(abs_tol, rel_tol * |upper|) or
/// max_subdivisions subdomains were split.
/// Lower bound of a subdomain: min_i b_i / c_i when every c_i > 0 (b - m c has nonnegative
/// coefficients for m <= each b_i / c_i: relaxation, Paper V §3.1), each quotient rounded
/// down with the coefficients' error bounds; upper bound: b / c at the subdomain's vertices,
/// where a Bézier coefficient is a value. Subdivision is exact and convex, so the children's
/// coefficients carry the parent's error plus basis.subdivision_rounding() * max|parent|.
/// @param b, c    basis.size() coefficients each, within err_b and err_c of the exact ones
RatioRefinement refine_ratio_minimum(const BezierBasis& basis, const double* b, double err_b,
                                     const double* c, double err_c, double abs_tol,
                                     double rel_tol, int max_subdivisions);

}  // namespace quadval
