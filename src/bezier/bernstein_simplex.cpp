// Bernstein polynomials on a unit simplex: multi-indices, evaluation, the exact
// Lagrange-to-Bézier matrix and the exact midpoint-subdivision matrices.
// Thesis, Paper III §4.1-4.3 (eqs. 14, 18-20).
#include <gmpxx.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "bezier/bezier_exact.hpp"
#include "bezier/rational_rounding.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

using MultiIndex = std::array<int, 4>;


mpz_class factorial(int n) {
  mpz_class f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

// n! / prod alpha_a!
mpz_class multinomial(int d, const MultiIndex& a) {
  int n = 0;
  for (int c = 0; c <= d; ++c) n += a[static_cast<std::size_t>(c)];
  mpz_class r = factorial(n);
  for (int c = 0; c <= d; ++c) r /= factorial(a[static_cast<std::size_t>(c)]);
  return r;
}

// Inverse of a square rational matrix by Gauss-Jordan elimination (exact).
std::vector<mpq_class> invert(std::vector<mpq_class> a, int n) {
  const auto at = [n](int r, int c) { return static_cast<std::size_t>(r) * n + c; };
  std::vector<mpq_class> inv(static_cast<std::size_t>(n) * n, mpq_class(0));
  for (int i = 0; i < n; ++i) inv[at(i, i)] = 1;
  for (int col = 0; col < n; ++col) {
    int pivot = col;
    while (pivot < n && sgn(a[at(pivot, col)]) == 0) ++pivot;
    QV_ASSERT(pivot < n, "singular Bernstein collocation matrix");
    if (pivot != col) {
      for (int c = 0; c < n; ++c) {
        std::swap(a[at(pivot, c)], a[at(col, c)]);
        std::swap(inv[at(pivot, c)], inv[at(col, c)]);
      }
    }
    const mpq_class p = a[at(col, col)];
    for (int c = 0; c < n; ++c) {
      a[at(col, c)] /= p;
      inv[at(col, c)] /= p;
    }
    for (int r = 0; r < n; ++r) {
      if (r == col || sgn(a[at(r, col)]) == 0) continue;
      const mpq_class f = a[at(r, col)];
      for (int c = 0; c < n; ++c) {
        if (sgn(a[at(col, c)]) != 0) a[at(r, c)] -= f * a[at(col, c)];
        if (sgn(inv[at(col, c)]) != 0) inv[at(r, c)] -= f * inv[at(col, c)];
      }
    }
  }
  return inv;
}

// V[k][alpha] = B_alpha(point k), points beta / den (eq. 18).
template <class PointOf>
std::vector<mpq_class> collocation(int dim, const std::vector<MultiIndex>& alphas, PointOf point_of,
                                   int den) {
  const auto n = alphas.size();
  std::vector<mpq_class> v(n * n);
  for (std::size_t k = 0; k < n; ++k) {
    const MultiIndex beta = point_of(static_cast<int>(k));
    for (std::size_t i = 0; i < n; ++i) {
      const MultiIndex& alpha = alphas[i];
      mpq_class b(multinomial(dim, alpha));
      for (int a = 0; a <= dim; ++a) {
        mpq_class l(beta[static_cast<std::size_t>(a)], den);
        l.canonicalize();  // gmpxx does not reduce a num/den pair
        for (int e = 0; e < alpha[static_cast<std::size_t>(a)]; ++e) b *= l;
      }
      v[k * n + i] = b;
    }
  }
  return v;
}

// Transposes square blocks of size n*n.
std::vector<double> transpose_blocks(const std::vector<double>& m, std::size_t n) {
  std::vector<double> t(m.size());
  for (std::size_t b = 0; b < m.size(); b += n * n)
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t c = 0; c < n; ++c) t[b + c * n + r] = m[b + r * n + c];
  return t;
}

