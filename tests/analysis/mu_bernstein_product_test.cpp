// Bernstein products (Paper V Prop. 4) against exact rational arithmetic: the product's
// control values, evaluated exactly at rational points with an independent Bernstein
// evaluation, must equal f(x) g(x) within the documented rounding bound.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "bezier/bernstein_product.hpp"
#include "bezier/rational_rounding.hpp"

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

double largest_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
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

// Exact control values of sum_t s_t f_t g_t, independently of the product tables: per
// factor multi-indices a (of f) and b (of g) give a + b (of h) with the weight
// C(a) C(b) / C(a + b), C the multinomial (Paper V Prop. 4), all in rationals.
std::vector<mpq_class> exact_product_sum(const std::vector<FactorDegree>& fd, const std::vector<FactorDegree>& gd,
                                         const std::vector<double>& scales,
                                         const std::vector<std::vector<double>>& fs,
                                         const std::vector<std::vector<double>>& gs) {
  const auto multinomial = [](const std::array<int, 4>& a) {
    mpz_class c = factorial(a[0] + a[1] + a[2] + a[3]);
    for (int v : a) c /= factorial(v);
    return c;
  };
  const auto hd = product_degrees(fd, gd);
  std::vector<std::vector<std::array<int, 4>>> fi, gi;
  std::vector<std::map<std::array<int, 4>, int>> hi;
  for (std::size_t f = 0; f < fd.size(); ++f) {
    fi.push_back(simplex_multi_indices(fd[f].dim, fd[f].degree));
    gi.push_back(simplex_multi_indices(gd[f].dim, gd[f].degree));
    std::map<std::array<int, 4>, int> m;
    const auto h = simplex_multi_indices(hd[f].dim, hd[f].degree);
    for (std::size_t k = 0; k < h.size(); ++k) m[h[k]] = static_cast<int>(k);
    hi.push_back(m);
  }
  std::vector<mpq_class> out(static_cast<std::size_t>(bernstein_space_size(hd)), mpq_class(0));
  for (std::size_t i = 0; i < fs[0].size(); ++i)
    for (std::size_t j = 0; j < gs[0].size(); ++j) {
      std::size_t ri = i, rj = j, k = 0, stride = 1;
      mpq_class w = 1;
      for (std::size_t f = 0; f < fd.size(); ++f) {
        const auto& a = fi[f][ri % fi[f].size()];
        const auto& b = gi[f][rj % gi[f].size()];
        ri /= fi[f].size();
        rj /= gi[f].size();
        std::array<int, 4> c{};
        for (std::size_t x = 0; x < 4; ++x) c[x] = a[x] + b[x];
        w *= mpq_class(multinomial(a) * multinomial(b), multinomial(c));
        k += stride * static_cast<std::size_t>(hi[f].at(c));
        stride *= hi[f].size();
      }
      for (std::size_t t = 0; t < scales.size(); ++t)
        out[k] += w * mpq_class(scales[t]) * mpq_class(fs[t][i]) * mpq_class(gs[t][j]);
    }
  return out;
}

