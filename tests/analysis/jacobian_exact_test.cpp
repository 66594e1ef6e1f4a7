// Exact rational oracle: for small random elements of every family (complete and
// incomplete, orders 1-3), the exact Bézier coefficients of J are computed here by exact
// polynomial arithmetic, independently of the code under test:
//   nodes (dyadic doubles) -> exact Lagrange interpolant by a rational Vandermonde solve in
//   the element's monomial space -> J as an exact polynomial -> Bernstein coefficients by
//   the closed form  lambda^gamma = sum_alpha [mult(n-m; alpha-gamma) / mult(n; alpha)] B_alpha.
// Our floating-point coefficients must lie within our error bound of them, and the root
// bounds must contain the exact Bézier bounds.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "analysis/jacobian_product.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/jacobian_space.hpp"
#include "jacobian_test_util.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using Mono = std::array<int, 3>;
using Poly = std::map<Mono, mpq_class>;

Poly mul(const Poly& a, const Poly& b) {
  Poly r;
  for (const auto& [ea, ca] : a)
    for (const auto& [eb, cb] : b) r[{ea[0] + eb[0], ea[1] + eb[1], ea[2] + eb[2]}] += ca * cb;
  return r;
}
Poly add(Poly a, const Poly& b, int sign = 1) {
  for (const auto& [e, c] : b) a[e] += sign * c;
  return a;
}
Poly deriv(const Poly& a, int v, const mpq_class& factor) {
  Poly r;
  for (const auto& [e, c] : a) {
    if (e[static_cast<std::size_t>(v)] == 0) continue;
    Mono f = e;
    --f[static_cast<std::size_t>(v)];
    r[f] += c * e[static_cast<std::size_t>(v)] * factor;
  }
  return r;
}

mpz_class fact(int n) {
  mpz_class f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

// Which Bézier-domain axes are Gmsh [-1, 1] directions.
std::array<bool, 3> interval_axes(ElementFamily f) {
  switch (f) {
    case ElementFamily::line: return {true, false, false};
    case ElementFamily::quadrangle: return {true, true, false};
    case ElementFamily::prism: return {false, false, true};
    case ElementFamily::hexahedron: return {true, true, true};
    default: return {false, false, false};
  }
}

std::vector<Mono> complete_exponents(ElementFamily f, int p) {
  std::vector<Mono> e;
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= p; ++j)
      for (int k = 0; k <= p; ++k) {
        bool ok = false;
        switch (f) {
          case ElementFamily::line: ok = j == 0 && k == 0; break;
          case ElementFamily::triangle: ok = i + j <= p && k == 0; break;
          case ElementFamily::quadrangle: ok = k == 0; break;
          case ElementFamily::tetrahedron: ok = i + j + k <= p; break;
          case ElementFamily::prism: ok = i + j <= p; break;
          case ElementFamily::hexahedron: ok = true; break;
          default: break;
        }
        if (ok) e.push_back({i, j, k});
      }
  return e;
}

// Factors (groups of axes) and the Jacobian degree of each (Paper III Table 1).
struct Factor {
  std::vector<int> axes;
  int degree;
};
std::vector<Factor> factors_of(ElementFamily f, int p) {
  switch (f) {
    case ElementFamily::line: return {{{0}, p - 1}};
    case ElementFamily::triangle: return {{{0, 1}, 2 * p - 2}};
    case ElementFamily::quadrangle: return {{{0}, 2 * p - 1}, {{1}, 2 * p - 1}};
    case ElementFamily::tetrahedron: return {{{0, 1, 2}, 3 * p - 3}};
    case ElementFamily::prism: return {{{0, 1}, 3 * p - 2}, {{2}, 3 * p - 1}};
    case ElementFamily::hexahedron: return {{{0}, 3 * p - 1}, {{1}, 3 * p - 1}, {{2}, 3 * p - 1}};
    default: return {};
  }
}

class ExactOracleTest : public testing::TestWithParam<const ElementType*> {};

