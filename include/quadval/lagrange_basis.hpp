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
///               (thesis, Paper IV eqs. 1-2)
/// Unused coordinates are 0.

#include <array>
#include <memory>
#include <span>

#include "quadval/element_type.hpp"

namespace quadval {

using RefPoint = std::array<double, 3>;

/// Reference coordinates of the nodes of `type`, in Gmsh's node order.
/// @pre type.has_lagrange_basis (throws std::invalid_argument otherwise)
/// Built once per type; the span stays valid for the life of the program.
std::span<const RefPoint> reference_nodes(const ElementType& type);

/// The Lagrange shape functions of one element type: N_i(node_j) = delta_ij.
class LagrangeBasis {
 public:
  virtual ~LagrangeBasis() = default;
  const ElementType& type() const noexcept { return *type_; }
  int num_nodes() const noexcept { return type_->num_nodes; }

  /// values[i] = N_i(p). @pre values.size() >= num_nodes()
  virtual void evaluate(const RefPoint& p, std::span<double> values) const = 0;
  /// gradients[3*i + d] = dN_i/dp_d (d = 0, 1, 2; zero for unused dimensions).
  /// @pre gradients.size() >= 3 * num_nodes()
  virtual void evaluate_gradients(const RefPoint& p, std::span<double> gradients) const = 0;

 protected:
  explicit LagrangeBasis(const ElementType& type) : type_(&type) {}

 private:
  const ElementType* type_;
};

/// The basis of `type`, built once, immutable and shared by all threads.
/// @pre type.has_lagrange_basis (throws std::invalid_argument otherwise)
const LagrangeBasis& lagrange_basis(const ElementType& type);

}  // namespace quadval