TEST(MuBernsteinProduct, SumsOfProductsMatchExactCoefficients) {
  // Both kernels, coefficient by coefficient against exact rationals, for sums of three
  // products (one scaled accumulation, unscaled once): grids where the larger operand is
  // f or g, whole-plane runs (tensor factors) and row runs (simplices).
  const std::vector<Case> cases{
      {{{1, 4}, {1, 4}, {1, 4}}, {{1, 2}, {1, 2}, {1, 2}}},
      {{{1, 2}, {1, 2}, {1, 2}}, {{1, 6}, {1, 6}, {1, 6}}},
      {{{3, 4}}, {{3, 2}}},
      {{{3, 2}}, {{3, 5}}},
      {{{2, 4}, {1, 3}}, {{2, 2}, {1, 1}}},
      {{{2, 6}}, {{2, 6}}},
      {{{1, 6}, {1, 6}}, {{1, 3}, {1, 3}}},
      // Rows of the smaller operand of every length up to 8 (triangle of degree 7), and
      // longer ones cut into 8 + 2 (line factor of degree 9).
      {{{2, 7}}, {{2, 8}}},
      {{{1, 9}, {1, 2}}, {{1, 10}, {1, 3}}},
      // Multinomials beyond 2^53 (the grid scales then rounded by GMP), beyond 128 bits
      // (degree 150), and a product of two factors' multinomials beyond 128 bits.
      {{{1, 146}}, {{1, 4}}},
      {{{1, 120}, {1, 5}}, {{1, 4}, {1, 5}}},
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::vector<double> scales{1.0, -0.5, 3.25};
  for (const Case& cs : cases) {
    for (const bool entries : {false, true}) {
      BernsteinProduct table(cs.f, cs.g);
      table.use_entry_kernel(entries);
      std::vector<std::vector<double>> fs(3), gs(3);
      double mag = 0;
      for (std::size_t t = 0; t < 3; ++t) {
        double fm = 0, gm = 0;
        fs[t].resize(static_cast<std::size_t>(table.f_size()));
        gs[t].resize(static_cast<std::size_t>(table.g_size()));
        // Mixed magnitudes and some exact zeros (skipped by the convolution's outer loop).
        for (double& v : fs[t]) fm = std::max(fm, std::abs(v = (u(rng) > 0.8 ? 0.0 : u(rng) * std::ldexp(1.0, static_cast<int>(8 * u(rng))))));
        for (double& v : gs[t]) gm = std::max(gm, std::abs(v = u(rng) * 1e-3));
        mag += std::abs(scales[t]) * fm * gm;
      }
      const std::vector<BernsteinProduct::Term> terms{{scales[0], fs[0].data(), gs[0].data()},
                                                      {scales[1], fs[1].data(), gs[1].data()},
                                                      {scales[2], fs[2].data(), gs[2].data()}};
      std::vector<double> h(static_cast<std::size_t>(table.h_size()), 0.0);
      table.multiply_add_sum(terms, h.data());
      const auto want = exact_product_sum(cs.f, cs.g, scales, fs, gs);
      const double bound = table.rounding(3) * mag;
      double worst = 0;
      for (std::size_t k = 0; k < h.size(); ++k) {
        const double diff = mpq_class(abs(mpq_class(mpq_class(h[k]) - want[k]))).get_d();
        worst = std::max(worst, diff);
        EXPECT_LE(diff, bound) << "case " << &cs - cases.data() << " k " << k << (entries ? " (entries)" : " (convolution)");
      }
      // The bound is small enough to mean something (about 1e-14 relative).
      EXPECT_LT(bound, 1e-12 * mag) << "case " << &cs - cases.data();
      // Same sum as three separate products, within both rounding bounds.
      std::vector<double> h3(h.size(), 0.0);
      for (const auto& t : terms) table.multiply_add(t.f, t.g, t.scale, h3.data());
      for (std::size_t k = 0; k < h.size(); ++k) EXPECT_NEAR(h[k], h3[k], 2 * bound);
    }
  }
}

TEST(MuBernsteinProduct, SumsOfSquaresMatchExactCoefficients) {
  // Terms f_t * f_t (same pointer twice) take the entry kernel's rows of squares: each pair
  // (i, j), i < j, once with twice its weight. Against exact rationals for 1, 2, 3 and 6
  // terms (the counts with a fused walk) and 4 (separate products), on simplex and tensor
  // spaces; a square row that dropped or failed to double its off-diagonal pairs would be
  // off by about |f_i f_j| here, far beyond the rounding bound.
  const std::vector<std::vector<FactorDegree>> spaces{
      {{1, 3}}, {{2, 2}}, {{3, 3}}, {{1, 2}, {1, 2}, {1, 2}}, {{2, 2}, {1, 3}}, {{1, 1}, {1, 2}, {1, 0}}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& d : spaces)
    for (const std::size_t count : {1u, 2u, 3u, 4u, 6u}) {
      const BernsteinProduct& table = bernstein_product(d, d);
      std::vector<std::vector<double>> fs(count);
      std::vector<double> scales(count);
      std::vector<BernsteinProduct::Term> terms;
      double mag = 0;
      for (std::size_t t = 0; t < count; ++t) {
        double fm = 0;
        fs[t].resize(static_cast<std::size_t>(table.f_size()));
        for (double& v : fs[t]) fm = std::max(fm, std::abs(v = u(rng) * std::ldexp(1.0, static_cast<int>(6 * u(rng)))));
        scales[t] = t % 2 == 0 ? 1.0 : -0.375;
        mag += std::abs(scales[t]) * fm * fm;
        terms.push_back({scales[t], fs[t].data(), fs[t].data()});
      }
      std::vector<double> h(static_cast<std::size_t>(table.h_size()), 0.0);
      table.multiply_add_sum(terms, h.data());
      const auto want = exact_product_sum(d, d, scales, fs, fs);
      const double bound = table.rounding(static_cast<int>(count)) * mag;
      EXPECT_LT(bound, 1e-12 * mag);
      for (std::size_t k = 0; k < h.size(); ++k)
        EXPECT_LE(mpq_class(abs(mpq_class(mpq_class(h[k]) - want[k]))).get_d(), bound)
            << "space " << &d - spaces.data() << ", " << count << " terms, k " << k;
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

// Each weight of the entry kernel (the products of fewer than 2048 pairs) is the exact
// tensor weight prod_f alpha_i alpha_j / alpha_k rounded once to nearest: the product of
// two unit vectors e_i e_j is that weight at k = i + j and zero elsewhere, bit for bit
// against GMP here, over simplices and tensor products.
TEST(MuBernsteinProduct, EntryWeightsAreTheExactWeightsRounded) {
  const std::vector<Case> cases{{{{1, 3}}, {{1, 3}}},
                                {{{1, 30}}, {{1, 31}}},
                                {{{2, 6}}, {{2, 6}}},
                                {{{2, 4}}, {{2, 5}}},
                                {{{3, 3}}, {{3, 4}}},
                                {{{3, 5}}, {{3, 3}}},
                                {{{1, 3}, {1, 3}}, {{1, 3}, {1, 3}}},
                                {{{1, 2}, {1, 2}, {1, 1}}, {{1, 2}, {1, 1}, {1, 3}}},
                                {{{2, 2}, {1, 3}}, {{2, 3}, {1, 2}}}};
  for (const Case& c : cases) {
    const BernsteinProduct table(c.f, c.g);
    ASSERT_LT(table.f_size() * table.g_size(), 2048) << "not the entry kernel";
    std::vector<double> a(static_cast<std::size_t>(table.f_size())), b(static_cast<std::size_t>(table.g_size()));
    std::vector<double> h(static_cast<std::size_t>(table.h_size()));
    std::mt19937 rng(21);
    for (int sample = 0; sample < 200; ++sample) {
      const auto i = static_cast<std::size_t>(rng() % a.size()), j = static_cast<std::size_t>(rng() % b.size());
      std::fill(a.begin(), a.end(), 0.0);
      std::fill(b.begin(), b.end(), 0.0);
      a[i] = b[j] = 1;
      table.multiply(a.data(), b.data(), h.data());
      const std::vector<mpq_class> want = exact_product_sum(c.f, c.g, {1.0}, {a}, {b});
      for (std::size_t m = 0; m < h.size(); ++m)
        ASSERT_EQ(h[m], nearest_double(want[m])) << "case " << &c - cases.data() << " i " << i << " j " << j;
    }
  }
}

// multiply4 (four products in the lanes of one walk over the pairs) against multiply on each
// lane alone: the same bits, signed zeros included, in the spaces the scaled Jacobian's
// frame products use (simplices, a prism's and a pyramid's tensor spaces) and a few more.
TEST(MuBernsteinProduct, Multiply4EqualsFourMultipliesBitForBit) {
  const std::vector<std::pair<std::vector<FactorDegree>, std::vector<FactorDegree>>> cases{
      {{{3, 2}}, {{3, 2}}}, {{{3, 4}}, {{3, 2}}}, {{{2, 3}}, {{2, 1}}}, {{{1, 5}}, {{1, 0}}},
      {{{2, 1}, {1, 2}}, {{2, 1}, {1, 2}}}, {{{2, 2}, {1, 4}}, {{2, 2}, {1, 1}}},
      {{{1, 2}, {1, 2}, {1, 2}}, {{1, 2}, {1, 2}, {1, 2}}}, {{{1, 3}, {1, 3}, {1, 3}}, {{1, 1}, {1, 1}, {1, 1}}}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& [fd, gd] : cases) {
    SCOPED_TRACE(::testing::Message() << "f space of " << fd.size() << " factors, degree " << fd[0].degree);
    const BernsteinProduct& table = bernstein_product(fd, gd);
    const auto nf = static_cast<std::size_t>(table.f_size()), ng = static_cast<std::size_t>(table.g_size()),
               nh = static_cast<std::size_t>(table.h_size());
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<double> f(4 * nf), g(4 * ng), h(4 * nh, 1.0);
      for (double& v : f) v = rng() % 7 == 0 ? (rng() % 2 ? 0.0 : -0.0) : u(rng) * std::ldexp(1.0, static_cast<int>(8 * u(rng)));
      for (double& v : g) v = rng() % 7 == 0 ? (rng() % 2 ? 0.0 : -0.0) : u(rng) * std::ldexp(1.0, static_cast<int>(8 * u(rng)));
      ASSERT_TRUE(table.multiply4(f.data(), g.data(), h.data()));
      for (std::size_t l = 0; l < 4; ++l) {
        std::vector<double> fl(nf), gl(ng), want(nh);
        for (std::size_t i = 0; i < nf; ++i) fl[i] = f[4 * i + l];
        for (std::size_t j = 0; j < ng; ++j) gl[j] = g[4 * j + l];
        table.multiply(fl.data(), gl.data(), want.data());
        for (std::size_t k = 0; k < nh; ++k)
          ASSERT_EQ(std::bit_cast<std::uint64_t>(h[4 * k + l]), std::bit_cast<std::uint64_t>(want[k]))
              << "lane " << l << " k " << k << ": " << h[4 * k + l] << " vs " << want[k];
      }
    }
  }
}

// multiply_add_sum2x4 (two terms on four lanes, the planar scaled Jacobian's J = c_0,x
// c_1,y - c_0,y c_1,x) against multiply_add_sum on each lane alone: the same bits, signed
// zeros included, added to what h held; declined, h untouched, without the entry kernel.
TEST(MuBernsteinProduct, TwoTermSumsInLanesEqualEachLaneBitForBit) {
  const std::vector<std::pair<std::vector<FactorDegree>, std::vector<FactorDegree>>> cases{
      {{{2, 1}}, {{2, 1}}}, {{{2, 3}}, {{2, 3}}}, {{{2, 5}}, {{2, 5}}},
      {{{1, 1}, {1, 2}}, {{1, 2}, {1, 1}}}, {{{1, 3}, {1, 4}}, {{1, 4}, {1, 3}}}};
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto value = [&] { return rng() % 7 == 0 ? (rng() % 2 ? 0.0 : -0.0) : u(rng) * std::ldexp(1.0, static_cast<int>(8 * u(rng))); };
  for (const auto& [fd, gd] : cases) {
    SCOPED_TRACE(::testing::Message() << "f space of " << fd.size() << " factors, degree " << fd[0].degree);
    const BernsteinProduct& table = bernstein_product(fd, gd);
    const auto nf = static_cast<std::size_t>(table.f_size()), ng = static_cast<std::size_t>(table.g_size()),
               nh = static_cast<std::size_t>(table.h_size());
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<double> f0(4 * nf), g0(4 * ng), f1(4 * nf), g1(4 * ng), h(4 * nh);
      for (auto* v : {&f0, &g0, &f1, &g1, &h})
        for (double& x : *v) x = value();
      const std::vector<double> h_before = h;
      ASSERT_TRUE(table.multiply_add_sum2x4(1.0, f0.data(), g0.data(), -1.0, f1.data(), g1.data(), h.data()));
      for (std::size_t l = 0; l < 4; ++l) {
        const auto lane = [&](const std::vector<double>& v, std::size_t n) {
          std::vector<double> out(n);
          for (std::size_t i = 0; i < n; ++i) out[i] = v[4 * i + l];
          return out;
        };
        const std::vector<double> a = lane(f0, nf), b = lane(g0, ng), c = lane(f1, nf), d = lane(g1, ng);
        std::vector<double> want = lane(h_before, nh);
        const BernsteinProduct::Term terms[2] = {{1.0, a.data(), b.data()}, {-1.0, c.data(), d.data()}};
        table.multiply_add_sum(terms, want.data());
        for (std::size_t k = 0; k < nh; ++k)
          ASSERT_EQ(std::bit_cast<std::uint64_t>(h[4 * k + l]), std::bit_cast<std::uint64_t>(want[k]))
              << "lane " << l << " k " << k << ": " << h[4 * k + l] << " vs " << want[k];
      }
    }
  }
  const BernsteinProduct& large = bernstein_product(std::vector<FactorDegree>{{1, 4}, {1, 4}, {1, 4}},
                                                    std::vector<FactorDegree>{{1, 4}, {1, 4}, {1, 4}});
  std::vector<double> f(4 * static_cast<std::size_t>(large.f_size()), 1.0), g = f;
  std::vector<double> h(4 * static_cast<std::size_t>(large.h_size()), -7.0);
  EXPECT_FALSE(large.multiply_add_sum2x4(1.0, f.data(), g.data(), -1.0, g.data(), f.data(), h.data()));
  EXPECT_TRUE(std::all_of(h.begin(), h.end(), [](double v) { return v == -7.0; }));
}

// gram_sums2x4 (the Gram sums of two planar columns on four lanes) against gram_sums on each
// lane alone (two coordinates): the same bits, signed zeros included.
TEST(MuBernsteinProduct, PlanarGramSumsInLanesEqualEachLaneBitForBit) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const std::vector<FactorDegree>& deg : {std::vector<FactorDegree>{{2, 2}}, std::vector<FactorDegree>{{2, 4}},
                                              std::vector<FactorDegree>{{1, 2}, {1, 2}}}) {
    const BernsteinProduct& table = bernstein_product(deg, deg);
    const auto n = static_cast<std::size_t>(table.f_size()), nh = static_cast<std::size_t>(table.h_size());
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<double> cols(4 * 4 * n), out(3 * 4 * nh, 0.0);
      for (double& v : cols) v = rng() % 7 == 0 ? (rng() % 2 ? 0.0 : -0.0) : u(rng) * std::ldexp(1.0, static_cast<int>(8 * u(rng)));
      const double* w[4] = {cols.data(), cols.data() + 4 * n, cols.data() + 8 * n, cols.data() + 12 * n};
      double* h[3] = {out.data(), out.data() + 4 * nh, out.data() + 8 * nh};
      ASSERT_TRUE(table.gram_sums2x4(w, h));
      for (std::size_t l = 0; l < 4; ++l) {
        std::vector<double> lane(6 * n, 0.0), want(3 * nh, 0.0);
        for (std::size_t a = 0; a < 2; ++a)
          for (std::size_t x = 0; x < 2; ++x)
            for (std::size_t i = 0; i < n; ++i) lane[(3 * a + x) * n + i] = w[2 * a + x][4 * i + l];
        const double* wl[6];
        for (std::size_t j = 0; j < 6; ++j) wl[j] = lane.data() + j * n;
        double* hl[3] = {want.data(), want.data() + nh, want.data() + 2 * nh};
        ASSERT_TRUE(table.gram_sums(wl, 2, hl, 2));
        for (std::size_t e = 0; e < 3; ++e)
          for (std::size_t k = 0; k < nh; ++k)
            ASSERT_EQ(std::bit_cast<std::uint64_t>(h[e][4 * k + l]), std::bit_cast<std::uint64_t>(hl[e][k]))
                << "entry " << e << " lane " << l << " k " << k;
      }
    }
  }
}

