// Bernstein products (thesis, Paper V Prop. 4), two kernels computing the same sums:
//  - small products: per-factor tables of (i, j, k, weight), applied as a tensor product
//    of the factor tables; weights are exact rationals rounded once to double;
//  - large products: the scaled form. With alpha the multinomials,
//      h_k = (1 / alpha_k) sum_{i + j = k} (alpha_i f_i) (alpha_j g_j),
//    a plain N-D convolution of the scaled coefficients (grids of the barycentric indices),
//    computed as contiguous runs in h's strides; a sum of products in the same spaces is
//    accumulated in scaled form and unscaled once (multiply_add_sum).
// Error model of the scaled form, per term alpha_i alpha_j / alpha_k f_i g_j: alpha_i,
// alpha_j, 1 / alpha_k each rounded to nearest (within u; 2u allowed), scale * alpha_i (u),
// times f_i (u), alpha_j g_j (u), the term product (u, or none with a fused multiply-add),
// the unscaling product (u) and the final addition into h (u): at most 12 roundings, so
// the computed term is the exact convex-weighted term times (1 + theta_12). The k terms
// of one cell of a sum of `products` products (k <= products * max_terms; the zero
// padding adds exact zeros) are summed recursively (gamma_k, Higham §3.1). Together:
// |computed - exact| <= gamma_{products * max_terms + 16} sum |scale| max|f| max|g|,
// since the exact convex weights of one k sum to 1 — the same bound as the entry kernel.
#include "bezier/bernstein_product.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <gmpxx.h>

#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <tuple>

#include "bezier/multi_index_table.hpp"
#include "bezier/native_lanes.hpp"
#include "bezier/rational_rounding.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

using MultiIndex = std::array<int, 4>;

mpz_class factorial(int n) {
  mpz_class f = 1;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}

// n! / prod alpha_a!
mpz_class multinomial(const MultiIndex& a, int dim) {
  int n = 0;
  mpz_class den = 1;
  for (int c = 0; c <= dim; ++c) {
    n += a[static_cast<std::size_t>(c)];
    den *= factorial(a[static_cast<std::size_t>(c)]);
  }
  return factorial(n) / den;
}

// Exact weights without GMP where they fit. A weight is a ratio of integers kept in
// 128 bits; when both parts are below 2^53 they are exact doubles, and their IEEE quotient
// is the double nearest to the exact ratio (never a tie: the ratio is either a double or
// not dyadic), as nearest_double rounds it, reduced or not. Anything larger is reduced to
// lowest terms and, if still too large, goes through GMP. (GMP here was about 0.25 ms of a
// 2.2 ms first scaled-Jacobian check of quad_h0.4_o2; reducing every weight by gcd, and
// multinomials in 128 bits per pair, were half of the set-up of a product after that:
// (tetrahedron 6 x 6) 0.86 -> 0.36 ms, (triangle 6 x 6) 71 -> 28 us, warm.)
__extension__ typedef unsigned __int128 U128;  // GCC and Clang

// n! / prod alpha_a!, or 0 when it does not fit 128 bits. Each step m * n / t is exact: m
// is then the multinomial of the indices so far.
U128 multinomial128(const MultiIndex& a, int dim) {
  U128 m = 1;
  unsigned n = 0;
  for (int c = 0; c <= dim; ++c)
    for (int t = 1; t <= a[static_cast<std::size_t>(c)]; ++t) {
      U128 x;
      if (__builtin_mul_overflow(m, static_cast<U128>(++n), &x)) return 0;
      m = x / static_cast<U128>(t);
    }
  return m;
}

// C(n, k) for 0 <= k <= n <= rows, each 0 where it does not fit 128 bits.
class PascalTriangle {
 public:
  explicit PascalTriangle(int rows) : c_(static_cast<std::size_t>((rows + 1) * (rows + 2) / 2)) {
    for (int n = 0; n <= rows; ++n) {
      at(n, 0) = at(n, n) = 1;
      for (int k = 1; k < n; ++k) {
        const U128 a = at(n - 1, k - 1), b = at(n - 1, k);
        U128 sum;
        at(n, k) = a == 0 || b == 0 || __builtin_add_overflow(a, b, &sum) ? 0 : sum;
      }
    }
  }
  U128 operator()(int n, int k) const { return c_[index(n, k)]; }

 private:
  static std::size_t index(int n, int k) { return static_cast<std::size_t>(n * (n + 1) / 2 + k); }
  U128& at(int n, int k) { return c_[index(n, k)]; }
  std::vector<U128> c_;
};

constexpr U128 kExactDoubles = U128(1) << 53;

U128 gcd128(U128 a, U128 b) {
  if ((a >> 64) == 0 && (b >> 64) == 0)  // the usual case: no 128-bit division
    return std::gcd(static_cast<std::uint64_t>(a), static_cast<std::uint64_t>(b));
  while (b != 0) {
    const U128 t = a % b;
    a = b;
    b = t;
  }
  return a;
}

// num / den > 0 (in lowest terms where said); den == 0 marks one that did not fit.
struct Fraction {
  U128 num = 1, den = 1;
};

