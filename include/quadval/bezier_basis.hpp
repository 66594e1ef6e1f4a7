#pragma once
/// Bézier (Bernstein) bases of the space of the Jacobian determinant, per element family
/// and order: Bernstein evaluation, Lagrange-to-Bézier conversion and subdivision.
/// Thesis, Paper III §4 (eqs. 14-22, Table 1).
///
/// Every family's space is a tensor product of one to three *simplex factors*
/// (BernsteinSimplex): line = [line], triangle = [triangle], quadrangle = [line, line],
/// tetrahedron = [tetrahedron], prism = [triangle, line], hexahedron = [line, line, line].
/// Conversions and subdivisions are applied factor by factor (sum factorisation), so the
/// memory of a basis grows with the factor sizes, never with the square of the whole
/// coefficient count.
///
/// Reference domains here are the Bézier ones: each factor is the unit simplex
/// (line [0,1], triangle (0,0)(1,0)(0,1), tetrahedron (0,0,0)(1,0,0)(0,1,0)(0,0,1)). The
/// Jacobian code maps Gmsh's [-1,1] directions onto [0,1].
///
/// All matrices are computed once per key in exact rational arithmetic (GMP), then rounded
/// to the nearest double; subdivision matrices are dyadic and exact in double. Bases are
/// built once, immutable and shared by all threads (STYLE.md §7). The Lagrange-to-Bézier
/// matrix (an exact inverse, cubic in the factor size) is built on first use only: the
/// Jacobian coefficients of the six Lagrange families come from Bernstein products
/// (src/analysis/jacobian_product.hpp) and never need it.

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval {

/// Bernstein polynomials of degree n on the unit d-simplex (d = 1, 2, 3):
/// B_alpha(lambda) = n! / (alpha_0! ... alpha_d!) * prod_a lambda_a^alpha_a, |alpha| = n,
/// with barycentric coordinates lambda = (1 - sum xi, xi_1, ..., xi_d).
/// Thesis, Paper III eq. (14) and the triangle/tetrahedron formulas of §4.3.
class BernsteinSimplex {
 public:
  /// Builds the factor; prefer the shared instance bernstein_simplex(dim, degree).
  /// @pre 1 <= dim <= 3, 0 <= degree, and the coefficient count at most 500
  BernsteinSimplex(int dim, int degree);
  ~BernsteinSimplex();
  BernsteinSimplex(const BernsteinSimplex&) = delete;
  BernsteinSimplex& operator=(const BernsteinSimplex&) = delete;

  int dim() const noexcept { return dim_; }
  int degree() const noexcept { return degree_; }
  /// Number of coefficients, C(n + d, d).
  int size() const noexcept { return static_cast<int>(alphas_.size()); }
  /// Barycentric multi-index (alpha_0 .. alpha_d, unused entries 0) of coefficient i.
  std::span<const std::array<int, 4>> multi_indices() const noexcept { return alphas_; }
  /// True for the d+1 coefficients at the vertices (alpha = n e_a): they equal the value
  /// of the polynomial there (eq. 17). For degree 0 the single coefficient is a vertex one.
  bool is_vertex(int i) const noexcept { return vertex_[static_cast<std::size_t>(i)]; }

  /// Lagrange (sampling) point i in local coordinates: xi_c = alpha_c / n (c = 1..d); the
  /// barycentre for degree 0. Rounded to double (e.g. 1/3); exact values are alpha / n.
  std::array<double, 3> point(int i) const noexcept;
  /// Barycentric numerators of point i over the denominator point_denominator():
  /// lambda_a = point_numerators(i)[a] / point_denominator().
  std::array<int, 4> point_numerators(int i) const noexcept;
  int point_denominator() const noexcept { return degree_ == 0 ? dim_ + 1 : degree_; }

  /// values[i] = B_i(xi) for xi in local coordinates. @pre values.size() >= size()
  void evaluate(std::span<const double> xi, std::span<double> values) const;

  /// T (size x size, row-major): Bézier coefficients = T * values at the points (eq. 18),
  /// each entry the double nearest to the exact rational. Built on first use (thread-safe).
  std::span<const double> lagrange_to_bezier() const;
  /// The same matrix transposed (column-major), for vectorised products.
  std::span<const double> lagrange_to_bezier_transposed() const;
  /// max_i sum_j |T_ij| of the exact T, rounded up: how much an error in the samples can
  /// grow in the coefficients.
  double lagrange_to_bezier_norm() const;
  /// V = T^-1 (size x size, row-major): values at the points = V * Bézier coefficients,
  /// V_ki = B_i(point k), each entry the double nearest to the exact rational. Entries are
  /// nonnegative and each exact row sums to 1 (partition of unity, eq. 14). Built on first
  /// use (thread-safe): only sampling beyond the sampled orders needs it.
  std::span<const double> bezier_to_lagrange() const;
  std::span<const double> bezier_to_lagrange_transposed() const;
  /// The exact T and other rational data (src/bezier/bezier_exact.hpp; GMP stays out
  /// of the public headers). Building it inverts the collocation matrix on first use.
  struct Exact;
  const Exact& exact() const;

  /// 2^d children: the line halves, the 4 triangles of the midpoint split, the 8
  /// tetrahedra of the midpoint split (octahedron cut along the diagonal m02-m13).
  int num_children() const noexcept { return 1 << dim_; }
  /// Vertices of child q, in the parent's barycentric coordinates times 2 (entries 0..2).
  std::span<const std::array<std::array<int, 4>, 4>> child_vertices() const noexcept {
    return children_;
  }
  /// S_q (size x size, row-major): the child's Bézier coefficients = S_q * parent's
  /// (eq. 20). Entries are k / 2^n, nonnegative, each row sums to 1: exact in double.
  /// Built on first use (thread-safe).
  std::span<const double> subdivision(int child) const;
  /// S_q transposed.
  std::span<const double> subdivision_transposed(int child) const;

 private:
  int dim_;
  int degree_;
  std::vector<std::array<int, 4>> alphas_;
  void build_to_bezier() const;
  std::vector<bool> vertex_;
  mutable std::once_flag to_bezier_once_;
  mutable std::vector<double> to_bezier_, to_bezier_t_;
  mutable double to_bezier_norm_ = 0;
  void build_to_lagrange() const;
  mutable std::once_flag to_lagrange_once_;
  mutable std::vector<double> to_lagrange_, to_lagrange_t_;
  std::unique_ptr<Exact> exact_;
  std::vector<std::array<std::array<int, 4>, 4>> children_;
  void build_subdivision() const;
  mutable std::once_flag subdivision_once_;
  mutable std::vector<double> subdivision_, subdivision_t_;  // num_children blocks of size*size
};

/// Multi-indices of the Bernstein polynomials of degree n on the d-simplex (d = 0..3), in
/// the order of BernsteinSimplex::multi_indices(), without building a factor: the last
/// barycentric index slowest, alpha_0 = n - the others; d = 0 gives the single {n, 0, 0, 0}.
std::vector<std::array<int, 4>> simplex_multi_indices(int dim, int degree);

/// The shared factor of (dim, degree); thread-safe, built once.
const BernsteinSimplex& bernstein_simplex(int dim, int degree);

/// The degrees of the Jacobian determinant of a family of geometric order p, per simplex
/// factor (Paper III Table 1, with the prism's triangle factor at its true degree 3p-2,
/// one less than the table's 3p-1: dX/du and dX/dv lose one degree in (u,v)). Empty for
/// families with no factorisation here (pyramids: Paper IV, a separate space).
struct FactorDegree {
  int dim;
  int degree;
};
std::vector<FactorDegree> jacobian_factor_degrees(ElementFamily family, int order);

/// Highest geometric order whose Jacobian space we build, per family: lines, triangles and
/// quadrangles 10 (every order Gmsh defines), tetrahedra 4, prisms and hexahedra 4.
/// The Jacobian coefficients come from Bernstein products of the geometry's control
/// points (src/analysis/jacobian_product.hpp), not from the J space's ill-conditioned
/// conversion; the 3D limits are memory (tetrahedra of order 5: a 455-coefficient factor,
/// 8 x 455^2 subdivision entries) and time. Pyramids: kPyramidMaxOrder (Paper IV,
/// sampled). 0 for other families.
int max_supported_order(ElementFamily family) noexcept;

/// The Bézier basis of the Jacobian determinant space of (family, order p): a tensor
/// product of simplex factors. Coefficient index = i_0 + s_0 * (i_1 + s_1 * i_2) with
/// i_f the index in factor f (size s_f).
class BezierBasis {
 public:
  /// @pre factors non-empty, each factor a shared instance (borrowed for the program's life)
  BezierBasis(ElementFamily family, int order, std::vector<const BernsteinSimplex*> factors);

  ElementFamily family() const noexcept { return family_; }
  int order() const noexcept { return order_; }
  int dim() const noexcept { return dim_; }
  int size() const noexcept { return size_; }
  std::span<const BernsteinSimplex* const> factors() const noexcept { return factors_; }
  /// Coefficient indices at the vertices of the domain (corner coefficients, eq. 17).
  std::span<const int> vertex_indices() const noexcept { return vertex_indices_; }
  /// Sampling point i in Bézier-domain coordinates (factor coordinates concatenated;
  /// prism: (u, v, t)). Rounded to double.
  std::array<double, 3> point(int i) const noexcept;
  /// Factor index of coefficient i in factor f.
  int factor_index(int i, int f) const noexcept;

  /// values[i] = product of factor Bernstein values at x (Bézier-domain coordinates).
  void evaluate(std::span<const double> x, std::span<double> values) const;

  /// Bézier coefficients from samples at the points (eq. 18), factor by factor.
  /// @pre samples, coeffs: size(); scratch: 2 * size(); coeffs may not alias samples
  void to_bezier(const double* samples, double* coeffs, double* scratch) const;
  /// The same for `count` elements at once (a matrix-matrix product, DESIGN.md
  /// "Batching"); layout [k * count + e], element fastest. Every element's coefficients
  /// are summed in the same order as to_bezier's, so results are bit-identical.
  /// @pre samples, coeffs: size() * count; scratch: 2 * size() * count
  void to_bezier_batch(const double* samples, std::size_t count, double* coeffs,
                       double* scratch) const;
  /// Product of the factor norms (rounded up): |exact T| row-sum bound of the whole T.
  /// Computed on first use (builds every factor's T).
  double to_bezier_norm() const;
  /// Rounding of to_bezier: |computed - exact T applied to the same doubles| <=
  /// to_bezier_rounding() * to_bezier_norm() * max|samples| (entrywise).
  double to_bezier_rounding() const noexcept { return to_bezier_rounding_; }

  /// Values at the points from Bézier coefficients (V = T^-1, factor by factor), for
  /// `count` elements at once, layout as to_bezier_batch's.
  /// @pre coeffs, samples: size() * count; scratch: 2 * size() * count
  void from_bezier_batch(const double* coeffs, std::size_t count, double* samples,
                         double* scratch) const;
  /// Rounding of from_bezier_batch: |computed - exact V applied to the same doubles| <=
  /// from_bezier_rounding() * max|coeffs| (V >= 0 with rows summing to 1, rounded entries).
  double from_bezier_rounding() const noexcept { return from_bezier_rounding_; }

  int num_children() const noexcept { return num_children_; }
  /// Child coefficients of child q (0 <= q < num_children()): factor children
  /// q_f = digits of q in mixed radix (factor 0 fastest).
  /// @pre parent, child: size(); scratch: 2 * size(); child may not alias parent
  void subdivide(int child, const double* parent, double* out, double* scratch) const;
  /// The same for `count` vectors at once, each contiguous (parents[v * size() + k]):
  /// the factor matrix is read once, in column blocks that stay in cache, for all of them
  /// (the time goes there at high degree: 455 x 455 per child for the squared space of a
  /// cubic tetrahedron). Summed in the same order as subdivide: bit-identical results.
  /// @pre parents, out: size() * count; scratch: 2 * size(); out may not alias parents
  void subdivide_many(int child, const double* parents, std::size_t count, double* out,
                      double* scratch) const;
  /// Rounding of one subdivision: |computed - exact S_q applied to the same doubles| <=
  /// subdivision_rounding() * max|parent| (S_q is exact, nonnegative, rows sum to 1).
  double subdivision_rounding() const noexcept { return subdivision_rounding_; }
  /// Child q's factor child indices.
  std::array<int, 3> child_digits(int child) const noexcept;

 private:
  template <class MatrixOf>
  void apply_factors(const double* in, double* out, double* scratch, std::size_t count,
                     MatrixOf matrix_of) const;

  ElementFamily family_;
  int order_;
  int dim_ = 0;
  int size_ = 1;
  int num_children_ = 1;
  std::vector<const BernsteinSimplex*> factors_;
  std::vector<int> vertex_indices_;
  mutable std::once_flag norm_once_;
  mutable double to_bezier_norm_ = 1;
  double from_bezier_rounding_ = 0;
  double to_bezier_rounding_ = 0;
  double subdivision_rounding_ = 0;
};

/// The shared basis of the Jacobian space of (family, order); thread-safe, built once.
/// @pre 1 <= order <= max_supported_order(family) (throws std::invalid_argument otherwise)
const BezierBasis& bezier_basis(ElementFamily family, int order);

/// gamma_k = k u / (1 - k u), u = 2^-53: the classical bound on the relative rounding
/// error of a k-term floating-point sum of products (Higham, Accuracy and Stability, §3.1).
/// Inline, so that a constant k folds to a constant (it is taken per control point).
constexpr double rounding_gamma(int k) noexcept {
  constexpr double u = std::numeric_limits<double>::epsilon() / 2;
  return k * u / (1 - k * u);
}

}  // namespace quadval
