#pragma once
// The sampling side of the Jacobian determinant of one element type: the gradients of its
// Lagrange shape functions at the Lagrange points of the Jacobian's Bézier space, exact
// (rational) and rounded. Internal to src/analysis.
//
// Derivatives are taken in Gmsh's reference coordinates (lagrange_basis.hpp), so J is
// Gmsh's J: a [-1, 1] direction mapped from the Bézier [0, 1] contributes a factor 1/2 to
// the gradient (exact in binary). Sample k is at BezierBasis::point(k) (Bézier domain).
#include <gmpxx.h>

#include <memory>
#include <mutex>
#include <vector>

#include "analysis/jacobian_product.hpp"

#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"

namespace quadval {

class JacobianSpace {
 public:
  /// @pre type.has_lagrange_basis, family in {line, triangle, quadrangle, tetrahedron,
  ///      prism, hexahedron}, order <= max_supported_order(family)
  explicit JacobianSpace(const ElementType& type);

  const ElementType& type() const noexcept { return *type_; }
  const BezierBasis& basis() const noexcept { return *basis_; }
  int num_nodes() const noexcept { return num_nodes_; }
  int num_samples() const noexcept { return num_samples_; }
  int dim() const noexcept { return dim_; }
  int num_vertices() const noexcept { return num_vertices_; }

  /// dN_i/dxi_c at sample k: gradient(c)[k * num_nodes + i], each entry within
  /// gradient_rel_error() * |exact| of the exact rational. c < dim(). Built on first use
  /// of gradient, gradient_row_sum or gradient_rel_error (thread-safe): `check` takes the
  /// product path and never needs them, so a type's set-up does not pay for them.
  /// @pre has_sample_gradients()
  const std::vector<double>& gradient(int c) const;
  /// Same for the straight-sided (first-order) element through the vertices:
  /// straight_gradient(c)[k * num_vertices + v], rounded from the exact rationals. Built
  /// on first use of any straight_* accessor (thread-safe): only distortion needs it.
  const std::vector<double>& straight_gradient(int c) const;
  /// max over samples k and directions c of sum_i |gradient(c)[k, i]| (rounded up, and
  /// covering the exact entries too).
  double gradient_row_sum() const;
  double gradient_rel_error() const;
  /// The same two constants for straight_gradient.
  double straight_row_sum() const;
  double straight_rel_error() const;

  /// The exact gradient matrices (same layout), built on first use; thread-safe.
  /// @pre has_sample_gradients()
  const std::vector<mpq_class>& exact_gradient(int c) const;

  /// The Bernstein-product path to J's coefficients (jacobian_product.hpp); nullptr for
  /// pyramids, which are sampled (Paper IV).
  const JacobianProduct* product() const noexcept { return product_.get(); }
  /// Whether the sampling matrices above are available (built on first use): the orders
  /// the sampled path served before the product path (sampled_max_order), which
  /// jacobian_samples and the exact sampled checks still use. Beyond them (e.g. hexahedra of
  /// order 4-6, 1331-4913 samples), and for pyramids, only the product path exists;
  /// jacobian_samples then evaluates the product coefficients at the points.
  bool has_sample_gradients() const noexcept { return sampled_; }

 private:
  void build_exact() const;
  void build_gradients() const;
  void build_straight() const;
  void init_pyramid();  // src/analysis/pyramid_space.cpp (Paper IV)

  const ElementType* type_;
  const BezierBasis* basis_;
  int num_nodes_ = 0;
  int num_samples_ = 0;
  int dim_ = 0;
  int num_vertices_ = 0;
  bool sampled_ = false;  // sample gradients exist (built lazily by build_gradients)
  mutable std::once_flag gradients_once_;
  mutable std::vector<double> grad_[3];
  mutable std::once_flag straight_once_;
  mutable std::vector<double> straight_[3];
  mutable double gradient_row_sum_ = 0;
  mutable double gradient_rel_error_ = 0;
  mutable double straight_row_sum_ = 0;
  mutable double straight_rel_error_ = 0;
  std::unique_ptr<const JacobianProduct> product_;
  mutable std::once_flag exact_once_;
  mutable std::vector<mpq_class> exact_[3];
};

/// The shared space of `type`; thread-safe, built once.
/// @pre jacobian_supported(type)
const JacobianSpace& jacobian_space(const ElementType& type);

/// Highest order with sample gradient matrices per family: lines 10, triangles and
/// quadrangles 6, tetrahedra 4, prisms and hexahedra 3 (the orders whose equispaced
/// Lagrange-to-Bézier conversion of the J space is well enough conditioned in double).
int sampled_max_order(ElementFamily family) noexcept;

/// True when quadval computes Jacobian bounds for this type (all Lagrange types of the
/// six families, up to max_supported_order; not pyramids).
bool jacobian_supported(const ElementType& type) noexcept;

}  // namespace quadval