Fraction ratio(U128 num, U128 den) {
  if (num == 0 || den == 0) return {0, 0};
  const U128 g = gcd128(num, den);
  return {num / g, den / g};
}

Fraction times(const Fraction& a, const Fraction& b) {
  if (a.den == 0 || b.den == 0) return {0, 0};
  const U128 g1 = gcd128(a.num, b.den), g2 = gcd128(b.num, a.den);
  Fraction r;
  if (__builtin_mul_overflow(a.num / g1, b.num / g2, &r.num) || __builtin_mul_overflow(a.den / g2, b.den / g1, &r.den))
    return {0, 0};
  return r;
}

// a b without reducing (den 0: it does not fit, or one of them did not).
Fraction unreduced_times(const Fraction& a, const Fraction& b) {
  Fraction r;
  if (a.den == 0 || b.den == 0 || __builtin_mul_overflow(a.num, b.num, &r.num) ||
      __builtin_mul_overflow(a.den, b.den, &r.den))
    return {0, 0};
  return r;
}

Fraction lowest_terms(const Fraction& w) { return w.den == 0 ? w : ratio(w.num, w.den); }

// The double nearest to w, or `exact()` (an mpq_class) rounded by GMP when w did not fit.
template <class Exact>
double nearest(const Fraction& w, Exact exact) {
  if (w.den != 0 && w.num <= kExactDoubles && w.den <= kExactDoubles)
    return static_cast<double>(w.num) / static_cast<double>(w.den);
  return nearest_double(exact());
}

int binomial_size(int dim, int degree) {
  long s = 1;
  for (int c = 1; c <= dim; ++c) s = s * (degree + c) / c;
  return static_cast<int>(s);
}

// Products with fewer coefficient pairs use the weighted-entry loop (measured, mu_bench).
constexpr long kEntryKernelBelow = 2048;

// Four lanes of interleaved coefficients (coefficient i of lane l at 4 i + l, as
// multiply4, multiply_add_sum2x4 and gram_sums2x4 take them): coefficient i's vector.
typedef double V4 __attribute__((vector_size(32)));
V4 lanes_at(const double* p, std::size_t i) {
  V4 v;
  std::memcpy(&v, p + 4 * i, sizeof v);
  return v;
}
void store_lanes(double* p, std::size_t i, V4 v) { std::memcpy(p + 4 * i, &v, sizeof v); }

}  // namespace

int bernstein_space_size(std::span<const FactorDegree> factors) noexcept {
  int s = 1;
  for (const FactorDegree& f : factors) s *= binomial_size(f.dim, f.degree);
  return s;
}

std::vector<FactorDegree> product_degrees(std::span<const FactorDegree> f,
                                          std::span<const FactorDegree> g) {
  QV_ASSERT(f.size() == g.size(), "factor counts " << f.size() << " vs " << g.size());
  std::vector<FactorDegree> h;
  for (std::size_t i = 0; i < f.size(); ++i) {
    QV_ASSERT(f[i].dim == g[i].dim, "factor " << i << " dims differ");
    h.push_back({f[i].dim, f[i].degree + g[i].degree});
  }
  return h;
}

