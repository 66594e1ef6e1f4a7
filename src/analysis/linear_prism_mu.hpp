#pragma once
// Bounds of R = lambda_min / lambda_max of W^T W (mu = sqrt R, Paper V) for a valid
// first-order prism, without subdivision: the control-matrix bound of mu_control_bound.hpp
// on its 18 control matrices (lower) and Rayleigh quotients at its 6 vertices (upper), in
// SIMD lanes (vertex_metric_ratio.hpp). The prisms of boundary layers are first-order;
// the general path bounded them with a product table, an eigen solve per corner and a test
// per control matrix. Internal to src/analysis.
//
// The map. Gmsh's prism: nodes 0, 1, 2 on the triangle (0,0), (1,0), (0,1) at zeta = -1,
// nodes 3, 4, 5 above them at zeta = 1; x = sum_i lambda_i (xi, eta) ((1 - zeta) x_i +
// (1 + zeta) x_{i+3}) / 2. Twice its columns have the control values (vertex (i, l):
// triangle vertex i, end l of zeta)
//   2 J_1: 2 (x_1 - x_0) (l = 0), 2 (x_4 - x_3) (l = 1);   2 J_2: 2 (x_2 - x_0), 2 (x_5 - x_3);
//   2 J_3: x_{i+3} - x_i at triangle vertex i,
// each one difference (within u of it, doubling exact): J_1 and J_2 linear in zeta, J_3
// linear on the triangle. M = W^T W has degree 2 on the triangle and in zeta: 18 control
// values, each the mean over the vertex pairs summing to its multi-index (Paper V Prop. 4).
// A top triangle that is a translate of the bottom one makes W constant, bounded in closed
// form (columns_ratio, vertex_metric_ratio.hpp).
#include <array>
#include <span>

#include "analysis/vertex_metric_ratio.hpp"

namespace quadval {

/// R's bounds for the prism with these 6 nodes (x, y, z each, Gmsh order), J > 0 proven
/// on it by the caller. Not ok where a vertex's metric is not certified positive
/// definite or its eigenvalue step fails (a nearly degenerate element); lower is 0 where
/// another control matrix is not (vertex_metric_ratio.hpp).
/// @param jinv  the ideal prism's inverse Jacobian (MuSpace::ideal_inverse)
CertifiedRatio linear_prism_ratio(std::span<const double> x, const std::array<double, 9>& jinv);

}  // namespace quadval
