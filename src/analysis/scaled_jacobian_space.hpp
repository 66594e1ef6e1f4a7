#pragma once
// Per-type data of the scaled-Jacobian bounds (scaled_jacobian.hpp): the exact linear maps
// from an element's nodes to the Bézier coefficients of the columns of J_p in their own
// (native) degrees, the Bézier space of the squared quantities N and D_k (the Jacobian
// space's factors at twice their degree), the frames and the normalisation. Built once
// per type, immutable, shared by all threads. Internal to src/analysis.
//
// The squared space is subdivided by edge bisection (bezier/bernstein_bisection.hpp),
// not by BezierBasis's dense midpoint-split matrices: at the orders the Jacobian bounds
// reach, its simplex factors are far beyond what dense matrices allow (tetrahedron of
// order 4: degree 18, 1330 coefficients, 8 x 1330^2 doubles = 113 MB of matrices; triangle
// of order 9: degree 32, 561), and bisection costs fewer operations even where they fit
// (a split of the degree-12 squared factor of a cubic tetrahedron: ~15 thousand averages
// per vector against 1.7 million multiply-adds). N and D_k are formed once per element,
// then only subdivided: recomputing them by products on every subdomain (subdividing the
// columns instead) would cost a Bernstein product of the degree-2n spaces per vector and
// subdomain, more than the bisection of the product itself.
#include <array>
#include <span>
#include <vector>

#include "analysis/jacobian_space.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/sparse_rows.hpp"
#include "analysis/straight_sided.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// Frame column j = sum_c coefficient[j][c] * (column c of J_p); entries in {-1, 0, 1}.
using Frame = std::array<std::array<int, 3>, 3>;

class ScaledJacobianSpace {
 public:
  /// @pre scaled_jacobian_supported(type)
  explicit ScaledJacobianSpace(const ElementType& type);

  const ElementType& type() const noexcept { return *type_; }
  int dim() const noexcept { return type_->dim; }
  /// The space of J (jacobian_factor_degrees) and of N, D_k (twice those degrees).
  const std::vector<FactorDegree>& j_degrees() const noexcept { return j_degrees_; }
  const std::vector<FactorDegree>& squared_degrees() const noexcept { return squared_degrees_; }
  const BernsteinBisection& squared() const noexcept { return squared_; }
  const std::vector<Frame>& frames() const noexcept { return frames_; }
  /// s of the definition and a guaranteed enclosure s_lo <= s <= s_hi.
  double s_lo() const noexcept { return s_lo_; }
  double s_hi() const noexcept { return s_hi_; }

  /// Column c = dX/dxi_c (Gmsh coordinates) lies in the tensor space column_degrees(c):
  /// the geometry's degree p per factor, p - 1 in the factor holding direction c;
  /// pyramids: degree r in each cube coordinate (u, v, t) (mu_space.hpp,
  /// pyramid_column_maps), J then of degree 3r per axis.
  const std::vector<FactorDegree>& column_degrees(int c) const noexcept { return col_degrees_[static_cast<std::size_t>(c)]; }
  int column_size(int c) const noexcept { return col_size_[static_cast<std::size_t>(c)]; }
  /// Its Bézier coefficients = column_map(c) * (x_i - x_0) per axis: row-major
  /// column_size(c) x #nodes, each entry within 4u relative of the exact rational
  /// (the Jacobian product path's scaled derivative map times its rounded 1 / mult(k);
  /// pyramids: pyramid_column_maps, within u).
  const std::vector<double>& column_map(int c) const noexcept { return col_map_[static_cast<std::size_t>(c)]; }
  /// column_map(c) without its zero entries (sparse_rows.hpp).
  const SparseRows& column_nonzeros(int c) const noexcept { return col_sparse_[static_cast<std::size_t>(c)]; }
  /// max over rows of sum_i |exact entry|, rounded up.
  double column_row_sum(int c) const noexcept { return col_row_sum_[static_cast<std::size_t>(c)]; }

 private:
  void init_pyramid();

  const ElementType* type_;
  std::vector<FactorDegree> j_degrees_, squared_degrees_;
  BernsteinBisection squared_;
  std::vector<Frame> frames_;
  std::array<std::vector<FactorDegree>, 3> col_degrees_;
  std::array<int, 3> col_size_{0, 0, 0};
  std::array<std::vector<double>, 3> col_map_;
  std::array<SparseRows, 3> col_sparse_;
  std::array<double, 3> col_row_sum_{0, 0, 0};
  double s_lo_ = 1, s_hi_ = 1;
};