BernsteinProduct::BernsteinProduct(std::vector<FactorDegree> f, std::vector<FactorDegree> g)
    : f_degrees_(std::move(f)), g_degrees_(std::move(g)) {
  QV_ASSERT(!f_degrees_.empty() && f_degrees_.size() <= 3, "1 to 3 factors");
  h_degrees_ = product_degrees(f_degrees_, g_degrees_);
  std::vector<Fraction> exact_w[3];  // the factor weights of entries_, exactly
  std::vector<MultiIndex> f_index[3], g_index[3], h_index_of[3];  // for GMP, where needed
  // A factor entry's weight mult(alpha_i) mult(alpha_j) / mult(alpha_k) in GMP.
  const auto gmp_weight = [&](std::size_t fac, const Entry& e) {
    const int d = f_degrees_[fac].dim;
    mpq_class w(multinomial(f_index[fac][static_cast<std::size_t>(e.i)], d) *
                    multinomial(g_index[fac][static_cast<std::size_t>(e.j)], d),
                multinomial(h_index_of[fac][static_cast<std::size_t>(e.k)], d));
    w.canonicalize();
    return w;
  };
  int fs = 1, gs = 1, hs = 1;
  for (std::size_t fac = 0; fac < 3; ++fac) {
    f_stride_[fac] = fs;
    g_stride_[fac] = gs;
    h_stride_[fac] = hs;
    if (fac >= f_degrees_.size()) {
      entries_[fac] = {{0, 0, 0, 1.0}};
      exact_w[fac] = {Fraction{}};
      continue;
    }
    const int d = f_degrees_[fac].dim;
    const int nu = f_degrees_[fac].degree, mu = g_degrees_[fac].degree;
    QV_ASSERT(nu >= 0 && mu >= 0, "negative degree");
    f_index[fac] = simplex_multi_indices(d, nu);
    g_index[fac] = simplex_multi_indices(d, mu);
    h_index_of[fac] = simplex_multi_indices(d, nu + mu);
    const auto& fi = f_index[fac];
    const auto& gi = g_index[fac];
    const auto& hi = h_index_of[fac];
    const MultiIndexTable h_index(hi, nu + mu);
    // Weight of (i, j): prod_a C(k_a, i_a) / C(nu + mu, nu) with k = i + j (B_i B_j =
    // that times B_k), an integer over the factor's one denominator: both are exact doubles
    // far beyond the degrees used, so their IEEE quotient is the nearest double to the
    // weight (never a tie: a ratio of integers below 2^53 is either a double or not
    // dyadic). Lowest terms and GMP only where a part is too large.
    const PascalTriangle binomial(nu + mu);
    const U128 den = binomial(nu + mu, nu);
    const bool small = den != 0 && den <= kExactDoubles;
    std::vector<int> terms(hi.size(), 0);
    entries_[fac].reserve(fi.size() * gi.size());
    exact_w[fac].reserve(fi.size() * gi.size());
    for (std::size_t i = 0; i < fi.size(); ++i)
      for (std::size_t j = 0; j < gi.size(); ++j) {
        MultiIndex k{};
        U128 num = 1;
        for (std::size_t a = 0; a < 4; ++a) {
          k[a] = fi[i][a] + gi[j][a];
          if (num != 0 && __builtin_mul_overflow(num, binomial(k[a], fi[i][a]), &num)) num = 0;
        }
        const int kk = h_index(k);  // k has degree nu + mu: components 1-3 place it
        QV_ASSERT(kk >= 0, "multi-index outside the product space");
        Entry e{static_cast<int>(i), static_cast<int>(j), kk, 0.0};
        const Fraction w = small && num != 0 ? Fraction{num, den} : ratio(num, den);
        e.w = small && num != 0 ? static_cast<double>(w.num) / static_cast<double>(w.den)
                                : nearest(w, [&] { return gmp_weight(fac, e); });
        entries_[fac].push_back(e);
        exact_w[fac].push_back(w);
        ++terms[static_cast<std::size_t>(kk)];
      }
    int most = 0;
    for (int t : terms) most = std::max(most, t);
    max_terms_ *= most;
    fs *= static_cast<int>(fi.size());
    gs *= static_cast<int>(gi.size());
    hs *= static_cast<int>(hi.size());
  }
  f_size_ = fs;
  g_size_ = gs;
  h_size_ = hs;
  // Small products: the grids' set-up costs more than the gathers (measured, mu_bench).
  entries_kernel_ = static_cast<long>(f_size_) * g_size_ < kEntryKernelBelow;
  if (entries_kernel_) {
    // Flattened entry kernel: every (i, j) pair with its exact tensor weight, by k (a
    // stable counting sort of the pairs in the order below).
    std::vector<std::pair<int, Pair>> by_k;
    by_k.reserve(static_cast<std::size_t>(f_size_) * static_cast<std::size_t>(g_size_));
    // The exact tensor weight w0 w1 w2, with w1 w2 formed once per (a1, a2) and the unit
    // weights of unused factors not multiplied at all (GMP products are most of the set-up).
    for (std::size_t a2 = 0; a2 < entries_[2].size(); ++a2)
      for (std::size_t a1 = 0; a1 < entries_[1].size(); ++a1) {
        const Fraction w12 = unreduced_times(exact_w[1][a1], exact_w[2][a2]);
        const bool unit = w12.den != 0 && w12.num == w12.den;
        for (std::size_t a0 = 0; a0 < entries_[0].size(); ++a0) {
          const Entry& e0 = entries_[0][a0];
          const Entry& e1 = entries_[1][a1];
          const Entry& e2 = entries_[2][a2];
          const int i = e0.i * f_stride_[0] + e1.i * f_stride_[1] + e2.i * f_stride_[2];
          const int j = e0.j * g_stride_[0] + e1.j * g_stride_[1] + e2.j * g_stride_[2];
          const int k = e0.k * h_stride_[0] + e1.k * h_stride_[1] + e2.k * h_stride_[2];
          const Fraction w012 = unit ? Fraction{} : unreduced_times(exact_w[0][a0], w12);
          const double w = unit ? e0.w
                           : w012.den != 0 && w012.den <= kExactDoubles
                               ? static_cast<double>(w012.num) / static_cast<double>(w012.den)
                               : nearest(times(lowest_terms(exact_w[0][a0]), lowest_terms(w12)), [&] {
            mpq_class exact = gmp_weight(0, e0);
            for (std::size_t fac = 1; fac < f_degrees_.size(); ++fac) exact *= gmp_weight(fac, fac == 1 ? e1 : e2);
            return exact;
          });
          by_k.push_back({k, {i, j, w}});
        }
      }
    row_start_.assign(static_cast<std::size_t>(h_size_) + 1, 0);
    for (const auto& [k, q] : by_k) ++row_start_[static_cast<std::size_t>(k) + 1];
    for (std::size_t k = 0; k < static_cast<std::size_t>(h_size_); ++k) row_start_[k + 1] += row_start_[k];
    pairs_.resize(by_k.size());
    std::vector<int> fill(row_start_.begin(), row_start_.end() - 1);
    for (const auto& [k, q] : by_k) pairs_[static_cast<std::size_t>(fill[static_cast<std::size_t>(k)]++)] = q;
    bool same_space = true;
    for (std::size_t fac = 0; fac < f_degrees_.size(); ++fac)
      same_space = same_space && f_degrees_[fac].degree == g_degrees_[fac].degree;
    if (same_space) {
      square_row_start_.push_back(0);
      for (std::size_t k = 0; k < static_cast<std::size_t>(h_size_); ++k) {
        const std::span<const Pair> r(pairs_.data() + row_start_[k], pairs_.data() + row_start_[k + 1]);
        std::size_t below = 0, diagonal = 0;
        for (const Pair& q : r) {
          if (q.i < q.j) {
            square_pairs_.push_back({q.i, q.j, 2 * q.w});  // exact: a power of two
            ++below;
          } else if (q.i == q.j) {
            square_pairs_.push_back(q);
            ++diagonal;
          }
        }
        QV_ASSERT(2 * below + diagonal == r.size(), "a product of one space is not symmetric");
        square_row_start_.push_back(static_cast<int>(square_pairs_.size()));
      }
    }
  }
}

