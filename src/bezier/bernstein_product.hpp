#pragma once
// Products of polynomials in tensor-product Bernstein form (thesis, Paper V Prop. 4 and
// its three-factor form of §5.1), for any tensor product of simplex factors with the
// BezierBasis layout (coefficient index i_0 + s_0 * (i_1 + s_1 * i_2), factor 0 fastest;
// multi-indices in BernsteinSimplex order). Internal to quadval (src/).
//
// Per factor, the coefficient of B^{nu+mu}_k in f g is
//   h_k = sum_{i + j = k} f_i g_j alpha_i^nu alpha_j^mu / alpha_k^{nu+mu},
// alpha the multinomial of the multi-index; the weights of one k are positive and sum to 1
// (Vandermonde's identity), so every coefficient of a product is a convex combination of
// products f_i g_j. Rounding: each weight is rounded to nearest (relative u), the tensor
// weight is a product of at most three (2 more roundings), times scale, times f_i g_j
// (2 more) and summed with the other terms: |computed - exact| <= rounding(k) * sum over
// the k accumulated products of |scale| max|f| max|g|  (Higham, §3.1). Large products are
// computed as the equivalent scaled convolution (error model at the top of
// bernstein_product.cpp; the same bound).
#include <array>
#include <mutex>
#include <span>
#include <vector>

#include "quadval/bezier_basis.hpp"

namespace quadval {

/// Number of coefficients of a tensor-product space: prod C(n_f + d_f, d_f).
int bernstein_space_size(std::span<const FactorDegree> factors) noexcept;

/// Degrees of the space of a product: n_f + m_f per factor. @pre same factor dims
std::vector<FactorDegree> product_degrees(std::span<const FactorDegree> f,
                                          std::span<const FactorDegree> g);

/// The product table of two spaces with the same factor dimensions; immutable, shared.
class BernsteinProduct {
 public:
  /// @pre f.size() == g.size() in 1..3, f[i].dim == g[i].dim, degrees >= 0
  BernsteinProduct(std::vector<FactorDegree> f, std::vector<FactorDegree> g);

  int f_size() const noexcept { return f_size_; }
  int g_size() const noexcept { return g_size_; }
  int h_size() const noexcept { return h_size_; }
  std::span<const FactorDegree> h_degrees() const noexcept { return h_degrees_; }
  /// Largest number of (i, j) pairs that contribute to one output coefficient.
  int max_terms() const noexcept { return max_terms_; }