TEST_P(ExactOracleTest, FloatingCoefficientsAndBoundsContainExactOnes) {
  const ElementType& type = *GetParam();
  const int p = type.order;
  const auto axes = interval_axes(type.family);
  const auto ref = reference_nodes(type);
  const std::size_t n = ref.size();
  const std::vector<Mono> expo = type.complete
      ? complete_exponents(type.family, p)
      : [&] {
          std::vector<Mono> e;
          for (const auto& x : detail::polynomial_space(type, detail::FactorBasis::monomial).exponents)
            e.push_back({x[0], x[1], x[2]});
          return e;
        }();
  ASSERT_EQ(expo.size(), n);
  // exact reference nodes in Bézier-domain coordinates
  std::vector<std::array<mpq_class, 3>> t(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < type.dim; ++a) {
      const double x = ref[i][static_cast<std::size_t>(a)];
      const double v = axes[static_cast<std::size_t>(a)] ? (x + 1) / 2 : x;
      t[i][static_cast<std::size_t>(a)] = mpq_class(static_cast<long>(std::lround(v * p)), p);
      t[i][static_cast<std::size_t>(a)].canonicalize();
    }
  // Vandermonde (exact) and its inverse
  std::vector<mpq_class> v(n * n), inv(n * n, mpq_class(0));
  for (std::size_t i = 0; i < n; ++i) {
    inv[i * n + i] = 1;
    for (std::size_t j = 0; j < n; ++j) {
      mpq_class m = 1;
      for (int a = 0; a < 3; ++a)
        for (int k = 0; k < expo[j][static_cast<std::size_t>(a)]; ++k) m *= t[i][static_cast<std::size_t>(a)];
      v[i * n + j] = m;
    }
  }
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t pr = c;
    while (sgn(v[pr * n + c]) == 0) ++pr;
    for (std::size_t k = 0; k < n; ++k) {
      std::swap(v[pr * n + k], v[c * n + k]);
      std::swap(inv[pr * n + k], inv[c * n + k]);
    }
    const mpq_class d = v[c * n + c];
    for (std::size_t k = 0; k < n; ++k) v[c * n + k] /= d, inv[c * n + k] /= d;
    for (std::size_t r = 0; r < n; ++r) {
      if (r == c || sgn(v[r * n + c]) == 0) continue;
      const mpq_class f = v[r * n + c];
      for (std::size_t k = 0; k < n; ++k) v[r * n + k] -= f * v[c * n + k], inv[r * n + k] -= f * inv[c * n + k];
    }
  }

  std::mt19937 rng(static_cast<unsigned>(100 + type.gmsh_id));
  std::uniform_int_distribution<int> small(-6, 6);
  BoundsWorkspace ws;
  const auto& space = jacobian_space(type);
  const BezierBasis& basis = space.basis();
  for (int trial = 0; trial < 4; ++trial) {
    // dyadic nodes: reference node scaled, plus k/64
    std::vector<double> x(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        double val = c < type.dim ? 2 * ref[i][static_cast<std::size_t>(c)] : 0;
        if (type.dim == 1 && c > 0) val = 0;
        const bool vertex = i < static_cast<std::size_t>(family_num_vertices(type.family));
        if (!(type.dim == 2 && c == 2) && !(type.dim == 1 && vertex)) val += small(rng) / 64.0;
        if (type.dim == 1 && vertex && c == 0) val = ref[i][0] * 2;
        x[3 * i + static_cast<std::size_t>(c)] = std::ldexp(std::round(std::ldexp(val, 20)), -20);
      }
    // exact map X_c(t) = sum_j a_cj t^e_j, a = V^{-1} x
    Poly X[3];
    for (int c = 0; c < 3; ++c)
      for (std::size_t j = 0; j < n; ++j) {
        mpq_class a = 0;
        for (std::size_t i = 0; i < n; ++i) a += inv[j * n + i] * mpq_class(x[3 * i + static_cast<std::size_t>(c)]);
        if (sgn(a) != 0) X[c][expo[j]] += a;
      }
    // derivatives in Gmsh coordinates
    Poly d[3][3];
    for (int a = 0; a < type.dim; ++a)
      for (int c = 0; c < 3; ++c)
        d[a][c] = deriv(X[c], a, axes[static_cast<std::size_t>(a)] ? mpq_class(1, 2) : mpq_class(1));
    Poly jac;
    if (type.dim == 3) {
      const auto minor = [&](int r1, int r2) { return add(mul(d[1][r1], d[2][r2]), mul(d[1][r2], d[2][r1]), -1); };
      jac = add(add(mul(d[0][0], minor(1, 2)), mul(d[0][1], minor(2, 0))), mul(d[0][2], minor(0, 1)));
    } else if (type.dim == 2) {
      jac = add(mul(d[0][0], d[1][1]), mul(d[0][1], d[1][0]), -1);
    } else {
      jac = d[0][0];  // vertices on the x axis: t = (1, 0, 0)
    }
    // Bernstein coefficients, factor by factor (closed form above).
    const auto fs = factors_of(type.family, p);
    std::vector<mpq_class> exact(static_cast<std::size_t>(basis.size()), mpq_class(0));
    for (const auto& [e, coef] : jac) {
      // per factor: list of (factor coefficient index, weight)
      std::vector<std::vector<std::pair<int, mpq_class>>> per(fs.size());
      for (std::size_t f = 0; f < fs.size(); ++f) {
        const BernsteinSimplex& fac = *basis.factors()[f];
        ASSERT_EQ(fac.degree(), fs[f].degree);
        const int ndeg = fs[f].degree;
        int m = 0;
        for (int a : fs[f].axes) m += e[static_cast<std::size_t>(a)];
        ASSERT_LE(m, ndeg) << "J outside the Table 1 space";
        for (int i = 0; i < fac.size(); ++i) {
          const auto al = fac.multi_indices()[static_cast<std::size_t>(i)];
          bool ok = true;
          mpz_class denom_rest = 1;  // prod (alpha - gamma)!
          mpz_class alpha_fact = 1;  // prod alpha!
          int rest0 = al[0];
          for (std::size_t k = 0; k < fs[f].axes.size(); ++k) {
            const int g = e[static_cast<std::size_t>(fs[f].axes[k])];
            const int ak = al[k + 1];
            if (ak < g) ok = false;
            else denom_rest *= fact(ak - g);
            alpha_fact *= fact(ak);
          }
          if (!ok) continue;
          denom_rest *= fact(rest0);
          alpha_fact *= fact(rest0);
          // mult(n-m; alpha-gamma) / mult(n; alpha)
          mpq_class w1(fact(ndeg - m), denom_rest), w2(fact(ndeg), alpha_fact);
          w1.canonicalize();
          w2.canonicalize();
          const mpq_class w = w1 / w2;
          per[f].push_back({i, w});
        }
      }
      // tensor combination
      std::vector<std::pair<int, mpq_class>> acc{{0, coef}};
      int stride = 1;
      for (std::size_t f = 0; f < fs.size(); ++f) {
        std::vector<std::pair<int, mpq_class>> next;
        for (const auto& [idx, w] : acc)
          for (const auto& [i, wf] : per[f]) next.push_back({idx + stride * i, w * wf});
        acc.swap(next);
        stride *= basis.factors()[f]->size();
      }
      for (const auto& [idx, w] : acc) exact[static_cast<std::size_t>(idx)] += w;
    }

    // The product path (jacobian_product.hpp): exact coefficients equal the oracle's, and
    // the floating-point ones lie within their certified error bound of them.
    {
      const JacobianProduct& prod = *space.product();
      ASSERT_EQ(prod.exact_coefficients(SampleMap::curved, x.data(), type.dim == 2), exact) << type.name;
      std::vector<double> pc(exact.size());
      double perr = -1;
      ProductScratch ps;
      prod.coefficients(SampleMap::curved, x.data(), 1, type.dim == 2, pc.data(), &perr, ps);
      ASSERT_GE(perr, 0);
      double big = 0;
      for (std::size_t i = 0; i < exact.size(); ++i) {
        ASSERT_LE(abs(mpq_class(pc[i]) - exact[i]), mpq_class(perr)) << type.name << " coeff " << i;
        big = std::max(big, std::abs(exact[i].get_d()));
      }
      // and the bound is useful: the a priori model grows with the row sums of the
      // geometry conversion (about 1e4 for hexahedra of order 4), not with the J space's
      EXPECT_LE(perr, 1e-6 * (1 + big)) << type.name << ": bound far above the rounding";
    }
    mpq_class emin = exact[0], emax = exact[0], vmin = exact[static_cast<std::size_t>(basis.vertex_indices()[0])],
              vmax = vmin;
    double scale = 0;
    for (std::size_t i = 0; i < exact.size(); ++i) {
      emin = std::min(emin, exact[i]);
      emax = std::max(emax, exact[i]);
      scale = std::max(scale, std::abs(exact[i].get_d()));
    }
    if (space.has_sample_gradients()) {
      // The sampled path: samples then the J space's Lagrange-to-Bézier conversion.
      std::vector<double> samples(static_cast<std::size_t>(basis.size())), coeffs(samples.size()),
          scratch(2 * samples.size());
      double err = 0;
      SampleScratch ss;
      jacobian_samples(space, SampleMap::curved, x.data(), 1, type.dim == 2, samples.data(), &err, ss);
      basis.to_bezier(samples.data(), coeffs.data(), scratch.data());
      for (std::size_t i = 0; i < exact.size(); ++i)
        EXPECT_NEAR(coeffs[i], exact[i].get_d(), 1e-6 * (1 + scale)) << type.name << " coeff " << i;
    }
    for (int vi : basis.vertex_indices()) {
      vmin = std::min(vmin, exact[static_cast<std::size_t>(vi)]);
      vmax = std::max(vmax, exact[static_cast<std::size_t>(vi)]);
    }
    BoundsOptions root_only;
    root_only.max_subdivisions = 0;
    root_only.goal = BoundsGoal::measure;  // (uses the per-sample error bound)
    root_only.exact_fallback = false;
    const JacobianBounds b = jacobian_bounds(type, x, root_only, ws, type.dim == 2);
    EXPECT_LE(mpq_class(b.jmin_lower), emin) << type.name;
    EXPECT_GE(mpq_class(b.jmin_upper), emin) << type.name;  // (min J lies in between)
    EXPECT_LE(mpq_class(b.jmax_lower), vmax) << type.name;
    EXPECT_GE(mpq_class(b.jmax_upper), emax) << type.name;
    // and they are tight: the certified margin of the product path stays below 1e-6 of
    // the coefficients' scale up to order 4 (the sampled path needed 5e-2 at order 3)
    EXPECT_NEAR(b.jmin_lower, emin.get_d(), 1e-6 * (1 + scale)) << type.name;
  }
}

std::string type_name(const testing::TestParamInfo<const ElementType*>& i) {
  std::string s(i.param->name);
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(OrdersUpTo4, ExactOracleTest,
                         testing::ValuesIn(test::analysed_types(4, 4)), type_name);

}  // namespace
}  // namespace quadval