/// The shared space of `type`; thread-safe, built once. @pre scaled_jacobian_supported(type)
const ScaledJacobianSpace& scaled_jacobian_space(const ElementType& type);

/// The first stage of scaled_jacobian_bounds_given on its own (tests): bounds of sj(E) from J
/// and the frame columns alone, refined by at most max_splits splits until upper - lower <=
/// tol (scaled_jacobian_quotient.hpp). Certified when J > 0 on the whole element; lower =
/// -inf when J's least coefficient is not positive or for a surface element in 3D.
QualityBounds scaled_jacobian_quotient_stage(const ElementType& type, std::span<const double> nodes, bool planar,
                                             double tol, int max_splits);

/// The signed first stage on its own (tests): bounds of sj(E) of a 3D element, or a 2D one
/// in a plane z = const, where J <= 0 was found at a point (the caller's claim: upper starts at 0), from J's coefficients with
/// their signs and the columns (scaled_jacobian_quotient.hpp), refined by at most max_splits
/// splits; floor_root_ends as for signed_quotient_bounds.
QualityBounds scaled_jacobian_signed_stage(const ElementType& type, std::span<const double> nodes, double tol,
                                           int max_splits, bool floor_root_ends = false);

/// Tests only: switch off (on by default), in the calling thread, the closed-form bounds of
/// valid straight-sided simplices (planar triangles, tetrahedra: columns within the
/// straight_sided.hpp margins of their edges) and of valid bilinear planar quadrangles
/// (bilinear_quad_quality.hpp), and the root bounds of valid first-order hexahedra and
/// pyramids (trilinear_hex_sj.hpp, linear_pyramid_sj.hpp), to compare them with the
/// general path.
void scaled_jacobian_use_straight_path(bool on) noexcept;
bool scaled_jacobian_straight_path_enabled() noexcept;

/// Tests only: switch off (on by default), in the calling thread, the paired bound of the
/// first stage of valid elements (3D, planar 2D; scaled_jacobian_quotient.cpp,
/// paired_bound): the stage then bounds J's least coefficient over the largest norms alone.
void scaled_jacobian_use_paired_stage(bool on) noexcept;

/// scaled_jacobian_bounds with the element's validity already settled by the Jacobian
/// engine (jacobian_bounds, any goal: only the sign of min J is used), as check_mesh has
/// it; results are identical. @pre v is that element's certified validity.
/// @param known the element's straight-sided margin, when the caller has it (the same
///              bounds, without computing it again)
QualityBounds scaled_jacobian_bounds_given(const ElementType& type, std::span<const double> nodes,
                                           const QualityOptions& options, bool planar, Validity v,
                                           const KnownMargin* known = nullptr);

/// scaled_jacobian_bounds_given(type, nodes[l], options, true, Validity::valid, known[l])
/// for four valid planar 2D elements at once, where it is settled without subdivisions
/// (closed forms, or the first stage's root in SIMD lanes: paired_quotient_roots in
/// scaled_jacobian_quotient.hpp): bit l set where out[l] holds exactly that call's result;
/// the others need the call. A lane's result does not depend on the other lanes (pass an
/// element twice to fill them). @pre type.dim == 2, every element valid
unsigned scaled_jacobian_valid_planar4(const ElementType& type, const std::array<std::span<const double>, 4>& nodes,
                                       const QualityOptions& options, const std::array<const KnownMargin*, 4>& known,
                                       std::array<QualityBounds, 4>& out);

/// scaled_jacobian_bounds_given of kNativeLanes valid straight-sided tetrahedra, or triangles
/// in a plane z = const, of `type` at once, where the closed form of straight-sided simplices
/// settles them (the same bits): edges[3 c + j]: coordinate j of x_{c+1} - x_0 per lane
/// (computed from the nodes; 0 for a triangle's z); beta[c] and margin: the straight-sided
/// margins of column c and of J that call gets (0 for first order). Bit l is set where
/// out[l] holds lane l's bounds; the other lanes need the call.
unsigned straight_simplex_sj_lanes(const ElementType& type, const Lanes<kNativeLanes>* edges,
                                   const Lanes<kNativeLanes>* beta, Lanes<kNativeLanes> margin, double tol,
                                   QualityBounds* out);

}  // namespace quadval
