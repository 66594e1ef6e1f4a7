#pragma once
// Exact shape functions of Bergot's pyramids (Paper IV eqs. 1-2) and the exact control
// points of their derivatives in the cube coordinates of bezier/pyramid_basis.hpp, from
// which JacobianProduct (jacobian_product.hpp, init_pyramid in pyramid_space.cpp) forms
// the Bézier coefficients of J in the enriched basis (eq. 6) by Bernstein products.
// Internal to src/analysis.
#include <gmpxx.h>

#include <array>
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval {

/// Shape functions of one pyramid type in the monomial basis of Bergot's space:
/// N_i = sum_j phi_j coefficients[j * #nodes + i], phi_j = X^a Y^b t^k for
/// exponents[j] = (a, b, k), a, b <= k (X = 2u - 1, Y = 2v - 1, t = 1 - zeta).
struct PyramidShapeCoefficients {
  std::vector<std::array<int, 3>> exponents;
  std::vector<mpq_class> coefficients;
};

/// Exact coefficients, from the inverse of the generalized Vandermonde matrix at the
/// type's reference nodes (Gmsh order). @pre type is a Lagrange pyramid
PyramidShapeCoefficients pyramid_shape_coefficients(const ElementType& type);

/// Degrees in (u, v, t) of the derivative of an order-r map along Gmsh direction c
/// (0 xi, 1 eta, 2 zeta): (r-1, r, r-1), (r, r-1, r-1), (r, r, r-1).
std::array<int, 3> pyramid_derivative_degrees(int r, int c) noexcept;

/// Scaled Bernstein coefficients (C(n0,i0) C(n1,i1) C(n2,i2) times the Bézier control
/// value, index i0 + (n0+1) (i1 + (n1+1) i2)) of the derivative along direction c of the
/// function sum_j monomial[j] phi_j, in the degrees of pyramid_derivative_degrees(r, c).
/// Derivatives in Gmsh coordinates: d/dxi (X^a Y^b t^k) = a X^(a-1) Y^b t^(k-1),
/// d/deta likewise, d/dzeta = (a + b - k) X^a Y^b t^(k-1).
/// @pre every exponent (a, b, k) has a, b <= k <= r
std::vector<mpq_class> pyramid_scaled_derivative(int r, int c,
                                                 const std::vector<std::array<int, 3>>& exponents,
                                                 const std::vector<mpq_class>& monomial);

}  // namespace quadval
