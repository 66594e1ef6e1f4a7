#pragma once
// Closed-form bounds of the scaled Jacobian (scaled_jacobian.hpp) and of mu (mu_bounds.hpp)
// of a valid quadrangle in a plane z = const whose geometry is bilinear: order 1, or a
// higher order whose nodes lie where the bilinear map of its vertices puts them, up to the
// straight_sided.hpp margin. Most quadrangles of a curved quad mesh are such (the interior
// ones); the general paths bounded them with products of twice the degree (sj) or control
// matrices (mu). Internal to src/analysis.
//
// Both minima are at a corner. On Gmsh's [-1, 1]^2 the bilinear map's columns are
//   c_1(eta) = ((1 - eta) e_0 + (1 + eta) e_1) / 4,  e_0 = x_1 - x_0, e_1 = x_2 - x_3,
//   c_2(xi)  = ((1 - xi) f_0 + (1 + xi) f_1) / 4,    f_0 = x_3 - x_0, f_1 = x_2 - x_1,
// and J_1 = c_1 x c_2 is bilinear, so J_1 > 0 at the four corners makes it positive
// everywhere.
//  - sj: c_1 runs along a segment that misses the origin (J_1 > 0), so its direction angle
//    phi_1(eta) is monotone, and likewise phi_2(xi). The angle theta = phi_2 - phi_1
//    between the columns is a sum of monotone functions of separate variables, so its
//    extremes over the square are at corners, and it stays in (0, pi); sj_1 = sin theta is
//    concave there, so its minimum is the least corner value (a x b) / (|a| |b|) for the
//    corner's two edges a, b.
//  - mu: the ideal quadrangle's J_i is a multiple of I, so mu = sigma_min / sigma_max of
//    [c_1 c_2] =: r, and r + 1/r = g := (|c_1|^2 + |c_2|^2) / J_1, decreasing in r. On a
//    line eta = const, |c_1|^2 is constant and |c_2(xi)|^2 convex while J_1 is affine and
//    positive, so {g <= t} = {|c_1|^2 + |c_2|^2 - t J_1 <= 0} is an interval: g is
//    quasi-convex and takes its maximum at an end. The same holds along xi = const, so the
//    maximum of g, the minimum of mu, is at a corner.
//
// The nodes off the bilinear map. With |c_j - c_j,1| <= beta_j and |J - J_1| <= m on the
// element (StraightSidedMargin::margin, in the same reference scale) and J_lo > m the least
// corner value of J_1:
//  - sj >= (J_1 - m) / ((|c_1,1| + beta_1)(|c_2,1| + beta_2))
//       >= S (1 - m / J_lo) / ((1 + beta_1 / a_lo)(1 + beta_2 / b_lo)),
//    S the least corner value, a_lo = J_lo / b_max <= |c_1,1| (as J_1 <= |c_1,1| |c_2,1|),
//    b_max the larger end of c_2's segment (a norm is convex), b_lo alike; at the corner of
//    least value sj <= (J_1 + m) / ((|c_1,1| - beta_1)(|c_2,1| - beta_2)).
//  - mu: the singular values move by at most eps = |(beta_1, beta_2)| (Weyl, |E|_2 <= |E|_F),
//    so mu >= (sigma_min,1 - eps) / (sigma_max,1 + eps) >= (R s - eps) / (s + eps), R the
//    least corner value and s = sqrt(J_lo) <= sigma_max,1 (the bound increases with
//    sigma_max,1); at the corner of least value mu <= (sigma_min,1 + eps) / (sigma_max,1 - eps).
// Rounding: an edge's coordinates are one difference each (relative u), a corner's cross
// product is within 8u (|a_x b_y| + |a_y b_x|) + 2^-1000 (gradual underflow) of the exact
// one, norms (kept within [2^-400, 2^400]) and squared norms within 1e-12 relative; every
// later step is rounded outward.

#include <optional>
#include <span>

#include "analysis/lane_vector.hpp"
#include "analysis/straight_sided.hpp"
#include "quadval/element_type.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// Bounds of sj(E) as above, for a quadrangle (any order) in a plane z = const, J taken
/// along +z. Nothing when the element is not such, its first-order J is not proven positive
/// at the corners, its nodes are off the bilinear map by more than the straight-sided
/// margin allows, or upper - lower > tol.
/// @param known the element's margin (straight_sided.hpp), when the caller has it
std::optional<QualityBounds> bilinear_quad_sj_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known = nullptr);

/// The same for mu(E).
std::optional<QualityBounds> bilinear_quad_mu_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known = nullptr);

/// The same bounds of kNativeLanes quadrangles at once, bit for bit those of the functions
/// above (the same operations lane by lane): xy[2 k], xy[2 k + 1] the x and y of vertex k,
/// beta[0], beta[1] and margin the element's straight-sided margins (as KnownMargin's; 0 at
/// order 1). Bit l of the result is set where out[l] holds lane l's bounds; the function
/// above gives the others nothing (they need the general path). The callers' switches
/// (mu_use_constant_path, scaled_jacobian_use_straight_path) are theirs to check.
unsigned bilinear_quad_sj_lanes(const Lanes<kNativeLanes>* xy, const Lanes<kNativeLanes>* beta,
                                Lanes<kNativeLanes> margin, double tol, QualityBounds* out);
unsigned bilinear_quad_mu_lanes(const Lanes<kNativeLanes>* xy, const Lanes<kNativeLanes>* beta,
                                Lanes<kNativeLanes> margin, double tol, QualityBounds* out);

}  // namespace quadval