// Children of the midpoint subdivision, vertices as barycentric coordinates times 2.
std::vector<std::array<MultiIndex, 4>> midpoint_children(int d) {
  const auto vertex = [](int a) {
    MultiIndex v{0, 0, 0, 0};
    v[static_cast<std::size_t>(a)] = 2;
    return v;
  };
  const auto mid = [](int a, int b) {
    MultiIndex v{0, 0, 0, 0};
    v[static_cast<std::size_t>(a)] = 1;
    v[static_cast<std::size_t>(b)] = 1;
    return v;
  };
  const MultiIndex z{0, 0, 0, 0};
  if (d == 1) return {{vertex(0), mid(0, 1), z, z}, {mid(0, 1), vertex(1), z, z}};
  if (d == 2)
    return {{vertex(0), mid(0, 1), mid(0, 2), z},
            {mid(0, 1), vertex(1), mid(1, 2), z},
            {mid(0, 2), mid(1, 2), vertex(2), z},
            {mid(1, 2), mid(0, 2), mid(0, 1), z}};
  return {{vertex(0), mid(0, 1), mid(0, 2), mid(0, 3)},
          {mid(0, 1), vertex(1), mid(1, 2), mid(1, 3)},
          {mid(0, 2), mid(1, 2), vertex(2), mid(2, 3)},
          {mid(0, 3), mid(1, 3), mid(2, 3), vertex(3)},
          // the octahedron, cut along its diagonal m02-m13
          {mid(0, 2), mid(1, 3), mid(0, 1), mid(1, 2)},
          {mid(0, 2), mid(1, 3), mid(1, 2), mid(2, 3)},
          {mid(0, 2), mid(1, 3), mid(2, 3), mid(0, 3)},
          {mid(0, 2), mid(1, 3), mid(0, 3), mid(0, 1)}};
}

}  // namespace