// A large product (a quadratic pyramid's second frame product: 125 x 27 pairs) has no entry
// kernel: multiply4 says so and leaves h alone, and the caller multiplies one lane at a time.
TEST(MuBernsteinProduct, Multiply4DeclinesLargeProducts) {
  const BernsteinProduct& table = bernstein_product(std::vector<FactorDegree>{{1, 4}, {1, 4}, {1, 4}},
                                                    std::vector<FactorDegree>{{1, 2}, {1, 2}, {1, 2}});
  std::vector<double> f(4 * static_cast<std::size_t>(table.f_size()), 1.0), g(4 * static_cast<std::size_t>(table.g_size()), 1.0);
  std::vector<double> h(4 * static_cast<std::size_t>(table.h_size()), -7.0);
  EXPECT_FALSE(table.multiply4(f.data(), g.data(), h.data()));
  EXPECT_TRUE(std::all_of(h.begin(), h.end(), [](double v) { return v == -7.0; }));
}

// gram_sums (every entry of W^T W in one walk over the pairs, 8 lanes) against the three-term
// sums of the general pair walk, entry by entry: bit for bit, since each lane does the same
// roundings in the same order (diagonal entries through two copies of the column, so that
// multiply_add_sum does not take its rows of squares). Also, against exact rationals,
// within rounding(3).
// gram_sums over two coordinates (planar elements: W's z coordinates are +0 everywhere)
// against the same sums over three with that coordinate +0: bit for bit, for every space,
// column count and entry.
TEST(MuBernsteinProduct, GramSumsOfTwoCoordinatesEqualThreeWithZeroZ) {
  const std::vector<std::vector<FactorDegree>> spaces{{{2, 1}}, {{2, 3}}, {{1, 2}, {1, 2}}, {{3, 2}}, {{2, 2}, {1, 2}}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& d : spaces)
    for (const int columns : {2, 3}) {
      SCOPED_TRACE(::testing::Message() << "space " << &d - spaces.data() << ", " << columns << " columns");
      const BernsteinProduct& table = bernstein_product(d, d);
      const auto n = static_cast<std::size_t>(table.f_size());
      std::vector<std::vector<double>> w(static_cast<std::size_t>(3 * columns), std::vector<double>(n));
      for (std::size_t c = 0; c < w.size(); ++c)
        for (double& v : w[c]) v = c % 3 == 2 ? 0.0 : u(rng) * std::ldexp(1.0, static_cast<int>(4 * u(rng)));
      const double* cols[9];
      for (int c = 0; c < 3 * columns; ++c) cols[c] = w[static_cast<std::size_t>(c)].data();
      std::vector<std::vector<double>> three(6, std::vector<double>(static_cast<std::size_t>(table.h_size()), 0.0));
      std::vector<std::vector<double>> two = three;
      double* out3[6];
      double* out2[6];
      for (std::size_t e = 0; e < 6; ++e) out3[e] = three[e].data(), out2[e] = two[e].data();
      ASSERT_TRUE(table.gram_sums(cols, columns, out3, 3));
      ASSERT_TRUE(table.gram_sums(cols, columns, out2, 2));
      for (std::size_t e = 0; e < 6; ++e)
        for (std::size_t k = 0; k < three[e].size(); ++k) {
          ASSERT_EQ(std::signbit(two[e][k]), std::signbit(three[e][k])) << "entry " << e << " k " << k;
          ASSERT_EQ(two[e][k], three[e][k]) << "entry " << e << " k " << k;
        }
      // And a nonzero z is left out: the sums differ somewhere.
      for (double& v : w[2]) v = 1;
      std::vector<std::vector<double>> with_z(6, std::vector<double>(static_cast<std::size_t>(table.h_size()), 0.0));
      for (std::size_t e = 0; e < 6; ++e) out3[e] = with_z[e].data();
      ASSERT_TRUE(table.gram_sums(cols, columns, out3, 3));
      EXPECT_NE(with_z[0], two[0]);
    }
}

