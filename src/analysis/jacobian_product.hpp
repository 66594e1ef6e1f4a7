#pragma once
// Bézier coefficients of the Jacobian determinant by Bernstein products, without sampling
// J and without the ill-conditioned Lagrange-to-Bézier matrix of the J space:
//   nodes -> control points of the derivatives X_xi, X_eta, X_zeta (one exact linear map
//   per direction: equispaced Lagrange-to-Bézier of the GEOMETRY factors, degree p, then
//   the Bernstein derivative rule p (P_{a+e_c} - P_{a+e_0})) -> J = det[X_xi, X_eta, X_zeta]
//   by Bernstein products (Paper V Prop. 4: coefficient gamma of f g is
//   sum_{a+b=gamma} f_a g_b mult(a) mult(b) / mult(gamma)), with an a priori bound on the
//   rounding of every coefficient. Internal to src/analysis.
//
// Scaled coefficients: the derivative maps store f^_a = mult(a) f_a, so that a product is a
// plain convolution over multi-indices, and J_gamma = J^_gamma / mult(gamma) at the end.
// Since sum_{a+b=gamma} mult(a) mult(b) = mult(gamma) (Vandermonde), every coefficient of a
// product is a convex combination of products of factor coefficients: |J_gamma| and its
// rounding are bounded by the largest factor coefficients, per coordinate.
//
// Incomplete (serendipity) types: their map lies in the complete space of the same order,
// so the complete nodes' values are an exact linear map of the element's nodes, folded into
// the derivative maps. The straight-sided map (for the distortion) likewise: the vertices'
// linear interpolant evaluated at the complete nodes.
#include <gmpxx.h>

#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "bezier/native_lanes.hpp"
#include "analysis/sparse_rows.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"

namespace quadval {

struct PyramidShapeCoefficients;  // pyramid_space.hpp

/// Which geometry to use: the element's own map, or its straight-sided element's.
enum class SampleMap { curved, straight };

/// The tables of a JacobianProduct: everything its double arithmetic reads that is rounded
/// from exact rationals, and the index tables of its kernel. Generated at build time for
/// common types (product_tables.hpp), else made when the product is built.
struct ProductTables {
  struct MapTables {
    int num_nodes = 0;
    std::array<std::vector<double>, 3> matrix;  ///< direction c: rows(c) x num_nodes, scaled rows
    std::array<double, 3> row_sum{0, 0, 0};     ///< max_k sum_i |exact entry| / mult(k), rounded up
  };
  std::array<MapTables, 2> maps;                   ///< SampleMap::curved, SampleMap::straight
  std::array<std::vector<double>, 3> deriv_inv_mult;  ///< 1 / mult(k) of each derivative space
  std::vector<double> inv_mult;                    ///< 1 / mult(gamma) of the J space
  double rounding = 0;                             ///< relative rounding of the products
  std::vector<int> lattice_of_node;                ///< complete types: lattice index of node i
  /// The convolutions by output (0: the cross product, 1: 3D's dot product): offsets
  /// (outputs + 1) into the terms, and the terms' inputs (a, b), flattened, in summation order.
  std::array<std::vector<int>, 2> gather_first, gather_terms;
};

struct ProductTableView;  // product_tables.hpp

/// Where a JacobianProduct takes its rounded tables from.
enum class TableSource {
  generated_or_exact,  ///< the build-time tables when the type has them, else exact
  exact,               ///< always round them here from the exact rationals (the generator, tests)
};

/// Scratch of JacobianProduct::coefficients, reused across calls.
struct ProductScratch {
  std::vector<double> block;  // one lane block's coordinates, derivatives and cross products
  std::vector<double> pair;   // the two lanes' coefficients of a single element
};

class JacobianProduct {
 public:
  /// Elements computed together, one per SIMD lane (one vector register, native_lanes.hpp).
  static constexpr int kLanes = kNativeLanes;

  /// @pre type a Lagrange line, triangle, quadrangle, tetrahedron, prism or hexahedron
  ///      (or pyramid, src/analysis/pyramid_space.cpp); basis = bezier_basis(type.family,
  ///      type.order)
  /// With generated tables (pyramids included) the exact rational data (GMP) is built only
  /// on the first exact_coefficients call (thread-safe), so the set-up of a type costs
  /// microseconds.
  JacobianProduct(const ElementType& type, const BezierBasis& basis,
                  TableSource source = TableSource::generated_or_exact);

  /// A copy of the rounded tables (what the generator writes, and what tests compare).
  ProductTables tables() const;

  /// Nodes read per element: all of them (curved) or the vertices (straight).
  int num_nodes(SampleMap map) const noexcept { return maps_[static_cast<int>(map)].num_nodes; }

  /// max_k sum_i |G_ki|, rounded up, where G_ki is the Bézier coefficient k of the
  /// derivative in Gmsh direction c of node i's shape function: |d f / d xi_c| <= this
  /// times max_i |f_i| on the element, for any nodal values f_i.
  double derivative_row_sum(SampleMap map, int c) const noexcept {
    return maps_[static_cast<int>(map)].row_sum[static_cast<std::size_t>(c)];
  }

  /// Bézier coefficients of J for `count` elements at once, each with a bound on the error
  /// of every one of its coefficients.
  /// @param nodes   count x #nodes x 3 (Gmsh node order; the full node list also for
  ///                SampleMap::straight, of which the vertices are read)
  /// @param planar  2D: n = +z (jacobian_bounds.hpp)
  /// @param coeffs  out: count x basis.size() (element-major)
  /// @param errors  out: count; |coeffs - exact| <= errors[e] for every coefficient of e
  /// Results do not depend on `count`: elements go through in lane blocks of
  /// kLanes (a tail one by one), each element with the same operations in the same order.
  void coefficients(SampleMap map, const double* nodes, std::size_t count, bool planar,
                    double* coeffs, double* errors, ProductScratch& scratch) const;