void BernsteinProduct::build_grids() const {
  // Grids of the convolution kernel, all addressed with the strides of h's grid.
  std::array<int, 3> hdims{1, 1, 1};
  {
    int coord = 0;
    for (const FactorDegree& d : h_degrees_)
      for (int c = 0; c < d.dim; ++c) hdims[static_cast<std::size_t>(coord++)] = d.degree + 1;
  }
  h_cells_ = hdims[0] * hdims[1] * hdims[2];
  const auto make_grid = [&](const std::vector<FactorDegree>& deg, bool invert) {
    Grid grid;
    std::vector<std::vector<MultiIndex>> idx;
    // Per factor, each index's multinomial (0: beyond 128 bits), once: per cell they were
    // recomputed and multiplied as reduced fractions, 128-bit divisions that made half of
    // the set-up of a first scaled-Jacobian check (27-node hexahedron: 1.41 -> 0.72 ms).
    std::vector<std::vector<U128>> mult;
    for (const FactorDegree& d : deg) {
      idx.push_back(simplex_multi_indices(d.dim, d.degree));
      auto& m = mult.emplace_back();
      for (const MultiIndex& a : idx.back()) m.push_back(multinomial128(a, d.dim));
    }
    int size = 1;
    for (const auto& v : idx) size *= static_cast<int>(v.size());
    for (int i = 0; i < size; ++i) {
      int rest = i, c = 0;
      std::array<int, 3> pos{0, 0, 0};
      // alpha, the product of the factors' multinomials: an integer, exact in U128 unless
      // a factor did not fit or the product overflows (then alpha = 0 and GMP below).
      U128 alpha = 1;
      std::array<const MultiIndex*, 3> parts{};
      for (std::size_t f = 0; f < deg.size(); ++f) {
        const auto n = static_cast<int>(idx[f].size());
        const auto at = static_cast<std::size_t>(rest % n);
        const MultiIndex& a = idx[f][at];
        rest /= n;
        if (__builtin_mul_overflow(alpha, mult[f][at], &alpha)) alpha = 0;
        parts[f] = &a;
        for (int k = 1; k <= deg[f].dim; ++k) pos[static_cast<std::size_t>(c++)] = a[static_cast<std::size_t>(k)];
      }
      const auto exact_alpha = [&] {
        mpz_class m = 1;
        for (std::size_t f = 0; f < deg.size(); ++f) m *= multinomial(*parts[f], deg[f].dim);
        return m;
      };
      grid.offset.push_back(pos[0] + hdims[0] * (pos[1] + hdims[1] * pos[2]));
      const Fraction w = alpha == 0 ? Fraction{0, 0} : invert ? Fraction{1, alpha} : Fraction{alpha, 1};
      grid.scale.push_back(invert ? nearest(w, [&] { return mpq_class(mpz_class(1), exact_alpha()); })
                                  : nearest(w, [&] { return mpq_class(exact_alpha()); }));
    }
    // Runs: the valid cells of a row are a prefix (an index sum <= n per simplex factor);
    // consecutive rows merge into one run while at least half of its cells are valid
    // (whole planes of tensor grids; row by row for simplices, mostly padding otherwise).
    // Per row of h's grid, the (first, end) offsets of the grid's cells in it; {0, 0}: none
    // (a vector, not a map: first 27-node hexahedron's scaled Jacobian 0.61 -> 0.52 ms).
    std::vector<std::array<int, 2>> rows(static_cast<std::size_t>(h_cells_ / hdims[0]), std::array<int, 2>{0, 0});
    for (int off : grid.offset) {
      auto& span = rows[static_cast<std::size_t>(off / hdims[0])];
      span = span[1] == 0 ? std::array<int, 2>{off, off + 1} : std::array<int, 2>{std::min(span[0], off), std::max(span[1], off + 1)};
    }
    int valid = 0;
    for (const auto& span : rows) {
      if (span[1] == 0) continue;
      if (!grid.runs.empty()) {
        auto& last = grid.runs.back();
        const int merged = span[1] - last[0];
        if (2 * (valid + span[1] - span[0]) >= merged) {
          last[1] = merged;
          valid += span[1] - span[0];
          continue;
        }
      }
      grid.runs.push_back({span[0], span[1] - span[0]});
      valid = span[1] - span[0];
    }
    return grid;
  };
  f_grid_ = make_grid(f_degrees_, false);
  g_grid_ = make_grid(g_degrees_, false);
  h_grid_ = make_grid(h_degrees_, true);

  // The outer operand's rows (its coefficients in cell order, cut where a cell is skipped
  // or a row is full) and the inner operand's runs, spaced kRowBlock zeros apart.
  outer_is_g_ = f_size_ > g_size_;
  const Grid& outer = outer_is_g_ ? g_grid_ : f_grid_;
  const Grid& inner = outer_is_g_ ? f_grid_ : g_grid_;
  outer_order_.resize(outer.offset.size());
  std::iota(outer_order_.begin(), outer_order_.end(), 0);
  std::sort(outer_order_.begin(), outer_order_.end(),
            [&](int a, int b) { return outer.offset[static_cast<std::size_t>(a)] < outer.offset[static_cast<std::size_t>(b)]; });
  int row_end = 0;  // the cell just past the rows' last one
  for (std::size_t p = 0; p < outer_order_.size(); ++p) {
    const int cell = outer.offset[static_cast<std::size_t>(outer_order_[p])];
    Row* last = outer_rows_.empty() ? nullptr : &outer_rows_.back();
    if (last != nullptr && last->length < kRowBlock && cell == last->offset + last->length)
      ++last->length;
    else
      outer_rows_.push_back({static_cast<int>(p), 1, cell});
    row_end = std::max(row_end, cell + 1);
  }
  int guarded = kRowBlock, run_end = 0;
  for (const auto& [start, length] : inner.runs) {
    inner_runs_.push_back({start, length, guarded});
    guarded += length + kRowBlock;
    run_end = std::max(run_end, start + length);
  }
  guarded_size_ = guarded;
  inner_guarded_.resize(inner.offset.size());
  for (std::size_t j = 0; j < inner.offset.size(); ++j) {
    const int cell = inner.offset[j];
    const auto run = std::find_if(inner_runs_.begin(), inner_runs_.end(),
                                  [&](const Run& r) { return cell >= r.start && cell < r.start + r.length; });
    QV_ASSERT(run != inner_runs_.end(), "cell " << cell << " in no run");
    inner_guarded_[j] = run->guarded + (cell - run->start);
  }
  // A row of length R against a run writes R - 1 cells past the run's end (zeros there).
  acc_cells_ = std::max(h_cells_, row_end + kRowBlock - 1 + run_end);
}

