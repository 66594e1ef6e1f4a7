#pragma once
/// Reference elements, node positions and Lagrange shape functions of every Gmsh type
/// that has a Lagrange basis (ElementType::has_lagrange_basis).
///
/// Reference elements are Gmsh's:
///   line        [-1, 1]
///   triangle    (0,0) (1,0) (0,1)
///   quadrangle  [-1, 1]^2
///   tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1)
///   hexahedron  [-1, 1]^3
///   prism       triangle (u, v) × w in [-1, 1]
///   pyramid     base [-1, 1]^2 at w = 0, apex (0, 0, 1); Bergot's rational space
///               (thesis, Paper IV eqs. 1-2, lines 1502-1540 of the text), written in
///               xi' = xi/(1-zeta), eta' = eta/(1-zeta) in [-1, 1]: an affine change of the
///               thesis' xi/(1-zeta) in [0, 1], so the same space. Gmsh 4.8.4's complete
///               pyramids use this space too (its values agree with ours to 1e-11, orders 1-9).
/// Unused coordinates are 0.
///
/// Node order is Gmsh's: vertices, then the nodes inside each edge (running from the
/// edge's first vertex to its second), then for complete types the nodes inside each face
/// (the interior nodes of an order-p triangle or quadrangle, mapped onto the face through
/// its vertex list), then the interior nodes, which are the nodes of a lower-order element
/// of the same family shrunk into the interior (triangle p-3, quadrangle p-2, tetrahedron
/// p-4, hexahedron p-2, pyramid p-3), recursively.
///
/// Prisms of order >= 3 (ids 90, 91, 106-117): Gmsh 4.8.4 cannot give their nodes
/// ("FaceClosureFull not implemented for prisms of order 3"). quadval defines them in the
/// same way: faces in the order of reference_faces(prism) (triangles (0,2,1), (3,4,5), then
/// quadrangles (0,1,4,3), (0,3,5,2), (1,2,5,4), as Gmsh lists them), each face's nodes as
/// above; interior nodes are the tensor product of the triangle interior (order p-3
/// triangle, inner index) and the line interior (an order p-2 line at w in
/// [-(p-2)/p, (p-2)/p] in Gmsh line order: the two ends, then the inner points; outer
/// index). For p = 3, 4 this is also the vertex-first order of a small prism.
///
/// Function spaces (each checked against gmsh.model.mesh.getBasisFunctions in the tests):
///   complete     P_p (simplices), Q_p (line, quadrangle, hexahedron), P_p(u,v) ⊗ P_p(w)
///                (prism), Bergot's P^p (pyramid)
///   incomplete   quadrangle / hexahedron: monomials with at most one exponent > 1;
///                triangle / tetrahedron: monomials on the edges of Pascal's triangle /
///                tetrahedron (x^i y^j z^k, i+j+k <= p, at least two of i, j, k, p-i-j-k
///                zero); prism: (triangle incomplete) ⊗ {1, w}  +  {1, u, v} ⊗ {w^2..w^p};
///                pyramid: (xi/(1-zeta))^i (eta/(1-zeta))^j (1-zeta)^k with i, j <= k <= p and
///                either i, j <= 1 or (k = max(i, j) and min(i, j) <= 1). For order 2 this is
///                Gmsh's 13-node pyramid (Bergot's P^2 less x^2 y^2 / (1-zeta)^2); Gmsh 4.8.4
///                has no interpolating basis for incomplete pyramids of order >= 3 (its
///                functions are not 1 at their own nodes), so that definition is quadval's:
///                it reduces to Gmsh's on order 2 and traces Gmsh's incomplete quadrangle
///                space on the base.

#include <array>
#include <memory>
#include <span>

#include <Eigen/Core>

#include "quadval/element_type.hpp"