std::vector<std::array<int, 4>> simplex_multi_indices(int d, int n) {
  std::vector<std::array<int, 4>> out;
  if (d == 0) {
    out.push_back({n, 0, 0, 0});
  } else if (d == 1) {
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

BernsteinSimplex::BernsteinSimplex(int dim, int degree)
    : dim_(dim), degree_(degree), exact_(std::make_unique<Exact>()) {
  QV_ASSERT(dim >= 1 && dim <= 3 && degree >= 0, "dim " << dim << " degree " << degree);
  alphas_ = simplex_multi_indices(dim, degree);
  const int s = size();
  QV_ASSERT(s <= 500, "Bernstein factor too large: " << s);
  const auto n_sz = static_cast<std::size_t>(s);
  vertex_.assign(n_sz, false);
  for (int i = 0; i < s; ++i)
    for (int a = 0; a <= dim; ++a)
      if (alphas_[static_cast<std::size_t>(i)][static_cast<std::size_t>(a)] == degree)
        vertex_[static_cast<std::size_t>(i)] = true;

  QV_ASSERT(degree <= 60, "degree too high for exact dyadic subdivision: " << degree);
  children_ = midpoint_children(dim);
}

void BernsteinSimplex::build_subdivision() const {
  // Built on first use: a check whose elements all pass at the first Bézier stage never
  // subdivides (9,647 quadratic tetrahedra: 0.15 ms of a 2 ms check were this).
  std::call_once(subdivision_once_, [this] {
    const int dim = dim_, degree = degree_, s = size();
    const auto n_sz = static_cast<std::size_t>(s);
    // Subdivision (eq. 20) by blossoming: the child's coefficient beta is the blossom of the
    // parent at (w_0 repeated beta_0 times, ..., w_d repeated beta_d times), i.e. the
    // coefficient of t^alpha in prod_k (w_k . t)^beta_k times the parent's b_alpha.
    // With w in halves, the integer numerators sum to 2^n per row. The product is expanded
    // densely over monomial codes (sum_a m_a base^a) in 64-bit integers: every partial
    // product has nonnegative coefficients summing to 2^(factors so far) <= 2^60, so no
    // overflow, and the final ones (< 2^53, checked) are exact in double. The exact rational
    // copies are made only when the exact fallback asks for them (build_to_bezier).
    const int base = degree + 1;
    std::array<int, 4> place{1, 0, 0, 0};  // base^a
    for (int a = 1; a <= dim; ++a) place[static_cast<std::size_t>(a)] = place[static_cast<std::size_t>(a - 1)] * base;
    const int codes = place[static_cast<std::size_t>(dim)] * base;
    std::vector<int> index_of(static_cast<std::size_t>(codes), -1);
    const auto code = [&](const MultiIndex& a) {
      int c = 0;
      for (int x = 0; x <= dim; ++x) c += a[static_cast<std::size_t>(x)] * place[static_cast<std::size_t>(x)];
      return c;
    };
    for (int i = 0; i < s; ++i) index_of[static_cast<std::size_t>(code(alphas_[static_cast<std::size_t>(i)]))] = i;
    const double scale = std::ldexp(1.0, -degree);
    subdivision_.assign(children_.size() * n_sz * n_sz, 0.0);
    std::vector<std::int64_t> poly(static_cast<std::size_t>(codes), 0), next(poly.size(), 0);
    std::vector<int> live, next_live;
    for (std::size_t q = 0; q < children_.size(); ++q) {
      for (int r = 0; r < s; ++r) {
        const MultiIndex& beta = alphas_[static_cast<std::size_t>(r)];
        live.assign(1, 0);
        poly[0] = 1;
        for (int k = 0; k <= dim; ++k) {
          const auto& w = children_[q][static_cast<std::size_t>(k)];
          for (int rep = 0; rep < beta[static_cast<std::size_t>(k)]; ++rep) {
            next_live.clear();
            for (const int c : live) {
              const std::int64_t coef = poly[static_cast<std::size_t>(c)];
              poly[static_cast<std::size_t>(c)] = 0;
              for (int a = 0; a <= dim; ++a) {
                const int wa = w[static_cast<std::size_t>(a)];
                if (wa == 0) continue;
                const auto nc = static_cast<std::size_t>(c + place[static_cast<std::size_t>(a)]);
                if (next[nc] == 0) next_live.push_back(static_cast<int>(nc));
                next[nc] += coef * wa;
              }
            }
            poly.swap(next);
            live.swap(next_live);
          }
        }
        for (const int c : live) {
          const std::int64_t coef = poly[static_cast<std::size_t>(c)];
          poly[static_cast<std::size_t>(c)] = 0;
          const int col = index_of[static_cast<std::size_t>(c)];
          QV_ASSERT(col >= 0, "monomial outside the space");
          QV_ASSERT(coef > 0 && coef < (std::int64_t{1} << 53), "non-exact entry");
          const std::size_t at = q * n_sz * n_sz + static_cast<std::size_t>(r) * n_sz +
                                 static_cast<std::size_t>(col);
          subdivision_[at] = static_cast<double>(coef) * scale;
        }
      }
    }
    subdivision_t_ = transpose_blocks(subdivision_, n_sz);
  });
}

void BernsteinSimplex::build_to_lagrange() const {
  std::call_once(to_lagrange_once_, [this] {
    const int dim = dim_, degree = degree_;
    const auto n_sz = static_cast<std::size_t>(size());
    // Collocation matrix V[k][alpha] = B_alpha(point k) (eq. 18), rounded (T = V^-1:
    // build_to_bezier). Integer arithmetic: B_alpha(beta / m) = mult(alpha)
    // prod beta_a^alpha_a / m^n, one rational (and one rounding) per nonzero entry: the
    // same doubles as collocation().
    const mpz_class den_power = [&] {
      mpz_class r;
      mpz_ui_pow_ui(r.get_mpz_t(), static_cast<unsigned long>(point_denominator()), static_cast<unsigned long>(degree));
      return r;
    }();
    std::vector<mpz_class> mult(n_sz);
    for (std::size_t i = 0; i < n_sz; ++i) mult[i] = multinomial(dim, alphas_[i]);
    to_lagrange_.assign(n_sz * n_sz, 0.0);
    mpz_class num, power;
    for (std::size_t k = 0; k < n_sz; ++k) {
      const MultiIndex beta = point_numerators(static_cast<int>(k));
      for (std::size_t i = 0; i < n_sz; ++i) {
        const MultiIndex& alpha = alphas_[i];
        num = mult[i];
        for (int a = 0; a <= dim && sgn(num) != 0; ++a) {
          const auto e = static_cast<unsigned long>(alpha[static_cast<std::size_t>(a)]);
          if (e == 0) continue;
          mpz_ui_pow_ui(power.get_mpz_t(), static_cast<unsigned long>(beta[static_cast<std::size_t>(a)]), e);
          num *= power;
        }
        if (sgn(num) == 0) continue;
        mpq_class q(num, den_power);
        q.canonicalize();
        to_lagrange_[k * n_sz + i] = nearest_double(q);
      }
    }
    to_lagrange_t_ = transpose_blocks(to_lagrange_, n_sz);
  });
}

std::span<const double> BernsteinSimplex::bezier_to_lagrange() const {
  build_to_lagrange();
  return to_lagrange_;
}

std::span<const double> BernsteinSimplex::bezier_to_lagrange_transposed() const {
  build_to_lagrange();
  return to_lagrange_t_;
}

void BernsteinSimplex::build_to_bezier() const {
  std::call_once(to_bezier_once_, [this] {
    const int s = size();
    const auto n_sz = static_cast<std::size_t>(s);
    exact_->to_bezier = invert(collocation(dim_, alphas_, [this](int k) { return point_numerators(k); },
                                           point_denominator()),
                               s);
    to_bezier_.resize(n_sz * n_sz);
    mpq_class worst_row = 0;
    for (std::size_t r = 0; r < n_sz; ++r) {
      mpq_class row = 0;
      for (std::size_t c = 0; c < n_sz; ++c) {
        const mpq_class& q = exact_->to_bezier[r * n_sz + c];
        to_bezier_[r * n_sz + c] = nearest_double(q);
        row += abs(q);
      }
      if (row > worst_row) worst_row = row;
    }
    to_bezier_norm_ = round_up(worst_row);
    to_bezier_t_ = transpose_blocks(to_bezier_, n_sz);
  });
}

std::span<const double> BernsteinSimplex::lagrange_to_bezier() const {
  build_to_bezier();
  return to_bezier_;
}

std::span<const double> BernsteinSimplex::lagrange_to_bezier_transposed() const {
  build_to_bezier();
  return to_bezier_t_;
}

double BernsteinSimplex::lagrange_to_bezier_norm() const {
  build_to_bezier();
  return to_bezier_norm_;
}

const BernsteinSimplex::Exact& BernsteinSimplex::exact() const {
  build_to_bezier();
  // The dyadic subdivision entries are exact in double (constructor), hence as rationals;
  // copied only here, not for lagrange_to_bezier(), which the sampled path needs.
  build_subdivision();
  std::call_once(exact_->subdivision_once, [this] {
    exact_->subdivision.resize(subdivision_.size());
    for (std::size_t i = 0; i < subdivision_.size(); ++i) exact_->subdivision[i] = subdivision_[i];
  });
  return *exact_;
}

BernsteinSimplex::~BernsteinSimplex() = default;


std::array<double, 3> BernsteinSimplex::point(int i) const noexcept {
  const MultiIndex num = point_numerators(i);
  const double den = point_denominator();
  std::array<double, 3> x{0, 0, 0};
  for (int c = 1; c <= dim_; ++c)
    x[static_cast<std::size_t>(c - 1)] = num[static_cast<std::size_t>(c)] / den;
  return x;
}

std::array<int, 4> BernsteinSimplex::point_numerators(int i) const noexcept {
  if (degree_ == 0) {
    MultiIndex b{0, 0, 0, 0};
    for (int a = 0; a <= dim_; ++a) b[static_cast<std::size_t>(a)] = 1;
    return b;
  }
  return alphas_[static_cast<std::size_t>(i)];
}

void BernsteinSimplex::evaluate(std::span<const double> xi, std::span<double> values) const {
  QV_ASSERT(values.size() >= static_cast<std::size_t>(size()), "values too short");
  std::array<double, 4> lambda{1, 0, 0, 0};
  for (int c = 1; c <= dim_; ++c) {
    lambda[static_cast<std::size_t>(c)] = xi[static_cast<std::size_t>(c - 1)];
    lambda[0] -= lambda[static_cast<std::size_t>(c)];
  }
  std::vector<double> fact(static_cast<std::size_t>(degree_) + 1, 1.0);
  for (int i = 1; i <= degree_; ++i) fact[static_cast<std::size_t>(i)] = fact[static_cast<std::size_t>(i) - 1] * i;
  for (int i = 0; i < size(); ++i) {
    const MultiIndex& a = alphas_[static_cast<std::size_t>(i)];
    double b = fact[static_cast<std::size_t>(degree_)];
    for (int c = 0; c <= dim_; ++c) {
      const auto e = static_cast<std::size_t>(a[static_cast<std::size_t>(c)]);
      b /= fact[e];
      for (std::size_t k = 0; k < e; ++k) b *= lambda[static_cast<std::size_t>(c)];
    }
    values[static_cast<std::size_t>(i)] = b;
  }
}

std::span<const double> BernsteinSimplex::subdivision_transposed(int child) const {
  build_subdivision();
  const auto n = static_cast<std::size_t>(size()) * static_cast<std::size_t>(size());
  return {subdivision_t_.data() + static_cast<std::size_t>(child) * n, n};
}

std::span<const double> BernsteinSimplex::subdivision(int child) const {
  build_subdivision();
  const auto n = static_cast<std::size_t>(size()) * static_cast<std::size_t>(size());
  return {subdivision_.data() + static_cast<std::size_t>(child) * n, n};
}

const BernsteinSimplex& bernstein_simplex(int dim, int degree) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::unique_ptr<const BernsteinSimplex>> cache;
  // One lock across find and insert (STYLE.md §7); building is rare and short.
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{dim, degree}];
  if (!slot) slot = std::make_unique<const BernsteinSimplex>(dim, degree);
  return *slot;
}

}  // namespace quadval
