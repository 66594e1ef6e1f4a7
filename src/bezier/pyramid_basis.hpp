#pragma once
// The Bézier space of the Jacobian determinant of Bergot's order-r pyramid (thesis,
// Paper IV §3-4), seen as a polynomial on the "shrunk cube" (Paper IV Fig. 2).
//
// Cube coordinates (u, v, t) in [0, 1]^3 of a point of Gmsh's reference pyramid (base
// [-1, 1]^2 at zeta = 0, apex (0, 0, 1)):
//   t = 1 - zeta,  u = (xi / t + 1) / 2,  v = (eta / t + 1) / 2,
// i.e. the thesis' xi/(1-zeta), eta/(1-zeta), 1-zeta after the affine map [-1,1] -> [0,1]
// of Gmsh's base. By eq. (3), J is a polynomial of degree <= 3r-1 in u and in v and
// <= 3r-3 in t (the exponents I, J <= K+2 <= 3r-1). Its tensor Bernstein basis is the
// enriched basis of eq. (6); it subdivides like a hexahedron's (8 children in (u, v, t)).
// For r = 1, J does not depend on t: two factors (a quadrangle in (u, v), sampled on
// zeta = 0), as Paper IV §4.1 prescribes. (It is in fact bilinear in (u, v), its minimum a
// corner value: check's first-order fast path uses that, analysis/linear_jacobian.hpp;
// the degree-(2, 2) coefficients here are those corner values degree-elevated.)
//
// The generalized basis of eq. (4) (B_i^(k+2)(u) B_j^(k+2)(v) B_k^(3r-3)(t)) spans the same J (J =
// sum_k B_k(t) P_k(u, v) with deg P_k <= k+2). Both bases share the t factor, so the enriched slice
// k is the generalized slice k degree-elevated from k+2 to 3r-1: each enriched coefficient is a
// convex combination of generalized ones of its slice, corners equal, and the slice k = 3r-3 (the
// base face) is not elevated at all. Hence at level 0 the enriched min is >= the generalized min
// and eq. 4 never settles a sign eq. 6 leaves open. Measured once in exact rationals on the 1,296
// order-2 pyramids of ../shared/data and on 20 random pyramids each of orders 2 and 3: the two
// minima were equal on every element, the same elements decided;
// tests/analysis/pyramid_jacobian_test.cpp (GeneralizedBasisOfEq4*) asserts the inequality on the
// random order-2 ones. Its only possible gain would be speed (86 vs 144 coefficients at r = 2, 280
// vs 567 at r = 3), but it is not a tensor space: no Bernstein products and no subdivision, only a
// sample-based Lagrange-to-Bézier matrix (at r = 2 about 86 x 14 x 9 products for the samples plus
// 86^2 for the transform, ~3x the product path's work, and a rounding bound scaled by that matrix's
// norm). So quadval computes only the enriched coefficients, as Bernstein products of the
// derivatives (src/analysis/pyramid_space.cpp); pyramid_generalized_size documents eq. 4's
// dimension for comparison.
#include <array>
#include <vector>

#include "quadval/bezier_basis.hpp"

namespace quadval {

/// Highest pyramid order with a Jacobian basis: every order Gmsh defines (ids 118-131).
/// The coefficients come from Bernstein products of the derivatives' control points
/// (src/analysis/pyramid_space.cpp), never from the equispaced Lagrange-to-Bézier matrix
/// of the J space, whose conditioning (factor degree 3r-1 up to 26) would limit r to 4.
inline constexpr int kPyramidMaxOrder = 9;

/// Line factors of the enriched basis (eq. 6) of the order-r pyramid: (3r-1, 3r-1, 3r-3)
/// for r >= 2, (2, 2) for r = 1. @pre r >= 1
std::vector<FactorDegree> pyramid_jacobian_factor_degrees(int r);

/// Dimension of the generalized basis of eq. (4): sum_{k=0}^{3r-3} (k+3)^2
/// = r/2 (3r+1)(6r+1) - 5 (Paper IV §3); 9 for r = 1 (the quadrangle case).
int pyramid_generalized_size(int r) noexcept;

/// Gmsh reference coordinates (xi, eta, zeta) of the cube point (u, v, t).
std::array<double, 3> pyramid_cube_to_gmsh(double u, double v, double t) noexcept;

/// Cube coordinates (u, v, t) of a Gmsh reference point. @pre zeta < 1
std::array<double, 3> pyramid_gmsh_to_cube(double xi, double eta, double zeta) noexcept;

}  // namespace quadval