  /// h += scale * f * g (coefficient vectors of sizes f_size(), g_size(), h_size()).
  void multiply_add(const double* f, const double* g, double scale, double* h) const;
  /// h = f * g.
  void multiply(const double* f, const double* g, double* h) const;
  /// Four products h_l = f_l * g_l at once, product l in lane l of interleaved vectors
  /// (coefficient i of f_l at f[4 i + l], likewise g and h), each lane with exactly the
  /// arithmetic of multiply: the same bits, in one walk over the pairs for all four.
  /// Returns false, computing nothing, without an entry kernel (large products).
  bool multiply4(const double* f, const double* g, double* h) const;
  /// h += s0 f0 g0 + s1 f1 g1 on four lanes at once (interleaved as multiply4), each lane
  /// with exactly the arithmetic of multiply_add_sum on those two terms (f0 != g0 or f1 !=
  /// g1: not squares): the same bits. Returns false, computing nothing, where that is not
  /// the entry kernel's two-term walk (large products).
  bool multiply_add_sum2x4(double s0, const double* f0, const double* g0, double s1, const double* f1,
                           const double* g1, double* h) const;
  /// One term scale * f * g of a sum of products in the same spaces.
  struct Term {
    double scale;
    const double* f;
    const double* g;
  };
  /// h += sum_t scale_t f_t g_t. The scaled convolution keeps the whole sum in scaled form
  /// and unscales once, the entry kernel sums 2 or 3 terms per pair in one walk, and
  /// squares (f_t == g_t, same pointer, in every term) in half the pairs;
  /// rounding(terms.size()) bounds the result as for repeated multiply_add.
  void multiply_add_sum(std::span<const Term> terms, double* h) const;
  /// The Gram sums of a matrix polynomial W in one walk over the pairs: for each entry e =
  /// (a, b) of W^T W, h[e] += sum_x w[3 a + x] * w[3 b + x] (w[3 a + x]: coordinate x of
  /// column a, in this product's f space, which must equal its g space), with per entry
  /// the arithmetic of multiply_add_sum on its three terms (scales 1) by the general pairs,
  /// so rounding(3) bounds each, in the order of kGramEntries3 (kGramEntries2 for 2
  /// columns). Returns false, adding nothing, without an entry kernel
  /// (large products): then one multiply_add_sum per entry. With coordinates = 2 the sums
  /// leave out x = 2 (w[3 a + 2] is not read): the same bits as 3 where that coordinate is
  /// zero everywhere (a planar element's z), as its products, +-0, change a pair's sum at
  /// most in the sign of a zero, which the row's sum from +0 then drops.
  bool gram_sums(const double* const* w, int columns, double* const* h, int coordinates = 3) const;
  /// gram_sums of two columns of two coordinates (planar elements) on four lanes at once
  /// (interleaved as multiply4): w[2 a + x] holds coordinate x of column a, h[e] receives
  /// entry e of kGramEntries2, each lane with exactly gram_sums' arithmetic: the same bits.
  /// Returns false, adding nothing, without an entry kernel.
  bool gram_sums2x4(const double* const* w, double* const* h) const;
  /// gram_sums' entries (a, b), in order: 3 columns, then 2.
  static constexpr std::array<std::array<int, 2>, 6> kGramEntries3{{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  static constexpr std::array<std::array<int, 2>, 3> kGramEntries2{{{0, 0}, {1, 1}, {0, 1}}};
  /// Choose the per-factor weighted-entry loop (default for small products) or the scaled
  /// convolution (default for large ones); same product within rounding().
  void use_entry_kernel(bool on) noexcept { entries_kernel_ = on; }

  /// Relative rounding bound of `products` products accumulated into one h (starting from
  /// zero): |h - exact| <= rounding(products) * sum |scale| max|f| max|g|.
  double rounding(int products) const noexcept;

 private:
  struct Entry {
    int i, j, k;  // factor-local indices in f, g, h
    double w;     // alpha_i alpha_j / alpha_k, rounded to nearest
  };
  std::vector<FactorDegree> f_degrees_, g_degrees_, h_degrees_;
  int f_size_ = 1, g_size_ = 1, h_size_ = 1;
  int max_terms_ = 1;
  std::array<int, 3> f_stride_{}, g_stride_{}, h_stride_{};
  std::vector<Entry> entries_[3];  // per factor; unused factors hold one entry {0,0,0,1}
  // The entry kernel flattened over the tensor product and grouped by output coefficient
  // (small products only): pairs_[row_start_[k] .. row_start_[k + 1]) are the (i, j) of
  // h_k, each with its tensor weight computed exactly and rounded once.
  struct Pair {
    int i, j;
    double w;
  };
  std::vector<int> row_start_;
  std::vector<Pair> pairs_;
  // Squares (f and g in the same space): the pairs (i, j) and (j, i) of a row have the same
  // weight, so f_i f_j appears twice; these rows keep i <= j, with the weight doubled
  // (exactly) where i < j: about half the pairs, and a convex combination as before.
  std::vector<int> square_row_start_;
  std::vector<Pair> square_pairs_;
  // The entry kernel, N terms per walk over the given rows (pairs_ or square_pairs_).
  template <std::size_t N>
  void fused_entries(std::span<const Term> terms, const std::vector<int>& row_start,
                     const std::vector<Pair>& pair_list, double* h) const;
  // gram_sums for 2 or 3 columns, of 2 or 3 coordinates.
  template <int Columns, int Coordinates>
  void gram_entries(const double* const* w, double* const* h) const;
  // The same product as a dense convolution: coefficients scaled by their multinomials on
  // a grid of the barycentric indices (alpha_1..alpha_d of each factor, concatenated; at
  // most 3 coordinates), h_k = (sum_{i+j=k} f_i alpha_i g_j alpha_j) / alpha_k. Every
  // grid is addressed with the strides of h's grid, so that adding a * (g's grid) at the
  // cell of f_i is one contiguous loop per plane of g.
  struct Grid {
    std::vector<int> offset;     // per coefficient: its cell in h's strides
    std::vector<double> scale;   // alpha (f, g) or 1 / alpha (h) per coefficient, rounded
    std::vector<std::array<int, 2>> runs;  // (offset, length): contiguous runs covering it
  };
  // The convolution runs over rows of the smaller operand ("outer": up to kRowBlock of its
  // coefficients at consecutive cells, together), each row against every run of the
  // larger one ("inner"), whose runs are copied apart with kRowBlock zeros between them.
  static constexpr int kRowBlock = 8;
  struct Row {
    int first;   // position in outer_order_
    int length;  // 1..kRowBlock coefficients at cells offset, offset + 1, ...
    int offset;
  };
  struct Run {
    int start, length;  // cells of h's grid
    int guarded;        // where it starts in the guarded copy
  };
  // Built on the grid kernel's first use (thread-safe): a small product never needs them
  // (their set-up was a third of a small product's).
  mutable std::once_flag grids_once_;
  mutable Grid f_grid_, g_grid_, h_grid_;
  mutable int h_cells_ = 1;    // cells of h's grid
  mutable int acc_cells_ = 1;  // cells the rows write: h's grid and the zeros past a row's end
  mutable bool outer_is_g_ = false;
  mutable std::vector<int> outer_order_;  // outer coefficients by cell
  mutable std::vector<Row> outer_rows_;
  mutable std::vector<Run> inner_runs_;
  mutable std::vector<int> inner_guarded_;  // per inner coefficient: its place in the guarded copy
  mutable int guarded_size_ = 0;
  void build_grids() const;
  bool entries_kernel_ = false;  // the weighted-entry loop (small products)
  // acc (h's grid) += scale * (scaled f) conv (scaled g).
  void accumulate_grid(const double* f, const double* g, double scale, double* acc) const;
};

/// The shared table of (f, g); thread-safe, built once per key.
const BernsteinProduct& bernstein_product(std::span<const FactorDegree> f,
                                          std::span<const FactorDegree> g);

/// The relative rounding bound of a product (f g) k computed with the tables fg = (f, g)
/// and fgk = (f g, k): |out - exact| <= returned * max|f| max|g| max|k|.
double triple_product_rounding(const BernsteinProduct& fg, const BernsteinProduct& fgk);

/// out = f * g * k (three factors of §5.1, as (f g) k), scratch sized for f * g.
/// @return the relative rounding bound: |out - exact| <= returned * max|f| max|g| max|k|
double bernstein_triple_product(std::span<const FactorDegree> f_deg, const double* f,
                                std::span<const FactorDegree> g_deg, const double* g,
                                std::span<const FactorDegree> k_deg, const double* k,
                                std::vector<double>& scratch, double* out);

}  // namespace quadval
