#pragma once
// Straight-sided high-order elements (issue 3, speed). Inside a curved mesh most elements
// are straight: their high-order nodes sit where the first-order element on their vertices
// puts them (93% of tri_h0.4_o4, 90% of tets_h0.8_o2, 85% of quad_h0.4_o2). Their J is the
// first-order element's J_1 up to a certified margin m, so the first-order fast path
// (linear_jacobian.hpp) decides them with its bounds widened by m, without the Bézier
// expansion of the full J. Internal to src/analysis (check_mesh.cpp).
//
// The margin. x = x_1 + d, with x_1 the first-order map of the vertices and d the element's
// interpolant of the deviations d_i = x_i - x_1(xi_i) (zero at the vertices). With a_c and
// D_c the columns c of dx_1/dxi and dd/dxi (Gmsh reference coordinates, as J everywhere),
//   |J - J_1| = |det[a + D] - det[a]| <= prod_c (alpha_c + beta_c) - prod_c alpha_c
// (expand the determinant over the columns taken from D; Hadamard bounds each term by the
// product of its column norms), for alpha_c >= |a_c| and beta_c >= |D_c| on the element:
//  - a_c: on a simplex the edge x_c - x_0; on a quadrangle or hexahedron (on [-1, 1]) half
//    a convex combination of the edges of direction c. alpha_c: the largest 1-norm of
//    those edges (halved), which bounds the 2-norm.
//  - D_c: bounded by its Bézier coefficients, sum_i G_ki d_i with G_ki the coefficient k
//    of the derivative of node i's shape function (the product map's rows,
//    jacobian_product.hpp), so |D_cj| <= Lambda_c delta_j, Lambda_c = max_k sum_i |G_ki|
//    (the map's row sum, rounded up), delta_j >= max_i |d_ij|; beta_c = Lambda_c sum_j
//    delta_j bounds the 2-norm.
// 2D elements (planar, J with n = +z): two columns of x and y only.
//
// The deviations in doubles: d~_ij = y_ij - sum_v N_v(xi_i) y_vj with y = x - x_0 (one
// rounding each), N_v the first-order shape values at the reference node, rounded (within
// 8u of the exact ones, which lie in [0, 1]), so |d~_ij - d_ij| <= (n_v + 14) u S_j with
// S_j = max_i |y_ij| + sum_v |y_vj|; we use twice that, plus 2^-1000 for gradual
// underflow. The margin's own arithmetic (a few products and sums
// of nonnegative terms) is covered by a factor 1 + 1e-12 and a final step up.
//
// Only elements straight to 1e-9 get a margin (the rest +inf: the general path, whose
// bounds are sharper for curved elements), so the bounds reported stay those of the
// first-order element to about 1e-9 of J.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "analysis/jacobian_space.hpp"
#include "analysis/linear_jacobian.hpp"
#include "quadval/mesh.hpp"

namespace quadval {

class StraightSidedMargin {
 public:
  /// For a curved type whose vertices make a first-order kind with a fast path
  /// (triangles and quadrangles when planar, tetrahedra, hexahedra); kind() is none
  /// otherwise (lines, prisms, pyramids, order 1, non-planar 2D).
  StraightSidedMargin(const ElementType& type, const JacobianSpace& space, bool planar);

  LinearKind kind() const noexcept { return kind_; }

  /// m with |J - J_1| <= m on the whole element, or +inf when the element is not straight
  /// to 1e-9 (relative to its edges) or a coordinate is not finite; for `count` elements,
  /// read from the mesh: element e's node i at coords + 3 * conn[e * #nodes + i] (Gmsh node
  /// order), 8 elements at a time; 8 curved ones are read only up to the first node that
  /// shows all of them curved.
  /// @param out count margins
  /// @param beta optional, count x 3: each element's beta_c as margin() gives them
  void margins(const double* coords, const NodeIndex* conn, std::size_t count, double* out,
               double* beta = nullptr) const noexcept;

  /// One element: its margin as above and beta_c >= |D_c| everywhere, the distance of
  /// column c of the Jacobian matrix from the first-order element's (meaningless where the
  /// margin is +inf).
  double margin(const double* nodes, std::array<double, 3>& beta) const noexcept;

 private:
  // W elements at once; at(i, j) gives coordinate j of node i in every lane; beta (W x 3,
  // optional) receives beta_c per lane.
  template <int W, class At>
  void lane_margins(const At& at, double* out, double* beta = nullptr) const noexcept;

  // A node other than the vertices: its first-order shape values N_v != 0, v >= 1 (the
  // term of vertex 0 is 0: coordinates are taken relative to it).
  struct NodeTerms {
    int count = 0;
    std::array<int, 7> vertex{};
    std::array<double, 7> value{};
  };

  LinearKind kind_ = LinearKind::none;
  int num_nodes_ = 0, num_vertices_ = 0, dim_ = 0, axes_ = 3;
  std::vector<NodeTerms> terms_;           // nodes num_vertices .. num_nodes - 1
  std::array<double, 3> lambda_{0, 0, 0};  // Lambda_c, rounded up
  double deviation_error_ = 0;             // see straight_sided.cpp
};

/// The margin of `type` for 2D elements in a plane z = const (x, y only) and 3D elements,
/// built once per thread (for the quality measures, element by element).
const StraightSidedMargin& straight_sided_margin(const ElementType& type);

/// An element's margin and column distances (StraightSidedMargin::margin), when the caller
/// has them already: check_mesh computes them 8 elements at a time for its validity.
struct KnownMargin {
  double margin = 0;
  std::array<double, 3> beta{0, 0, 0};
};

/// straight_sided_margin(type).margin(nodes, beta), or `known`'s when given.
inline double straight_margin_of(const ElementType& type, const double* nodes, const KnownMargin* known,
                                 std::array<double, 3>& beta) {
  if (known != nullptr) {
    beta = known->beta;
    return known->margin;
  }
  return straight_sided_margin(type).margin(nodes, beta);
}

/// True when every node of the element has the z of node 0 (a 2D element in a plane
/// z = const, where the 2D margin holds).
bool in_a_z_plane(std::span<const double> nodes) noexcept;

}  // namespace quadval
