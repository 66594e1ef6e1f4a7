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
// zeta = 0), as Paper IV §4.1 prescribes.
//
// The generalized basis of eq. (4) (B_i^(k+2)(u) B_j^(k+2)(v) B_k^(3r-3)(t)) spans the same
// J; by degree elevation each enriched coefficient is a convex combination of generalized
// ones, so the enriched coefficients bound J at least as sharply. quadval therefore
// computes the enriched coefficients directly (pyramid_generalized_size documents the
// smaller dimension of eq. 4 for comparison), as Bernstein products of the derivatives
// (src/analysis/pyramid_space.cpp).
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
