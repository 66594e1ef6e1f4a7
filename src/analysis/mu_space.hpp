#pragma once
// The precomputed data of the measure mu for one element type (thesis, Paper V §2-5):
// the Bézier space of the entries of W = J_p J_i^-1, the exact linear maps from the node
// coordinates to the control values of the derivatives X_xi, X_eta, X_zeta in that space,
// the inverse ideal Jacobian J_i^-1, and the Bernstein product tables of the metric
// polynomials. Built once per type, immutable, shared by all threads. Internal.
#include <array>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "analysis/jacobian_product.hpp"
#include "analysis/sparse_rows.hpp"
#include "analysis/straight_sided.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "bezier/bernstein_product.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// Highest order of each family for which mu is bounded: the Jacobian engine's
/// max_supported_order for every family (triangles and quadrangles 10, tetrahedra 4, prisms
/// and hexahedra 4, pyramids 9; lines 10: mu is 1 or 0); 0 for other families. Above
/// mu_certificate_max_order the control-matrix bound of mu_control_bound.hpp bounds every
/// subdomain alone: it is certified on its own and needs only W's space and the degree-2n
/// product table, so the set-up stays small. Measured (Release, one thread; random
/// curved elements, abs_tol 1e-2): MuSpace set-up <= 0.06 s and ~1 MB for tetrahedra,
/// prisms and hexahedra of orders 3-4; pyramids 0.04 s (order 4) to 3.5 s and 12-21 MB
/// (order 9, 385 nodes: the exact derivative maps of 1000 x 385 rationals per column),
/// about the Jacobian space's own set-up time (2.9 s) and a sixth of its memory (79 MB),
/// so pyramids go to order 9 too.
int mu_max_order(ElementFamily family) noexcept;

/// Highest order of each family whose MuSpace also holds the exact certificate of
/// mu_metric.hpp (product tables up to degree 4n in 2D, 12n in 3D): triangles and
/// quadrangles 10 (2D needs degree 4n only: 0.16 s at triangle order 10, 0.09 s at
/// quadrangle order 10),
/// tetrahedra 3, prisms, hexahedra and pyramids 2. Above, measured: the tetrahedron of
/// order 4 needs 6.8 s and 207 MB for its tables; prisms and hexahedra of order 3 build
/// theirs in 0.3 s, but one (6n, 6n) product takes 4.4 ms resp. 14 ms (hexahedron of order
/// 2: 1.6 ms; order 4: 61 ms) and a certificate call needs a dozen of them: seconds per
/// near-degenerate element.
int mu_certificate_max_order(ElementFamily family) noexcept;

/// The rounded derivative maps of a MuSpace (what its exact set-up computes): generated at
/// build time for common types (product_tables.hpp), else made when the space is built.
struct MuTables {
  std::array<std::vector<double>, 3> derivative;  ///< as MuSpace::derivative(c)
  std::array<double, 3> row_sum{0, 0, 0};         ///< as MuSpace::derivative_row_sum(c)
};

class MuSpace {
 public:
  /// @pre type a Lagrange triangle, quadrangle, tetrahedron, prism, hexahedron or pyramid
  ///      of order 1..mu_max_order(family)
  /// With generated tables the derivative maps cost no exact (GMP) arithmetic.
  explicit MuSpace(const ElementType& type, TableSource source = TableSource::generated_or_exact);

  /// A copy of the derivative maps (what the generator writes, and what tests compare).
  MuTables tables() const;

  /// True when the certificate's data (degrees, sizes and product tables above (1, 1))
  /// were built: order <= mu_certificate_max_order(family). Otherwise only the control-
  /// matrix bound (MuMetric::control_lower_bound) may be used on this space.
  bool has_certificate() const noexcept { return certificate_; }

  const ElementType& type() const noexcept { return *type_; }
  int dim() const noexcept { return dim_; }
  int num_nodes() const noexcept { return num_nodes_; }

  /// The space of the entries of W: degree n per factor (simplices p - 1; quadrangles,
  /// prisms, hexahedra p in every factor, the derivative factor degree-elevated; pyramids
  /// r in each of the cube coordinates (u, v, t) of bezier/pyramid_basis.hpp, every
  /// column degree-elevated from pyramid_derivative_degrees to (r, r, r)).
  const BezierBasis& w_basis() const noexcept { return *w_basis_; }
  int w_size() const noexcept { return w_basis_->size(); }
  /// Degrees m n per factor, m in {1, 2, 4, 6, 8, 12} (3D; 2D: 1, 2, 4); without the
  /// certificate only m in {1, 2} (the others are empty, their sizes 0).
  const std::vector<FactorDegree>& degrees(int m) const noexcept { return degrees_[m]; }
  int size(int m) const noexcept { return sizes_[m]; }
  /// The bisections of W's space (m = 1) and of M's (m = 2), looked up once here rather
  /// than per element (bernstein_bisection's keyed, locked cache).
  const BernsteinBisection& bisection(int m) const noexcept { return *bisection_[m == 1 ? 0 : 1]; }