namespace {

// d[x] += sum_{k < R} a[k] s[x - k] for x in [0, n + R - 1): one row of R outer
// coefficients at consecutive cells against a run of n inner ones, with R - 1 zeros before
// and after it in s. Each cell of d is loaded and stored once per row instead of once per
// coefficient. Every term a[k] s[x - k] is one product of the scaled form, summed with the
// others of its cell in another order: the same error bound (top of this file).
template <int R>
void convolve_row(const double* a, const double* __restrict s, int n, double* __restrict d) {
  for (int x = 0; x < n + R - 1; ++x) {
    double t = a[0] * s[x];
#pragma GCC unroll 8
    for (int k = 1; k < R; ++k) t += a[k] * s[x - k];
    d[x] += t;
  }
}

}  // namespace

void BernsteinProduct::accumulate_grid(const double* f, const double* g, double scale,
                                       double* acc) const {
  // The inner operand, scaled, is copied run by run with kRowBlock zeros between runs;
  // each row of the outer operand's scaled coefficients (times scale) is then convolved
  // with every run, into acc at the row's cell.
  thread_local std::vector<double> guarded;
  const Grid& outer = outer_is_g_ ? g_grid_ : f_grid_;
  const Grid& inner = outer_is_g_ ? f_grid_ : g_grid_;
  const double* ov = outer_is_g_ ? g : f;
  const double* iv = outer_is_g_ ? f : g;
  guarded.assign(static_cast<std::size_t>(guarded_size_), 0.0);
  for (std::size_t j = 0; j < inner_guarded_.size(); ++j)
    guarded[static_cast<std::size_t>(inner_guarded_[j])] = inner.scale[j] * iv[j];
  for (const Row& row : outer_rows_) {
    std::array<double, kRowBlock> a;
    bool zero = true;
    for (int k = 0; k < row.length; ++k) {
      const auto i = static_cast<std::size_t>(outer_order_[static_cast<std::size_t>(row.first + k)]);
      a[static_cast<std::size_t>(k)] = (scale * outer.scale[i]) * ov[i];
      zero = zero && a[static_cast<std::size_t>(k)] == 0;
    }
    if (zero) continue;
    double* dst = acc + row.offset;
    for (const Run& run : inner_runs_) {
      const double* s = guarded.data() + run.guarded;
      double* d = dst + run.start;
      switch (row.length) {
        case 1: convolve_row<1>(a.data(), s, run.length, d); break;
        case 2: convolve_row<2>(a.data(), s, run.length, d); break;
        case 3: convolve_row<3>(a.data(), s, run.length, d); break;
        case 4: convolve_row<4>(a.data(), s, run.length, d); break;
        case 5: convolve_row<5>(a.data(), s, run.length, d); break;
        case 6: convolve_row<6>(a.data(), s, run.length, d); break;
        case 7: convolve_row<7>(a.data(), s, run.length, d); break;
        default: convolve_row<8>(a.data(), s, run.length, d); break;
      }
    }
  }
}

