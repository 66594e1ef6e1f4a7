#pragma once
// The first stage of the scaled-Jacobian bounds (scaled_jacobian_quotient.hpp: sj >= min_k
// s J_lo / prod_j max |V_kj|, corner values above) for a first-order pyramid, by fixed-size
// formulas instead of the general path's maps and products. Internal to src/analysis.
//
// In the cube coordinates (u, v, t) of mu_bounds.hpp (xi = u (1 - t), eta = v (1 - t),
// zeta = t) the first-order pyramid is x = (1 - t) B(u, v) + t x_4, B the bilinear map of
// the base, so the columns of J_p (Gmsh's reference coordinates) are
//   c_xi = B_u (linear in v: (x_1 - x_0) / 2 at v = -1, (x_2 - x_3) / 2 at v = 1),
//   c_eta = B_v (linear in u: (x_3 - x_0) / 2 at u = -1, (x_2 - x_1) / 2 at u = 1),
//   c_zeta = x_4 - B + u B_u + v B_v = x_4 - b_0 + b_3 u v (b_0 the base's centre,
//            b_3 = (x_0 - x_1 + x_2 - x_3) / 4),
// none depending on t: J (degree 2 in u and v, 9 coefficients: convex combinations of the
// 16 determinants of one control point of each column, weights 1, 1/2, 1/4: exact) and the
// frame columns (bilinear: their control points are their values at the four corners
// (u, v) = (+-1, +-1), the base vertices) are functions of (u, v) alone. The corners are
// points of the element, so sj there bounds sj(E) from above.
//
// Rounding: coordinates are taken relative to x_0 (one difference each, relative u); every
// control point's coordinate is then within e = 4u L of the exact one, L the sum of the
// 1-norms of the four offsets (each coordinate of a control point is at most L); a frame
// column's (a sum of at most three) within 4.5e, its norm within 16e (sqrt 3 of that, and
// its own rounding, 2u of at most 3 sqrt(3) L); a determinant of control points a, b, c
// within 16u T (T the sum of its triple products' magnitudes) + 2e' (|a||b| + |b||c| +
// |c||a|) + 2e'^2 (|a| + |b| + |c|) + 4e'^3, e' = 3e bounding a vector's error (1-norms
// throughout); J within that plus gamma_4 of its terms and 2^-1000 (gradual underflow). A norm is used only where it is at
// least twice its error, so the differences below lose at most 2u relative; positive
// quantities are then combined in plain arithmetic (fewer than 20 roundings) and widened
// once by 1e-11 relative.

#include <optional>
#include <span>

#include "analysis/lane_vector.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// Certified bounds of sj(E) for a first-order pyramid (5 nodes, Gmsh order) proven valid,
/// as above; nothing when J's least coefficient is not proven positive, a frame column may
/// vanish at a corner, the coordinates are out of [2^-200, 2^200] in scale, or upper - lower
/// > tol (then the general path).
/// @param space the pyramid's ScaledJacobianSpace (its frames and s)
std::optional<QualityBounds> linear_pyramid_sj_bounds(const ScaledJacobianSpace& space, std::span<const double> x,
                                                      double tol);

/// The same for kNativeLanes pyramids, one per lane (x[3 n + k]: node n's coordinate k),
/// each with the bits linear_pyramid_sj_bounds gives it alone (the same lane code, its
/// element in both lanes of two): bit l of the result set where out[l] holds lane l's
/// bounds, the others as nothing above.
unsigned linear_pyramid_sj_lanes(const ScaledJacobianSpace& space, const Lanes<kNativeLanes>* x, double tol,
                                 QualityBounds* out);

}  // namespace quadval