  /// Control value k of dX/dxi_c (Gmsh reference coordinates; pyramids: as a polynomial
  /// in the cube coordinates, analysis/pyramid_space.hpp) = sum_i
  /// derivative(c)[k * num_nodes + i] * (x_i - x_0); entries within 2u of the exact
  /// rationals (relative). c < dim().
  const std::vector<double>& derivative(int c) const noexcept { return deriv_[c]; }
  /// max_k sum_i |derivative(c)[k, i]|, rounded up to cover the exact entries.
  double derivative_row_sum(int c) const noexcept { return row_sum_[c]; }
  /// derivative(c) without its zero entries (sparse_rows.hpp).
  const SparseRows& derivative_nonzeros(int c) const noexcept { return sparse_[c]; }

  /// J_i^-1 (dim x dim, row-major) of the ideal element (mu_bounds.hpp), each entry within
  /// 3u of the exact real number (relative).
  const std::array<double, 9>& ideal_inverse() const noexcept { return ideal_inv_; }

  /// Product tables (degrees in units of n): (1, 1); with the certificate also (2, 2), and
  /// in 3D (4, 2), (2, 4), (4, 4), (8, 4), (6, 6), built on first use (thread-safe): few
  /// elements ever need the certificate, and its exact tables are most of a type's set-up
  /// (0.75 s of the cubic tetrahedron's 0.75 s). @pre the table exists (QV_ASSERT)
  const BernsteinProduct& prod(int a, int b) const;

 private:
  // The W space (simplex factors of these dimensions, degree n each), its product tables
  // and the ideal element.
  void init_w_space(const std::vector<int>& factor_dims, int n);
  bool certificate_ = false;
  // Pyramids: derivative maps from Bergot's exact shape functions (pyramid_space.hpp).
  void init_pyramid_derivatives();
  // The other families: derivative maps from the geometry's exact Bézier form.
  void init_derivatives();

  const ElementType* type_;
  int dim_ = 0;
  int num_nodes_ = 0;
  std::unique_ptr<BezierBasis> w_basis_;
  std::vector<FactorDegree> degrees_[13];
  int sizes_[13] = {};
  std::vector<double> deriv_[3];
  SparseRows sparse_[3];
  double row_sum_[3] = {};
  std::array<double, 9> ideal_inv_{};
  const BernsteinProduct* prod11_ = nullptr;  // (1, 1): the control matrices of M
  const BernsteinBisection* bisection_[2] = {};  // degrees (1) and (2)
  void build_certificate_products() const;
  mutable std::once_flag certificate_once_;
  mutable std::vector<std::pair<std::pair<int, int>, const BernsteinProduct*>> certificate_prod_;
};

/// Pyramids: the exact maps from the nodes to the Bézier control values of the columns
/// X_xi, X_eta, X_zeta of J_p (Gmsh's directions) as polynomials in the cube coordinates
/// (u, v, t) (analysis/pyramid_space.hpp), every column degree-elevated from
/// pyramid_derivative_degrees(r, c) to (r, r, r): control value k (index
/// k0 + (r+1) (k1 + (r+1) k2)) of column c = sum_i map[c][k * #nodes + i] (x_i - x_0),
/// each entry the double nearest to the exact rational; row_sum[c] >= max_k sum_i of the
/// exact |entries|. Shared by mu (MuSpace) and the scaled Jacobian.
/// @pre type is a Lagrange pyramid
struct PyramidColumnMaps {
  std::array<std::vector<double>, 3> map;
  std::array<double, 3> row_sum{};
};
PyramidColumnMaps pyramid_column_maps(const ElementType& type);

/// The shared space of `type`; thread-safe, built once.
const MuSpace& mu_space(const ElementType& type);

/// mu_bounds (quadval/mu_bounds.hpp) with the element's validity already settled by the
/// Jacobian engine (validity goal or finer), as check_mesh has it: the same bounds
/// without computing it again. @pre validity is the certified answer for these nodes
/// @param known the element's straight-sided margin, when the caller has it (the same
///              bounds, without computing it again)
QualityBounds mu_bounds_given(const ElementType& type, std::span<const double> nodes,
                              const QualityOptions& options, bool planar, Validity validity,
                              const KnownMargin* known = nullptr);

/// mu_bounds_given(type, nodes[l], options, true, Validity::valid, known[l]) for four valid
/// planar 2D elements at once, where it is settled without subdivisions (closed forms, or
/// its root in SIMD lanes where the elements lie in planes z = const): bit l set where
/// out[l] holds exactly that call's result; the others need the call. A lane's result does
/// not depend on the other lanes (pass an element twice to fill them). @pre type.dim == 2,
/// mu_supported(type), every element valid
unsigned mu_valid_planar4(const ElementType& type, const std::array<std::span<const double>, 4>& nodes,
                          const QualityOptions& options, const std::array<const KnownMargin*, 4>& known,
                          std::array<QualityBounds, 4>& out);

}  // namespace quadval
