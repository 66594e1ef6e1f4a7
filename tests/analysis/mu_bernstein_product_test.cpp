// Bernstein products (Paper V Prop. 4) against exact rational arithmetic: the product's
// control values, evaluated exactly at rational points with an independent Bernstein
// evaluation, must equal f(x) g(x) within the documented rounding bound.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <random>
#include <vector>

#include "bezier/bernstein_product.hpp"

namespace quadval {
namespace {

mpz_class factorial(int n) {
  mpz_class f = 1;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}

// Exact value of sum_i c_i B_i at a point given per factor by barycentric coordinates.
mpq_class evaluate(const std::vector<FactorDegree>& deg, const std::vector<double>& c,
                   const std::vector<std::array<mpq_class, 4>>& bary) {
  // Per factor the Bernstein values, then the tensor product (factor 0 fastest).
  std::vector<std::vector<mpq_class>> values;
  for (std::size_t f = 0; f < deg.size(); ++f) {
    std::vector<mpq_class> v;
    for (const auto& a : simplex_multi_indices(deg[f].dim, deg[f].degree)) {
      mpq_class b(factorial(deg[f].degree));
      for (int k = 0; k <= deg[f].dim; ++k) {
        b /= factorial(a[static_cast<std::size_t>(k)]);
        for (int e = 0; e < a[static_cast<std::size_t>(k)]; ++e) b *= bary[f][static_cast<std::size_t>(k)];
      }
      v.push_back(b);
    }
    values.push_back(v);
  }
  mpq_class sum = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    mpq_class b = c[i];
    std::size_t rest = i;
    for (std::size_t f = 0; f < deg.size(); ++f) {
      b *= values[f][rest % values[f].size()];
      rest /= values[f].size();
    }
    sum += b;
  }
  return sum;
}

struct Case {
  std::vector<FactorDegree> f, g;
};

TEST(MuBernsteinProduct, MatchesExactPointwiseProducts) {
  const std::vector<Case> cases{
      {{{1, 2}}, {{1, 3}}},
      {{{2, 2}}, {{2, 3}}},
      {{{3, 1}}, {{3, 2}}},
      {{{3, 0}}, {{3, 2}}},
      {{{1, 1}, {1, 2}}, {{1, 2}, {1, 2}}},
      {{{2, 2}, {1, 1}}, {{2, 1}, {1, 2}}},
      {{{1, 1}, {1, 2}, {1, 1}}, {{1, 2}, {1, 1}, {1, 1}}},
      {{{3, 2}}, {{3, 3}}},
      {{{2, 3}, {1, 2}}, {{2, 2}, {1, 3}}},
  };
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> num(0, 64);
  for (const Case& cs : cases) {
    for (const bool entries : {false, true}) {
      // Both kernels: the scaled convolution and the weighted-entry loop.
      BernsteinProduct table(cs.f, cs.g);
      table.use_entry_kernel(entries);
      ASSERT_EQ(table.f_size(), bernstein_space_size(cs.f));
      ASSERT_EQ(table.g_size(), bernstein_space_size(cs.g));
      const auto hdeg = product_degrees(cs.f, cs.g);
      ASSERT_EQ(table.h_size(), bernstein_space_size(hdeg));
      for (int trial = 0; trial < 5; ++trial) {
        std::vector<double> f(static_cast<std::size_t>(table.f_size())), g(static_cast<std::size_t>(table.g_size()));
        double fm = 0, gm = 0;
        for (double& v : f) fm = std::max(fm, std::abs(v = u(rng) * 1e3));
        for (double& v : g) gm = std::max(gm, std::abs(v = u(rng)));
        std::vector<double> h(static_cast<std::size_t>(table.h_size()));
        table.multiply(f.data(), g.data(), h.data());
        const double bound = table.rounding(1) * fm * gm;
        for (int point = 0; point < 12; ++point) {
          std::vector<std::array<mpq_class, 4>> bary;
          for (const FactorDegree& d : cs.f) {
            std::array<mpq_class, 4> l{0, 0, 0, 0};
            mpq_class rest = 1;
            for (int k = 1; k <= d.dim; ++k) {
              mpq_class x(num(rng), 64 * d.dim);
              x.canonicalize();
              l[static_cast<std::size_t>(k)] = x;
              rest -= x;
            }
            l[0] = rest;
            bary.push_back(l);
          }
          const mpq_class want = evaluate(cs.f, f, bary) * evaluate(cs.g, g, bary);
          const mpq_class got = evaluate(hdeg, h, bary);
          EXPECT_LE(mpq_class(abs(mpq_class(got - want))).get_d(), bound)
              << "case " << &cs - cases.data() << (entries ? " (entries)" : " (convolution)");
        }
      }
    }
  }
}

TEST(MuBernsteinProduct, ProductOfOnesIsOneAndWeightsAreConvex) {
  // 1 * 1 = 1: every product coefficient is a convex combination (weights sum to 1).
  const std::vector<FactorDegree> f{{2, 3}, {1, 2}}, g{{2, 4}, {1, 1}};
  const BernsteinProduct& table = bernstein_product(f, g);
  std::vector<double> a(static_cast<std::size_t>(table.f_size()), 1.0), b(static_cast<std::size_t>(table.g_size()), 1.0);
  std::vector<double> h(static_cast<std::size_t>(table.h_size()));
  table.multiply(a.data(), b.data(), h.data());
  for (double v : h) EXPECT_NEAR(v, 1.0, table.rounding(1));
}

TEST(MuBernsteinProduct, TripleProductMatchesTwoProducts) {
  const std::vector<FactorDegree> d{{3, 1}};
  std::vector<double> f{1, -2, 0.5, 3}, g{0.25, 1, -1, 2}, k{2, 2, -3, 1};
  std::vector<double> scratch, out(static_cast<std::size_t>(bernstein_space_size(std::vector<FactorDegree>{{3, 3}})));
  const double r = bernstein_triple_product(d, f.data(), d, g.data(), d, k.data(), scratch, out.data());
  // Exact check at the tetrahedron's vertices (control values there are values).
  const auto idx = simplex_multi_indices(3, 3);
  for (std::size_t i = 0; i < idx.size(); ++i)
    for (int v = 0; v < 4; ++v) {
      if (idx[i][static_cast<std::size_t>(v)] == 3) {
        const auto vv = static_cast<std::size_t>(v);
        EXPECT_NEAR(out[i], f[vv] * g[vv] * k[vv], r * 3 * 2 * 3);
      }
    }
}

}  // namespace
}  // namespace quadval