// (Two interleaved partial sums per row, to halve the chain of dependent additions, were
// no faster: folded quartic triangles' scaled Jacobian 9.0-9.1 vs 9.1-9.3 us per element,
// alternating runs. The loop is bound by its indexed loads.)
// The entry kernel for N terms in one walk over the pairs: per pair, the N scaled products
// summed (N + 1 roundings deep), times the pair's weight, then the row's sum. Within
// rounding(N): with the weight's own rounding, N + 3 per pair plus the row's max_terms
// and the addition into h, at most N * max_terms + 16; and the weights of a row sum to 1,
// so the magnitude is at most sum_t |scale_t| max|f_t| max|g_t|, as for N separate walks.
// The rows of squares (f_t == g_t) hold the same sums in fewer pairs, each with the same
// roundings (a doubled weight is exact): within rounding(N) as well.
template <std::size_t N>
void BernsteinProduct::fused_entries(std::span<const Term> terms, const std::vector<int>& row_start,
                                     const std::vector<Pair>& pair_list, double* h) const {
  std::array<double, N> sc;
  std::array<const double*, N> f, g;
  for (std::size_t t = 0; t < N; ++t) {
    sc[t] = terms[t].scale;
    f[t] = terms[t].f;
    g[t] = terms[t].g;
  }
  const Pair* pairs = pair_list.data();
  for (int k = 0; k < h_size_; ++k) {
    double acc = 0;
    for (int p = row_start[static_cast<std::size_t>(k)]; p < row_start[static_cast<std::size_t>(k) + 1]; ++p) {
      const int i = pairs[p].i, j = pairs[p].j;
      if constexpr (N == 1) {
        acc += pairs[p].w * (f[0][i] * g[0][j]);  // as multiply_add: scaled once per row
      } else {
        double sum = 0;
        for (std::size_t t = 0; t < N; ++t) sum += sc[t] * (f[t][i] * g[t][j]);
        acc += pairs[p].w * sum;
      }
    }
    h[k] += N == 1 ? sc[0] * acc : acc;
  }
}

template <int Columns, int Coordinates>
void BernsteinProduct::gram_entries(const double* const* w, double* const* h) const {
  // Lane e of a pair's sum is entry e's sum_x w[3 a_e + x](i) w[3 b_e + x](j): per
  // coefficient, its values laid out once as the vectors (x < Coordinates) of the a_e side
  // and those of the b_e side, so that a pair costs a vector product and a sum per x. The
  // entries fill vectors of at most the native width (native_lanes.hpp): 2 columns' 3
  // entries one vector of 4; 3 columns' 6 one of 8 with AVX-512, else two of 4 (a vector of
  // 8 there was kept in memory and moved through integer registers; mu on AVX2, one thread:
  // warped_hexahedron_o2 1.84 -> 1.33 ms, warped_prism_o2 4.0 -> 3.46 ms).
  constexpr std::size_t kEntries = Columns * (Columns + 1) / 2;
  constexpr int kWidth = Columns == 2 ? 4 : kNativeLanes;
  constexpr std::size_t kParts = (kEntries + kWidth - 1) / kWidth;  // vectors per side and x
  static_assert(kParts <= 2);
  using V = typename LaneVector<kWidth>::Type;
  constexpr std::size_t kX = Coordinates;
  const auto entry = [](std::size_t e) { return Columns == 3 ? kGramEntries3[e] : kGramEntries2[e % 3]; };
  thread_local std::vector<V> side_a, side_b;  // (coefficient i, part, x) at (i kParts + part) kX + x
  const auto n = static_cast<std::size_t>(f_size_);
  side_a.assign(kParts * kX * n, V{});
  side_b.assign(kParts * kX * n, V{});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t x = 0; x < kX; ++x)
      for (std::size_t e = 0; e < kEntries; ++e) {
        const std::size_t at = (i * kParts + e / kWidth) * kX + x;
        side_a[at][e % kWidth] = w[3 * static_cast<std::size_t>(entry(e)[0]) + x][i];
        side_b[at][e % kWidth] = w[3 * static_cast<std::size_t>(entry(e)[1]) + x][i];
      }
  // As fused_entries<3> with scales 1 (exact): the same roundings in the same order.
  const auto dot = [](const V* a, const V* b) {
    V sum = a[0] * b[0] + a[1] * b[1];
    if constexpr (kX == 3) sum = sum + a[2] * b[2];
    return sum;
  };
  const Pair* pairs = pairs_.data();
  for (int k = 0; k < h_size_; ++k) {
    V acc0{}, acc1{};  // parts 0 and 1 (named: an array of vectors was kept in memory)
    for (int p = row_start_[static_cast<std::size_t>(k)]; p < row_start_[static_cast<std::size_t>(k) + 1]; ++p) {
      const V* x = side_a.data() + kParts * kX * static_cast<std::size_t>(pairs[p].i);
      const V* y = side_b.data() + kParts * kX * static_cast<std::size_t>(pairs[p].j);
      acc0 += pairs[p].w * dot(x, y);
      if constexpr (kParts == 2) acc1 += pairs[p].w * dot(x + kX, y + kX);
    }
    for (std::size_t e = 0; e < kEntries; ++e) h[e][k] += e < kWidth ? acc0[e % kWidth] : acc1[e % kWidth];
  }
}

