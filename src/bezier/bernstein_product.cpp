// Bernstein products (thesis, Paper V Prop. 4): per-factor tables of (i, j, k, weight),
// applied as a tensor product of the factor tables. Weights are exact rationals rounded
// once to double.
#include "bezier/bernstein_product.hpp"

#include <gmpxx.h>

#include <map>
#include <memory>
#include <mutex>
#include <tuple>

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

// The double nearest to q (within one ulp): the truncated value plus its truncated remainder.
double nearest(const mpq_class& q) {
  const double d = q.get_d();
  return d + mpq_class(q - mpq_class(d)).get_d();
}

int binomial_size(int dim, int degree) {
  long s = 1;
  for (int c = 1; c <= dim; ++c) s = s * (degree + c) / c;
  return static_cast<int>(s);
}

}  // namespace

std::vector<std::array<int, 4>> simplex_multi_indices(int d, int n) {
  // Same enumeration as BernsteinSimplex (src/bezier/bernstein_simplex.cpp): the last
  // barycentric index slowest, alpha_0 = n - the others.
  std::vector<MultiIndex> out;
  if (d == 1) {
    for (int i = 0; i <= n; ++i) out.push_back({n - i, i, 0, 0});
  } else if (d == 2) {
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i + j <= n; ++i) out.push_back({n - i - j, i, j, 0});
  } else {
    for (int k = 0; k <= n; ++k)
      for (int j = 0; j + k <= n; ++j)
        for (int i = 0; i + j + k <= n; ++i) out.push_back({n - i - j - k, i, j, k});
  }
  return out;
}

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
  int fs = 1, gs = 1, hs = 1;
  for (std::size_t fac = 0; fac < 3; ++fac) {
    f_stride_[fac] = fs;
    g_stride_[fac] = gs;
    h_stride_[fac] = hs;
    if (fac >= f_degrees_.size()) {
      entries_[fac] = {{0, 0, 0, 1.0}};
      continue;
    }
    const int d = f_degrees_[fac].dim;
    const int nu = f_degrees_[fac].degree, mu = g_degrees_[fac].degree;
    QV_ASSERT(nu >= 0 && mu >= 0, "negative degree");
    const auto fi = simplex_multi_indices(d, nu);
    const auto gi = simplex_multi_indices(d, mu);
    const auto hi = simplex_multi_indices(d, nu + mu);
    std::map<MultiIndex, int> h_index;
    for (std::size_t k = 0; k < hi.size(); ++k) h_index[hi[k]] = static_cast<int>(k);
    std::vector<int> terms(hi.size(), 0);
    for (std::size_t i = 0; i < fi.size(); ++i)
      for (std::size_t j = 0; j < gi.size(); ++j) {
        MultiIndex k{};
        for (std::size_t a = 0; a < 4; ++a) k[a] = fi[i][a] + gi[j][a];
        const int kk = h_index.at(k);
        const mpq_class w(multinomial(fi[i], d) * multinomial(gi[j], d), multinomial(k, d));
        entries_[fac].push_back({static_cast<int>(i), static_cast<int>(j), kk, nearest(mpq_class(w))});
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
  // Grids of the convolution kernel.
  const auto make_grid = [&](const std::vector<FactorDegree>& deg, bool invert) {
    Grid grid;
    int coord = 0;
    std::vector<std::vector<MultiIndex>> idx;
    for (const FactorDegree& d : deg) {
      for (int c = 0; c < d.dim; ++c) grid.dims[static_cast<std::size_t>(coord++)] = d.degree + 1;
      idx.push_back(simplex_multi_indices(d.dim, d.degree));
    }
    int size = 1;
    for (const auto& v : idx) size *= static_cast<int>(v.size());
    const int d0 = grid.dims[0], d1 = grid.dims[1];
    for (int i = 0; i < size; ++i) {
      int rest = i, c = 0;
      std::array<int, 3> pos{0, 0, 0};
      mpz_class alpha = 1;
      for (std::size_t f = 0; f < deg.size(); ++f) {
        const auto n = static_cast<int>(idx[f].size());
        const MultiIndex& a = idx[f][static_cast<std::size_t>(rest % n)];
        rest /= n;
        alpha *= multinomial(a, deg[f].dim);
        for (int k = 1; k <= deg[f].dim; ++k) pos[static_cast<std::size_t>(c++)] = a[static_cast<std::size_t>(k)];
      }
      grid.cell.push_back(pos[0] + d0 * (pos[1] + d1 * pos[2]));
      grid.scale.push_back(invert ? nearest(mpq_class(mpz_class(1), alpha)) : nearest(mpq_class(alpha)));
    }
    // Valid cells of a row form a prefix along coordinate 0 (sum of a factor's indices <= n).
    grid.row_len.assign(static_cast<std::size_t>(grid.dims[1] * grid.dims[2]), 0);
    for (int cell : grid.cell) {
      const int r = cell / d0;
      grid.row_len[static_cast<std::size_t>(r)] = std::max(grid.row_len[static_cast<std::size_t>(r)], cell % d0 + 1);
    }
    for (int r = 0; r < static_cast<int>(grid.row_len.size()); ++r)
      if (grid.row_len[static_cast<std::size_t>(r)] > 0)
        grid.rows.push_back({r % grid.dims[1], r / grid.dims[1], grid.row_len[static_cast<std::size_t>(r)]});
    return grid;
  };
  f_grid_ = make_grid(f_degrees_, false);
  g_grid_ = make_grid(g_degrees_, false);
  h_grid_ = make_grid(h_degrees_, true);
  // Small products: the grids' set-up costs more than the gathers (measured, mu_bench).
  entries_kernel_ = static_cast<long>(f_size_) * g_size_ < 2048;
}

void BernsteinProduct::multiply_add_grid(const double* f, const double* g, double scale,
                                         double* h) const {
  thread_local std::vector<double> gs, acc;
  const auto& gd = g_grid_.dims;
  const auto& hd = h_grid_.dims;
  gs.assign(static_cast<std::size_t>(gd[0] * gd[1] * gd[2]), 0.0);
  acc.assign(static_cast<std::size_t>(hd[0] * hd[1] * hd[2]), 0.0);
  for (int j = 0; j < g_size_; ++j)
    gs[static_cast<std::size_t>(g_grid_.cell[static_cast<std::size_t>(j)])] = g_grid_.scale[static_cast<std::size_t>(j)] * g[j];
  const int f0 = f_grid_.dims[0], f1 = f_grid_.dims[1];
  const int g0 = gd[0], g1 = gd[1];
  const int h0 = hd[0], h1 = hd[1];
  for (int i = 0; i < f_size_; ++i) {
    const double a = (scale * f_grid_.scale[static_cast<std::size_t>(i)]) * f[i];
    if (a == 0) continue;
    const int cell = f_grid_.cell[static_cast<std::size_t>(i)];
    const int i0 = cell % f0, i1 = (cell / f0) % f1, i2 = cell / (f0 * f1);
    double* hbase = acc.data() + i0 + h0 * (i1 + h1 * i2);
    for (const auto& [j1, j2, len] : g_grid_.rows) {
      const double* grow = gs.data() + g0 * (j1 + g1 * j2);
      double* hrow = hbase + h0 * (j1 + h1 * j2);
      for (int j0 = 0; j0 < len; ++j0) hrow[j0] += a * grow[j0];
    }
  }
  for (int k = 0; k < h_size_; ++k)
    h[k] += acc[static_cast<std::size_t>(h_grid_.cell[static_cast<std::size_t>(k)])] * h_grid_.scale[static_cast<std::size_t>(k)];
}

void BernsteinProduct::multiply_add(const double* f, const double* g, double scale,
                                    double* h) const {
  if (!entries_kernel_) {
    multiply_add_grid(f, g, scale, h);
    return;
  }
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
}

void BernsteinProduct::multiply(const double* f, const double* g, double* h) const {
  std::fill(h, h + h_size_, 0.0);
  multiply_add(f, g, 1.0, h);
}

double BernsteinProduct::rounding(int products) const noexcept {
  // Per term: weight (2u, nearest() may miss by one ulp), two weight products, scale,
  // f*g and the term product: 8 roundings; then a sum of products * max_terms terms.
  // Scaled convolution: f scale (2u) times scale and f (2u), g scale (2u)
  // times g (u), the term (u), h scale (2u) and its product (u), the final sum into h (u):
  // at most 16 roundings per term, relative to the same convex weights.
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
  // |fg~ - fg| <= r1 F G, so |fg~| <= (1 + r1) F G; then r2 on the second product.
  const double r1 = fg.rounding(1), r2 = fgk.rounding(1);
  return (r1 + r2 * (1 + r1)) * 1.01;
}

}  // namespace quadval
