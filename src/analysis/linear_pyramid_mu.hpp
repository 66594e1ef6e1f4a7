#pragma once
// Bounds of R = lambda_min / lambda_max of W^T W (mu = sqrt R, Paper V) for a valid
// first-order pyramid, without subdivision: the control-matrix bound of
// mu_control_bound.hpp on its 9 control matrices (lower) and Rayleigh quotients at its 4
// base corners (upper), in SIMD lanes (symmetric3_lanes.hpp). Internal to src/analysis.
//
// The map. Gmsh's pyramid (base [-1, 1]^2, apex (0, 0, 1)) in cube coordinates
// xi = u (1 - w), eta = v (1 - w), zeta = w is x = (1 - w) f(u, v) + w x_4, with f the
// bilinear map of the base. Its columns in (xi, eta, zeta) do not depend on w:
//   J_1 = f_u(v),  J_2 = f_v(u),  J_3 = x_4 - f + u f_u + v f_v = x_4 - a + d u v,
// with f = a + b u + c v + d u v; so W = J_p J_i^-1 = J_p diag(1, 1, 1/sqrt 2) (J_i as
// mu_space.cpp scales it) is a bilinear function of (u, v) alone, and min R over the
// pyramid is min R over the square. Twice those columns have the Bernstein control values
// (vertex (i, j) of the square, base node n(i, j) = 0, 1, 3, 2 for (0,0), (1,0), (0,1), (1,1)):
//   2 J_1: x_1 - x_0 (j = 0), x_2 - x_3 (j = 1);   2 J_2: x_3 - x_0 (i = 0), x_2 - x_1 (i = 1);
//   2 J_3: (x_4 - x_1) + (x_4 - x_3) where u v = 1, (x_4 - x_0) + (x_4 - x_2) where u v = -1.
// M = W^T W has degree 2 in each of u and v: its control value at (a, b) in {0, 1, 2}^2 is
// the mean of W(q) . W(q') over the vertex pairs with q + q' = (a, b) (Paper V Prop. 4;
// vertex_metric_ratio.hpp bounds R from those); at the corners it is the metric itself.
//
// Rounding. A difference rounds once (relative u); the third column adds two of them,
// within 4u D (D the largest difference coordinate); columns_ratio (vertex_metric_ratio.hpp)
// covers the product with J_i^-1. A parallelogram base (d = 0 above) makes W constant,
// which columns_ratio bounds in closed form.
#include <array>
#include <span>

#include "analysis/vertex_metric_ratio.hpp"

namespace quadval {

/// R's bounds for the pyramid with these 5 nodes (x, y, z each, Gmsh order), J > 0 proven
/// on it by the caller. Not ok where a vertex's metric is not certified positive
/// definite or its eigenvalue step fails (a nearly degenerate element); lower is 0 where
/// another control matrix is not (vertex_metric_ratio.hpp).
/// @param jinv  the ideal pyramid's inverse Jacobian (MuSpace::ideal_inverse)
CertifiedRatio linear_pyramid_ratio(std::span<const double> x, const std::array<double, 9>& jinv);

/// The closed form of linear_pyramid_ratio for a constant W (a parallelogram base: d = 0
/// above), one pyramid per lane, x[3 n + k] node n's coordinate k (constant_columns_ratio,
/// vertex_metric_ratio.hpp): bit l of ok set where lane l's pyramid has a constant W and
/// the closed form succeeded; then linear_pyramid_ratio returns these bounds (ok where
/// lower <= upper).
StraightSimplexRatio<kNativeLanes> linear_pyramid_constant_ratio(const Lanes<kNativeLanes>* x,
                                                                 const std::array<double, 9>& jinv);

struct QualityBounds;
struct ElementType;

/// mu of kNativeLanes valid first-order pyramids of `type` (x as above), each as
/// mu_bounds_given computes it (bit-identical) where bit l of the result is set; the other
/// lanes need mu_bounds_given (W not constant, a failed step, bounds wider than tol).
/// Nothing while mu_use_constant_path(false). Defined in mu_bounds.cpp.
unsigned linear_pyramid_mu_lanes(const ElementType& type, const Lanes<kNativeLanes>* x, double tol,
                                 QualityBounds* out);

}  // namespace quadval