bool BernsteinProduct::gram_sums(const double* const* w, int columns, double* const* h, int coordinates) const {
  QV_ASSERT(std::equal(f_degrees_.begin(), f_degrees_.end(), g_degrees_.begin(), g_degrees_.end(),
                       [](const FactorDegree& a, const FactorDegree& b) { return a.dim == b.dim && a.degree == b.degree; }),
            "Gram sums of a product of two spaces");
  QV_ASSERT(coordinates == 2 || coordinates == 3, coordinates << " coordinates");
  if (!entries_kernel_ || pairs_.empty()) return false;
  if (columns == 3 && coordinates == 3)
    gram_entries<3, 3>(w, h);
  else if (columns == 3)
    gram_entries<3, 2>(w, h);
  else if (columns == 2 && coordinates == 3)
    gram_entries<2, 3>(w, h);
  else if (columns == 2)
    gram_entries<2, 2>(w, h);
  else
    return false;
  return true;
}

bool BernsteinProduct::gram_sums2x4(const double* const* w, double* const* h) const {
  if (!entries_kernel_ || pairs_.empty()) return false;
  // gram_entries<2, 2>'s rows, lane by lane: per entry (a, b), sum_x a_x(i) b_x(j).
  const Pair* pairs = pairs_.data();
  for (int k = 0; k < h_size_; ++k) {
    V4 acc[3] = {};
    for (int p = row_start_[static_cast<std::size_t>(k)]; p < row_start_[static_cast<std::size_t>(k) + 1]; ++p) {
      const auto i = static_cast<std::size_t>(pairs[p].i), j = static_cast<std::size_t>(pairs[p].j);
      for (std::size_t e = 0; e < 3; ++e) {
        const auto [a, b] = kGramEntries2[e];
        acc[e] += pairs[p].w * (lanes_at(w[2 * a], i) * lanes_at(w[2 * b], j) + lanes_at(w[2 * a + 1], i) * lanes_at(w[2 * b + 1], j));
      }
    }
    for (std::size_t e = 0; e < 3; ++e)
      store_lanes(h[e], static_cast<std::size_t>(k), lanes_at(h[e], static_cast<std::size_t>(k)) + acc[e]);
  }
  return true;
}

void BernsteinProduct::multiply_add_sum(std::span<const Term> terms, double* h) const {
  if (entries_kernel_) {
    const bool squares = !square_pairs_.empty() &&
                         std::all_of(terms.begin(), terms.end(), [](const Term& t) { return t.f == t.g; });
    if (squares) {
      if (terms.size() == 1) return fused_entries<1>(terms, square_row_start_, square_pairs_, h);
      if (terms.size() == 2) return fused_entries<2>(terms, square_row_start_, square_pairs_, h);
      if (terms.size() == 3) return fused_entries<3>(terms, square_row_start_, square_pairs_, h);
      if (terms.size() == 6) return fused_entries<6>(terms, square_row_start_, square_pairs_, h);
    }
    if (!pairs_.empty() && terms.size() == 2) return fused_entries<2>(terms, row_start_, pairs_, h);
    if (!pairs_.empty() && terms.size() == 3) return fused_entries<3>(terms, row_start_, pairs_, h);
    for (const Term& t : terms) multiply_add(t.f, t.g, t.scale, h);
    return;
  }
  std::call_once(grids_once_, [this] { build_grids(); });
  thread_local std::vector<double> acc;
  acc.assign(static_cast<std::size_t>(acc_cells_), 0.0);
  for (const Term& t : terms) accumulate_grid(t.f, t.g, t.scale, acc.data());
  for (int k = 0; k < h_size_; ++k)
    h[k] += acc[static_cast<std::size_t>(h_grid_.offset[static_cast<std::size_t>(k)])] * h_grid_.scale[static_cast<std::size_t>(k)];
}

void BernsteinProduct::multiply_add(const double* f, const double* g, double scale,
                                    double* h) const {
  if (!entries_kernel_) {
    const Term t{scale, f, g};
    multiply_add_sum(std::span<const Term>(&t, 1), h);
    return;
  }
  if (pairs_.empty()) {  // a large product switched to the entry loop (tests)
    for (const Entry& e2 : entries_[2]) {
      const int f2 = e2.i * f_stride_[2], g2 = e2.j * g_stride_[2], h2 = e2.k * h_stride_[2];
      for (const Entry& e1 : entries_[1]) {
        const double w12 = scale * (e2.w * e1.w);
        const int f1 = f2 + e1.i * f_stride_[1], g1 = g2 + e1.j * g_stride_[1];
        double* h1 = h + h2 + e1.k * h_stride_[1];
        const double* fp = f + f1;
        const double* gp = g + g1;
        for (const Entry& e0 : entries_[0]) h1[e0.k] += (w12 * e0.w) * (fp[e0.i] * gp[e0.j]);
      }
    }
    return;
  }
  // Per term w (rounded once) * (f_i g_j): 2 roundings, the row's sum, times scale and
  // added into h: within the 16 + terms roundings of rounding() (top of this file).
  const Pair* pairs = pairs_.data();
  for (int k = 0; k < h_size_; ++k) {
    double acc = 0;
    for (int p = row_start_[static_cast<std::size_t>(k)]; p < row_start_[static_cast<std::size_t>(k) + 1]; ++p)
      acc += pairs[p].w * (f[pairs[p].i] * g[pairs[p].j]);
    h[k] += scale * acc;
  }
}

