#pragma once
// Exact gradients of the Lagrange shape functions of a pyramid (Bergot's space, Paper IV
// eqs. 1-2) at the sampling points of its Jacobian Bézier space (bezier/pyramid_basis.hpp).
// Internal to src/analysis; JacobianSpace::init_pyramid (pyramid_space.cpp) uses it.
#include <gmpxx.h>

#include <vector>

#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"

namespace quadval {

/// out[c][k * #nodes + i] = dN_i/dx_c (Gmsh coordinates xi, eta, zeta) at sample k of
/// `basis`, exactly. Sample k is the cube point (u, v, t) of the basis' factors
/// (t = 1, i.e. zeta = 0, when the basis has two factors).
///
/// Written in cube coordinates, with phi = X^a Y^b t^k (X = 2u-1, Y = 2v-1, a, b <= k):
///   dphi/dxi = a X^(a-1) Y^b t^(k-1),  dphi/deta = b X^a Y^(b-1) t^(k-1),
///   dphi/dzeta = (a + b - k) X^a Y^b t^(k-1)   (all zero for k = 0),
/// polynomials in (X, Y, t): on the face t = 0 they are the limits of the gradient along
/// the rays to the apex, never a value taken at the apex itself.
/// @pre type is a pyramid with has_lagrange_basis; its nodes on the 1/order lattice
void exact_pyramid_gradients(const ElementType& type, const BezierBasis& basis,
                             std::vector<mpq_class> (&out)[3]);

}  // namespace quadval
