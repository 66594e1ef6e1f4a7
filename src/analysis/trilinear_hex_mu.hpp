#pragma once
// Bounds of R = lambda_min / lambda_max of W^T W (mu = sqrt R, Paper V) for a valid
// first-order hexahedron, without subdivision: the control-matrix bound of
// mu_control_bound.hpp on its 27 control matrices (lower) and Rayleigh quotients at its 8
// corners (upper), every matrix in SIMD lanes (symmetric3_lanes.hpp). Most first-order
// hexahedra of a mesh are settled by these at the root; the general path (mu_bounds.cpp)
// computed the same two bounds with a product table, one eigen solve per corner and a test
// per control matrix. Internal to src/analysis.
//
// The map. With Gmsh's node order and Bernstein indices (i, j, k) in {0, 1}^3 at the
// vertices, column x of J is a trilinear polynomial constant along its own direction,
// e.g. column 0 has control values x_(1,j,k) - x_(0,j,k) (twice J's on [-1, 1]^3; R does not
// depend on W's scale, and the ideal cube's J_i is a multiple of I). So each entry
// M_xy = w_x . w_y of the metric has degree 2 per direction, its control value at
// (a, b, c) in {0, 1, 2}^3 the mean of the products w_x(q) . w_y(q') over the vertex
// pairs with q + q' = (a, b, c) (Paper V Prop. 4). At the 8 corners, (2i, 2j, 2k), that
// value is the metric itself.
//
// Rounding. Each edge coordinate is one difference, within 2u A of the exact one (A the
// largest edge coordinate); a control value is a mean of at most 8 sums of 3 products,
// within gamma_10 of the sum of its terms' magnitudes, at most 3 A^2, plus the propagated
// edge errors 3 (2 A + delta) delta. One bound err for all entries; every final bound is
// stepped outward (symmetric3_lanes.hpp).
#include <span>

#include "analysis/vertex_metric_ratio.hpp"

namespace quadval {

/// R's bounds for the hexahedron with these 8 vertices (x, y, z each, Gmsh order), J > 0
/// proven on it by the caller. Not ok where a vertex's metric is not certified positive
/// definite or its eigenvalue step fails (a nearly degenerate element); lower is 0 where
/// another control matrix is not (a distorted element: refinement gives its halves better
/// ones).
CertifiedRatio trilinear_hex_ratio(std::span<const double> x);

struct RefinedRatio {
  CertifiedRatio ratio;  ///< not ok where a box's certification failed
  int halvings = 0;
  bool settled = false;  ///< sqrt(upper) - sqrt(lower), rounded outward, is at most abs_tol
};

/// R's bounds for the same hexahedron refined best first from `root` (its
/// trilinear_hex_ratio, ok) until mu's are within abs_tol or max_halvings were made: the
/// box of least lower bound is halved, directions x, y, z in turn (the direction of largest
/// variation instead: as many halvings on hex_box_N20). The metric's control values of a
/// half come from its parent's by de Casteljau at 1/2 (M has degree 2 along each direction;
/// the averages' rounding added to their error bound), its columns' corner values likewise
/// (for the Rayleigh quotients). Each half keeps its parent's lower bound where that is
/// higher; the upper bound is the least over every box's corners. A half's control matrices
/// are certified only down to what settles the element (the general path's r_target), most
/// by the cheap test alone. The two halves share the 4 corners of the plane between them
/// and each keeps 4 of its parent's, so a halving encloses 4 corner metrics, not 16. On
/// hex_box_N20 (2,603 of its 7,705 valid hexahedra refined, 10,448 halvings), mu on 1 thread,
/// 11-15 alternating CLI runs: 28.2 -> 24.4 ms with the shared corners, then about 10% less
/// with the metric's de Casteljau instead of its products recomputed from the columns.
/// The general path refines the same way with its own products and one eigen solve per
/// corner.
RefinedRatio refine_trilinear_hex_ratio(std::span<const double> x, CertifiedRatio root, double abs_tol,
                                        int max_halvings);

}  // namespace quadval