void BernsteinProduct::multiply(const double* f, const double* g, double* h) const {
  std::fill(h, h + h_size_, 0.0);
  multiply_add(f, g, 1.0, h);
}

bool BernsteinProduct::multiply4(const double* f, const double* g, double* h) const {
  if (!entries_kernel_ || pairs_.empty()) return false;
  // multiply_add's rows, lane by lane: acc summed in the same order, then 0 + 1 * acc.
  const Pair* pairs = pairs_.data();
  for (int k = 0; k < h_size_; ++k) {
    V4 acc{};
    for (int p = row_start_[static_cast<std::size_t>(k)]; p < row_start_[static_cast<std::size_t>(k) + 1]; ++p)
      acc += pairs[p].w * (lanes_at(f, static_cast<std::size_t>(pairs[p].i)) * lanes_at(g, static_cast<std::size_t>(pairs[p].j)));
    store_lanes(h, static_cast<std::size_t>(k), V4{} + 1.0 * acc);
  }
  return true;
}

bool BernsteinProduct::multiply_add_sum2x4(double s0, const double* f0, const double* g0, double s1,
                                           const double* f1, const double* g1, double* h) const {
  QV_ASSERT(f0 != g0 || f1 != g1, "sums of squares take other rows");
  if (!entries_kernel_ || pairs_.empty()) return false;
  // fused_entries<2>'s rows, lane by lane.
  const Pair* pairs = pairs_.data();
  for (int k = 0; k < h_size_; ++k) {
    V4 acc{};
    for (int p = row_start_[static_cast<std::size_t>(k)]; p < row_start_[static_cast<std::size_t>(k) + 1]; ++p) {
      const auto i = static_cast<std::size_t>(pairs[p].i), j = static_cast<std::size_t>(pairs[p].j);
      V4 sum{};
      sum += s0 * (lanes_at(f0, i) * lanes_at(g0, j));
      sum += s1 * (lanes_at(f1, i) * lanes_at(g1, j));
      acc += pairs[p].w * sum;
    }
    store_lanes(h, static_cast<std::size_t>(k), lanes_at(h, static_cast<std::size_t>(k)) + acc);
  }
  return true;
}

double BernsteinProduct::rounding(int products) const noexcept {
  // Entry kernel, per term: weight (2u allowed; nearest_double is within u), two weight
  // products, scale, f*g and the term product: 8 roundings; scaled form: 12 (see the top
  // of this file); then a sum of products * max_terms terms.
  return rounding_gamma(products * max_terms_ + 16) * 1.01;
}

const BernsteinProduct& bernstein_product(std::span<const FactorDegree> f,
                                          std::span<const FactorDegree> g) {
  using Key = std::vector<std::tuple<int, int, int>>;
  static std::mutex mutex;
  static std::map<Key, std::unique_ptr<const BernsteinProduct>> cache;
  QV_ASSERT(f.size() == g.size(), "factor counts differ");
  Key key;
  for (std::size_t i = 0; i < f.size(); ++i) key.emplace_back(f[i].dim, f[i].degree, g[i].degree);
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[key];
  if (!slot)
    slot = std::make_unique<const BernsteinProduct>(std::vector<FactorDegree>(f.begin(), f.end()),
                                                    std::vector<FactorDegree>(g.begin(), g.end()));
  return *slot;
}

double bernstein_triple_product(std::span<const FactorDegree> f_deg, const double* f,
                                std::span<const FactorDegree> g_deg, const double* g,
                                std::span<const FactorDegree> k_deg, const double* k,
                                std::vector<double>& scratch, double* out) {
  const BernsteinProduct& fg = bernstein_product(f_deg, g_deg);
  const auto fg_deg = product_degrees(f_deg, g_deg);
  const BernsteinProduct& fgk = bernstein_product(fg_deg, k_deg);
  scratch.resize(static_cast<std::size_t>(fg.h_size()));
  fg.multiply(f, g, scratch.data());
  fgk.multiply(scratch.data(), k, out);
  return triple_product_rounding(fg, fgk);
}

double triple_product_rounding(const BernsteinProduct& fg, const BernsteinProduct& fgk) {
  // |fg~ - fg| <= r1 F G, so |fg~| <= (1 + r1) F G; then r2 on the second product.
  const double r1 = fg.rounding(1), r2 = fgk.rounding(1);
  return (r1 + r2 * (1 + r1)) * 1.01;
}

}  // namespace quadval