TEST(MuBernsteinProduct, GramSumsEqualThreeTermSumsBitForBit) {
  const std::vector<std::vector<FactorDegree>> spaces{{{3, 2}}, {{2, 3}}, {{1, 2}, {1, 2}, {1, 2}}, {{2, 2}, {1, 2}}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& d : spaces)
    for (const int columns : {2, 3}) {
      SCOPED_TRACE(::testing::Message() << "space " << &d - spaces.data() << ", " << columns << " columns");
      const BernsteinProduct& table = bernstein_product(d, d);
      ASSERT_LT(static_cast<long>(table.f_size()) * table.f_size(), 2048);
      std::vector<std::vector<double>> w(static_cast<std::size_t>(3 * columns), std::vector<double>(static_cast<std::size_t>(table.f_size())));
      for (auto& c : w)
        for (double& v : c) v = u(rng) * std::ldexp(1.0, static_cast<int>(4 * u(rng)));
      const int entries = columns * (columns + 1) / 2;
      const std::array<int, 6> ea = columns == 3 ? std::array<int, 6>{0, 1, 2, 0, 0, 1} : std::array<int, 6>{0, 1, 0};
      const std::array<int, 6> eb = columns == 3 ? std::array<int, 6>{0, 1, 2, 1, 2, 2} : std::array<int, 6>{0, 1, 1};
      std::vector<std::vector<double>> got(6, std::vector<double>(static_cast<std::size_t>(table.h_size()), 0.0));
      const double* cols[9];
      for (int c = 0; c < 3 * columns; ++c) cols[c] = w[static_cast<std::size_t>(c)].data();
      double* out[6];
      for (int e = 0; e < 6; ++e) out[e] = got[static_cast<std::size_t>(e)].data();
      ASSERT_TRUE(table.gram_sums(cols, columns, out));
      for (int e = 0; e < entries; ++e) {
        const auto a = static_cast<std::size_t>(ea[static_cast<std::size_t>(e)]), b = static_cast<std::size_t>(eb[static_cast<std::size_t>(e)]);
        std::vector<std::vector<double>> copies;  // column b's coordinates, as separate vectors
        for (std::size_t x = 0; x < 3; ++x) copies.push_back(w[3 * b + x]);
        std::vector<BernsteinProduct::Term> terms;
        for (std::size_t x = 0; x < 3; ++x) terms.push_back({1.0, w[3 * a + x].data(), copies[x].data()});
        std::vector<double> want(static_cast<std::size_t>(table.h_size()), 0.0);
        table.multiply_add_sum(terms, want.data());
        for (std::size_t k = 0; k < want.size(); ++k)
          ASSERT_EQ(got[static_cast<std::size_t>(e)][k], want[k]) << "entry " << e << " k " << k;
        std::vector<std::vector<double>> fs, gs;
        double mag = 0;
        for (std::size_t x = 0; x < 3; ++x) {
          fs.push_back(w[3 * a + x]);
          gs.push_back(w[3 * b + x]);
          mag += largest_abs(fs.back()) * largest_abs(gs.back());
        }
        const auto exact = exact_product_sum(d, d, {1.0, 1.0, 1.0}, fs, gs);
        for (std::size_t k = 0; k < want.size(); ++k)
          EXPECT_LE(mpq_class(abs(mpq_class(mpq_class(got[static_cast<std::size_t>(e)][k]) - exact[k]))).get_d(),
                    table.rounding(3) * mag);
      }
    }
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