  /// Exact Bézier coefficients of J of one element (its doubles taken as exact rationals).
  /// @param nodes #nodes x 3
  std::vector<mpq_class> exact_coefficients(SampleMap map, const double* nodes, bool planar) const;

 private:
  struct Space {  // a tensor product of simplex factors with per-factor degrees
    std::array<int, 3> degree{0, 0, 0};
    std::array<int, 3> size{1, 1, 1};
    int total = 1;
  };
  struct Pair {  // one term a_i b_j -> c_k of a factor's convolution
    int a, b, c;
  };
  struct Product {  // per factor, the convolution terms of two spaces
    std::array<std::vector<Pair>, 3> pairs;
    std::array<int, 3> stride_a{0, 0, 0}, stride_b{0, 0, 0}, stride_c{0, 0, 0};
    int max_terms = 1;  // at most this many terms reach one output coefficient
  };
  struct Gather {  // per output coefficient, its convolution terms in summation order
    std::vector<int> first;  // outputs + 1 offsets into terms
    std::vector<std::array<int, 2>> terms;  // (input a, input b)
  };
  struct Map {
    int num_nodes = 0;
    std::array<SparseRows, 3> rows;  // matrix without its zeros (sparse_rows.hpp), what the kernel reads
    // derivative maps: deriv[c] is rows(c) x num_nodes, row-major, scaled rows
    std::array<std::vector<double>, 3> matrix;
    std::array<double, 3> row_sum{0, 0, 0};  // max_k sum_i |exact entry| / mult(k), rounded up
    // exact nodal values on the complete lattice: lattice x num_nodes (empty: the nodes
    // are the lattice, node i at lattice_of_node[i])
    std::vector<mpq_class> to_lattice;
    // pyramids: the exact shape functions (pyramid_space.hpp), for exact_coefficients
    std::shared_ptr<const PyramidShapeCoefficients> pyramid;
  };

  Product make_product(const Space& a, const Space& b, const Space& c) const;
  template <class F>
  static void for_each_term(const Product& p, F&& f);  // f(a, b, c) per term
  template <class F>
  static void for_each_term(const Gather& g, F&& f);  // the same terms, by output
  // The gathers and the rounding constant from the convolutions (bcs: 3D's cross product
  // space; jspace: the J space).
  void build_products(const Space& bcs, const Space& jspace);
  void build_lattice_of_node();  // complete types
  void build_exact() const;       // the exact data below, once (thread-safe)
  void build_exact_data() const;  // factor_matrix_, mult_, to_lattice
  void build_lattice_values(SampleMap which) const;
  void build_rounded_tables();    // from the exact data
  void build_map_tables(SampleMap which);
  void load_tables(const ProductTableView& generated);
  Gather make_gather(const Product& p, int outputs) const;
  void build_sparse_rows();  // from the maps' matrices
  // coefficients() of W consecutive elements (lanes), all arrays lane-fastest in buf.
  template <int W>
  void lane_block(const Map& map, const double* nodes, std::size_t stride, bool planar,
                  double* coeffs, double* errors, double* buf) const;
  std::size_t block_size(const Map& map, int lanes) const;
  // Pyramids (src/analysis/pyramid_space.cpp, Paper IV, cube coordinates): the spaces and
  // products, then the rounded tables (generated, or rounded from the exact data)...
  void init_pyramid(TableSource source);
  void build_pyramid_exact_data() const;  // ...and the exact data: mult_, Map::pyramid
  void build_pyramid_rounded_tables();
  std::vector<mpq_class> exact_derivative(int c, const std::vector<mpq_class>& lattice_values) const;

  const ElementType* type_;
  const BezierBasis* basis_;
  int dim_ = 0;
  int order_ = 0;
  int num_factors_ = 0;
  std::array<int, 3> factor_dim_{0, 0, 0};
  std::array<int, 3> factor_first_{0, 0, 0};
  std::array<bool, 3> factor_interval_{false, false, false};
  std::array<int, 3> direction_factor_{0, 0, 0};  // factor of Gmsh direction c
  std::array<int, 3> direction_local_{0, 0, 0};   // its coordinate within the factor
  Space lattice_;                                 // degree p in every factor
  std::array<Space, 3> deriv_space_;
  std::array<std::vector<double>, 3> deriv_inv_mult_;  // 1 / mult(k), rounded to nearest
  std::vector<double> inv_mult_;                        // 1 / mult(gamma) of the J space
  // Exact data, built by build_exact (mutable: lazily, under exact_once_).
  mutable std::once_flag exact_once_;
  mutable std::vector<mpz_class> mult_;                 // mult(gamma) of the J space
  // exact per-factor derivative maps: factor_matrix_[c][h] is rows x lattice size of factor h
  mutable std::array<std::array<std::vector<mpq_class>, 3>, 3> factor_matrix_;
  std::vector<int> lattice_of_node_;  // complete types: lattice index of node i
  int cross_size_ = 0;  // 3D: coefficients of each component of X_eta x X_zeta
  // The convolutions by output: 3D: X_eta x X_zeta, then X_xi . (X_eta x X_zeta); 2D:
  // X_xi x X_eta (then J).
  Gather cross_gather_, dot_gather_;
  double rounding_ = 0;  // relative rounding of the products and the final scaling
  mutable std::array<Map, 2> maps_;  // mutable for Map::to_lattice, Map::pyramid (build_exact)
};

}  // namespace quadval