namespace quadval {

using RefPoint = std::array<double, 3>;

/// Corners of the reference element of a family, in Gmsh order; empty for families without
/// a Lagrange basis (polygon, polyhedron, trihedron). The point family has one vertex.
std::span<const RefPoint> reference_vertices(ElementFamily family) noexcept;

/// Edges as pairs of vertex indices, in Gmsh order; edge nodes run from .[0] to .[1].
std::span<const std::array<int, 2>> reference_edges(ElementFamily family) noexcept;

/// A face of a 3D reference element: 3 or 4 vertex indices, in the order that maps the
/// reference triangle (0,0) (1,0) (0,1) or quadrangle (-1,-1) (1,-1) (1,1) (-1,1) onto it.
struct ReferenceFace {
  int num_vertices;
  std::array<int, 4> vertices;  ///< the first num_vertices entries are used
};

/// Faces of a 3D family in Gmsh order; empty for families of dimension < 3.
std::span<const ReferenceFace> reference_faces(ElementFamily family) noexcept;

/// Where each group of nodes starts in the Gmsh node order of a Lagrange type.
struct NodeLayout {
  int nodes_per_edge = 0;           ///< order - 1
  int edge_begin = 0;               ///< edge e holds [edge_begin + e*nodes_per_edge, +nodes_per_edge)
  std::array<int, 7> face_begin{};  ///< face f holds [face_begin[f], face_begin[f+1]) (3D only)
  int interior_begin = 0;           ///< interior nodes are [interior_begin, num_nodes)
  int num_nodes = 0;
};

/// @pre type.has_lagrange_basis (throws std::invalid_argument otherwise)
NodeLayout node_layout(const ElementType& type);

/// Reference coordinates of the nodes of `type`, in Gmsh's node order.
/// @pre type.has_lagrange_basis (throws std::invalid_argument otherwise)
/// Built once per type; the span stays valid for the life of the program. Thread-safe.
std::span<const RefPoint> reference_nodes(const ElementType& type);

/// The Lagrange shape functions of one element type: N_i(node_j) = delta_ij.
///
/// N_i = sum_j phi_j C(j, i), with phi_j a basis of the space and C the inverse of the
/// generalized Vandermonde matrix V(k, j) = phi_j(node_k). phi_j: Bernstein polynomials for
/// complete triangles, tetrahedra and prisms (times Legendre in w), Legendre products in
/// [-1, 1] coordinates where those span the same space (quadrangles, hexahedra, pyramids),
/// monomials otherwise (incomplete triangles, tetrahedra, prisms of order >= 3 and
/// pyramids of order >= 3, whose spaces are not downward closed). Immutable after
/// construction, so one object can be used by any number of threads.
///
/// Pyramids: the functions are rational in zeta. Values are continuous up to the apex and
/// exact there. Gradients need zeta < 1; at zeta = 1 evaluate_gradients returns the limit
/// of the gradient along the axis xi = eta = 0 (finite, but only one of the directional
/// limits of a function whose gradient is not continuous at the apex).
class LagrangeBasis {
 public:
  /// Builds the basis (one LU of a #nodes × #nodes matrix); prefer the cached
  /// lagrange_basis(type). @pre type.has_lagrange_basis (throws std::invalid_argument)
  explicit LagrangeBasis(const ElementType& type);
  ~LagrangeBasis();
  LagrangeBasis(LagrangeBasis&&) noexcept;
  LagrangeBasis& operator=(LagrangeBasis&&) noexcept;

  const ElementType& type() const noexcept { return *type_; }
  int num_nodes() const noexcept { return type_->num_nodes; }
  /// Same as reference_nodes(type()).
  std::span<const RefPoint> nodes() const noexcept { return nodes_; }

  /// values[i] = N_i(p). No allocation. @pre values.size() >= num_nodes()
  void evaluate(const RefPoint& p, std::span<double> values) const;
  /// gradients[3*i + d] = dN_i/dp_d (d = 0, 1, 2; zero for unused dimensions).
  /// No allocation. @pre gradients.size() >= 3 * num_nodes()
  void evaluate_gradients(const RefPoint& p, std::span<double> gradients) const;

  /// #points × #nodes matrix: row k holds N_i(points[k]). One matrix product.
  Eigen::MatrixXd evaluate_batch(std::span<const RefPoint> points) const;
  /// Three #points × #nodes matrices: [d](k, i) = dN_i/dp_d (points[k]).
  std::array<Eigen::MatrixXd, 3> evaluate_gradients_batch(std::span<const RefPoint> points) const;

  struct Impl;  ///< the space and the coefficient matrix (src/mesh/lagrange_basis.cpp)

 private:
  const ElementType* type_;
  std::span<const RefPoint> nodes_;
  std::unique_ptr<const Impl> impl_;
};

/// The basis of `type`, built once, immutable and shared by all threads.
/// @pre type.has_lagrange_basis (throws std::invalid_argument otherwise)
const LagrangeBasis& lagrange_basis(const ElementType& type);

}  // namespace quadval
