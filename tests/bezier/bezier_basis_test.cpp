// Bernstein factors and Jacobian-space bases: partition of unity, the thesis's eq. (23),
// exact inverse property in rationals (collocation matrix built here independently),
// subdivision against the closed-form de Casteljau and against point evaluation.
#include "quadval/bezier_basis.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <tuple>

#include "bezier/bezier_exact.hpp"

namespace quadval {
namespace {

struct DimDegree {
  int dim;
  int degree;
};

std::vector<DimDegree> factor_grid() {
  std::vector<DimDegree> g;
  for (int n = 0; n <= 12; ++n) g.push_back({1, n});
  for (int n = 0; n <= 8; ++n) g.push_back({2, n});
  for (int n = 0; n <= 6; ++n) g.push_back({3, n});
  return g;
}

class FactorTest : public testing::TestWithParam<DimDegree> {};

// A random point of the unit d-simplex.
std::array<double, 3> random_point(int d, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  for (;;) {
    std::array<double, 3> x{u(rng), u(rng), u(rng)};
    double s = 0;
    for (int c = 0; c < d; ++c) s += x[static_cast<std::size_t>(c)];
    if (s <= 1) return x;
  }
}

TEST_P(FactorTest, PartitionOfUnityAndNonNegative) {
  const auto [d, n] = GetParam();
  const BernsteinSimplex& b = bernstein_simplex(d, n);
  const int expected = d == 1 ? n + 1 : d == 2 ? (n + 1) * (n + 2) / 2 : (n + 1) * (n + 2) * (n + 3) / 6;
  ASSERT_EQ(b.size(), expected);
  std::mt19937 rng(7);
  std::vector<double> v(static_cast<std::size_t>(b.size()));
  for (int t = 0; t < 50; ++t) {
    const auto x = random_point(d, rng);
    b.evaluate(x, v);
    double s = 0;
    for (double w : v) {
      EXPECT_GE(w, 0);
      s += w;
    }
    EXPECT_NEAR(s, 1.0, 1e-13);
  }
}

// T times the collocation matrix, both exact, is the identity. The collocation matrix is
// built here from the closed form n!/alpha! prod (beta_a/n)^alpha_a in rationals.
TEST_P(FactorTest, ExactLagrangeToBezierInvertsCollocation) {
  const auto [d, n] = GetParam();
  const BernsteinSimplex& b = bernstein_simplex(d, n);
  const int s = b.size();
  const auto fact = [](int k) {
    mpz_class f = 1;
    for (int i = 2; i <= k; ++i) f *= i;
    return f;
  };
  std::vector<mpq_class> v(static_cast<std::size_t>(s * s));
  for (int k = 0; k < s; ++k) {
    const auto beta = b.point_numerators(k);
    for (int i = 0; i < s; ++i) {
      const auto alpha = b.multi_indices()[static_cast<std::size_t>(i)];
      mpq_class val(fact(n));
      for (int a = 0; a <= d; ++a) {
        val /= fact(alpha[static_cast<std::size_t>(a)]);
        mpq_class l(beta[static_cast<std::size_t>(a)], b.point_denominator());
        l.canonicalize();
        for (int e = 0; e < alpha[static_cast<std::size_t>(a)]; ++e) val *= l;
      }
      v[static_cast<std::size_t>(k * s + i)] = val;
    }
  }
  const auto& t = b.exact().to_bezier;
  for (int r = 0; r < s; ++r)
    for (int c = 0; c < s; ++c) {
      mpq_class sum = 0;
      for (int k = 0; k < s; ++k) sum += t[static_cast<std::size_t>(r * s + k)] * v[static_cast<std::size_t>(k * s + c)];
      ASSERT_EQ(sum, mpq_class(r == c ? 1 : 0)) << r << "," << c;
    }
  // The double T is the rounded exact one, and the norm bounds its row sums.
  double worst = 0;
  for (int r = 0; r < s; ++r) {
    double row = 0;
    for (int c = 0; c < s; ++c) {
      const double got = b.lagrange_to_bezier()[static_cast<std::size_t>(r * s + c)];
      const mpq_class& q = t[static_cast<std::size_t>(r * s + c)];
      EXPECT_LE(std::abs(got - q.get_d()), 1e-15 * std::abs(q.get_d()) + 1e-300);
      row += std::abs(q.get_d());
    }
    worst = std::max(worst, row);
  }
  EXPECT_GE(b.lagrange_to_bezier_norm(), worst * (1 - 1e-14));
}

// Child coefficients give the same polynomial: child(x) == parent(map_q(x)).
TEST_P(FactorTest, SubdivisionReproducesValues) {
  const auto [d, n] = GetParam();
  const BernsteinSimplex& b = bernstein_simplex(d, n);
  const auto s = static_cast<std::size_t>(b.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coef(-1, 1);
  std::vector<double> parent(s), child(s), vp(s), vc(s);
  for (double& c : parent) c = coef(rng);
  for (int q = 0; q < b.num_children(); ++q) {
    const auto m = b.subdivision(q);
    for (std::size_t r = 0; r < s; ++r) {
      double row = 0;
      child[r] = 0;
      for (std::size_t c = 0; c < s; ++c) {
        EXPECT_GE(m[r * s + c], 0);
        row += m[r * s + c];
        child[r] += m[r * s + c] * parent[c];
      }
      EXPECT_EQ(row, 1.0);
    }
    const auto& w = b.child_vertices()[static_cast<std::size_t>(q)];
    for (int t = 0; t < 20; ++t) {
      const auto x = random_point(d, rng);
      std::array<double, 4> mu{1, 0, 0, 0};
      for (int c = 1; c <= d; ++c) {
        mu[static_cast<std::size_t>(c)] = x[static_cast<std::size_t>(c - 1)];
        mu[0] -= x[static_cast<std::size_t>(c - 1)];
      }
      // parent barycentric = sum_k mu_k w_k / 2
      std::array<double, 3> px{0, 0, 0};
      for (int c = 1; c <= d; ++c)
        for (int k = 0; k <= d; ++k)
          px[static_cast<std::size_t>(c - 1)] += mu[static_cast<std::size_t>(k)] *
              w[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)] / 2.0;
      b.evaluate(px, vp);
      b.evaluate(x, vc);
      double fp = 0, fc = 0;
      for (std::size_t i = 0; i < s; ++i) {
        fp += vp[i] * parent[i];
        fc += vc[i] * child[i];
      }
      EXPECT_NEAR(fp, fc, 1e-12);
    }
  }
}

// The vertex coefficients equal the polynomial's values at the vertices (eq. 17).
TEST_P(FactorTest, VertexCoefficientsAreValues) {
  const auto [d, n] = GetParam();
  const BernsteinSimplex& b = bernstein_simplex(d, n);
  int vertices = 0;
  std::vector<double> v(static_cast<std::size_t>(b.size()));
  for (int i = 0; i < b.size(); ++i) {
    if (!b.is_vertex(i)) continue;
    ++vertices;
    const auto a = b.multi_indices()[static_cast<std::size_t>(i)];
    std::array<double, 3> x{0, 0, 0};
    for (int c = 1; c <= d; ++c) x[static_cast<std::size_t>(c - 1)] = n == 0 ? 0 : a[static_cast<std::size_t>(c)] / double(n);
    b.evaluate(x, v);
    EXPECT_NEAR(v[static_cast<std::size_t>(i)], 1.0, 1e-15);
  }
  EXPECT_EQ(vertices, n == 0 ? 1 : d + 1);
}

INSTANTIATE_TEST_SUITE_P(AllFactors, FactorTest, testing::ValuesIn(factor_grid()),
                         [](const testing::TestParamInfo<DimDegree>& i) {
                           return "d" + std::to_string(i.param.dim) + "_n" +
                                  std::to_string(i.param.degree);
                         });

// Paper III eq. (23): T_LB for the quadratic triangle, nodes 1,2,3 (corners), 4 (mid 12),
// 5 (mid 23), 6 (mid 31).
TEST(BernsteinSimplexGolden, QuadraticTriangleMatchesEquation23) {
  const BernsteinSimplex& b = bernstein_simplex(2, 2);
  const auto index_of = [&](std::array<int, 4> a) {
    for (int i = 0; i < b.size(); ++i)
      if (b.multi_indices()[static_cast<std::size_t>(i)] == a) return i;
    return -1;
  };
  const int node[6] = {index_of({2, 0, 0, 0}), index_of({0, 2, 0, 0}), index_of({0, 0, 2, 0}),
                       index_of({1, 1, 0, 0}), index_of({0, 1, 1, 0}), index_of({1, 0, 1, 0})};
  const double want[6][6] = {{1, 0, 0, 0, 0, 0},       {0, 1, 0, 0, 0, 0},
                             {0, 0, 1, 0, 0, 0},       {-0.5, -0.5, 0, 2, 0, 0},
                             {0, -0.5, -0.5, 0, 2, 0}, {-0.5, 0, -0.5, 0, 0, 2}};
  const auto t = b.lagrange_to_bezier();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c)
      EXPECT_EQ(t[static_cast<std::size_t>(node[r] * 6 + node[c])], want[r][c]) << r << "," << c;
}

// De Casteljau at 1/2 in closed form: left child c_k = 2^-k sum_{j<=k} C(k,j) b_j.
TEST(BernsteinSimplexGolden, LineSubdivisionIsDeCasteljau) {
  for (int n = 1; n <= 10; ++n) {
    const BernsteinSimplex& b = bernstein_simplex(1, n);
    const auto s = static_cast<std::size_t>(n + 1);
    const auto left = b.subdivision(0);
    const auto right = b.subdivision(1);
    for (int k = 0; k <= n; ++k) {
      double binom = 1;
      for (int j = 0; j <= k; ++j) {
        EXPECT_EQ(left[static_cast<std::size_t>(k) * s + static_cast<std::size_t>(j)], std::ldexp(binom, -k));
        // right child mirrors: c_{n-k} from b_{n-j}
        EXPECT_EQ(right[static_cast<std::size_t>(n - k) * s + static_cast<std::size_t>(n - j)],
                  std::ldexp(binom, -k));
        binom = binom * (k - j) / (j + 1);
      }
    }
  }
}

// Table 1 of Paper III: number of coefficients of each family's Jacobian space
// (prisms: triangle degree 3p-2 times line degree 3p-1, see jacobian_factor_degrees).
TEST(BezierBasis, SizesFollowTable1) {
  for (int p = 1; p <= 3; ++p) {
    const int n2 = 2 * (p - 1), nq = 2 * p - 1, n3 = 3 * (p - 1), nh = 3 * p - 1;
    EXPECT_EQ(bezier_basis(ElementFamily::line, p).size(), p);
    EXPECT_EQ(bezier_basis(ElementFamily::triangle, p).size(), (n2 + 1) * (n2 + 2) / 2);
    EXPECT_EQ(bezier_basis(ElementFamily::quadrangle, p).size(), (nq + 1) * (nq + 1));
    EXPECT_EQ(bezier_basis(ElementFamily::tetrahedron, p).size(), (n3 + 1) * (n3 + 2) * (n3 + 3) / 6);
    EXPECT_EQ(bezier_basis(ElementFamily::hexahedron, p).size(), (nh + 1) * (nh + 1) * (nh + 1));
    EXPECT_EQ(bezier_basis(ElementFamily::prism, p).size(), (3 * p - 1) * 3 * p / 2 * (nh + 1));
    EXPECT_EQ(bezier_basis(ElementFamily::hexahedron, p).vertex_indices().size(), 8u);
    EXPECT_EQ(bezier_basis(ElementFamily::prism, p).vertex_indices().size(), 6u);
    EXPECT_EQ(bezier_basis(ElementFamily::quadrangle, p).vertex_indices().size(), 4u);
  }
  EXPECT_THROW(bezier_basis(ElementFamily::polygon, 1), std::invalid_argument);
  EXPECT_THROW(bezier_basis(ElementFamily::hexahedron, 0), std::invalid_argument);
}

// The tensor conversion equals the Kronecker product applied densely, and subdivision of a
// tensor basis reproduces values at mapped points.
class TensorTest : public testing::TestWithParam<std::tuple<ElementFamily, int>> {};

TEST_P(TensorTest, ToBezierThenEvaluateReproducesSamples) {
  const auto [family, p] = GetParam();
  const BezierBasis& b = bezier_basis(family, p);
  const auto s = static_cast<std::size_t>(b.size());
  // A polynomial given by random Bézier coefficients, sampled at the points, converted back.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coef(-1, 1);
  std::vector<double> c(s), samples(s), back(s), scratch(2 * s), v(s);
  for (double& x : c) x = coef(rng);
  for (std::size_t k = 0; k < s; ++k) {
    const auto x = b.point(static_cast<int>(k));
    b.evaluate(x, v);
    samples[k] = 0;
    for (std::size_t i = 0; i < s; ++i) samples[k] += v[i] * c[i];
  }
  b.to_bezier(samples.data(), back.data(), scratch.data());
  for (std::size_t i = 0; i < s; ++i) EXPECT_NEAR(back[i], c[i], 1e-9 * b.to_bezier_norm());
  // Children: value at a child point equals the parent's at the mapped point.
  std::vector<double> child(s);
  for (int q = 0; q < b.num_children(); ++q) {
    b.subdivide(q, c.data(), child.data(), scratch.data());
    const auto digits = b.child_digits(q);
    for (int t = 0; t < 5; ++t) {
      std::array<double, 3> x{0, 0, 0}, px{0, 0, 0};
      std::size_t off = 0;
      for (std::size_t f = 0; f < b.factors().size(); ++f) {
        const BernsteinSimplex& fac = *b.factors()[f];
        const auto xf = random_point(fac.dim(), rng);
        std::array<double, 4> mu{1, 0, 0, 0};
        for (int k = 1; k <= fac.dim(); ++k) {
          mu[static_cast<std::size_t>(k)] = xf[static_cast<std::size_t>(k - 1)];
          mu[0] -= xf[static_cast<std::size_t>(k - 1)];
        }
        const auto& w = fac.child_vertices()[static_cast<std::size_t>(digits[f])];
        for (int k = 1; k <= fac.dim(); ++k) {
          x[off + static_cast<std::size_t>(k - 1)] = xf[static_cast<std::size_t>(k - 1)];
          double pk = 0;
          for (int a = 0; a <= fac.dim(); ++a)
            pk += mu[static_cast<std::size_t>(a)] * w[static_cast<std::size_t>(a)][static_cast<std::size_t>(k)] / 2.0;
          px[off + static_cast<std::size_t>(k - 1)] = pk;
        }
        off += static_cast<std::size_t>(fac.dim());
      }
      b.evaluate(x, v);
      double fc = 0;
      for (std::size_t i = 0; i < s; ++i) fc += v[i] * child[i];
      b.evaluate(px, v);
      double fp = 0;
      for (std::size_t i = 0; i < s; ++i) fp += v[i] * c[i];
      EXPECT_NEAR(fc, fp, 1e-11);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Families, TensorTest,
    testing::Combine(testing::Values(ElementFamily::line, ElementFamily::triangle,
                                     ElementFamily::quadrangle, ElementFamily::tetrahedron,
                                     ElementFamily::prism, ElementFamily::hexahedron),
                     testing::Range(1, 4)));

// subdivide_many (several vectors, the matrix read once) gives the bits of subdivide applied
// to each vector: same products, summed in the same order.
TEST(BezierBasis, SubdivideManyEqualsSubdivideBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coef(-1, 1);
  for (const auto& [family, order] : std::vector<std::pair<ElementFamily, int>>{
           {ElementFamily::line, 5}, {ElementFamily::triangle, 4}, {ElementFamily::triangle, 9},
           {ElementFamily::tetrahedron, 2}, {ElementFamily::tetrahedron, 4},
           {ElementFamily::prism, 2}, {ElementFamily::hexahedron, 2}}) {
    const BezierBasis& b = bezier_basis(family, order);
    const auto s = static_cast<std::size_t>(b.size());
    for (std::size_t count : {1u, 3u, 6u, 9u}) {
      std::vector<double> parents(s * count), many(s * count), one(s), scratch(2 * s);
      for (double& x : parents) x = coef(rng);
      for (int q = 0; q < b.num_children(); ++q) {
        b.subdivide_many(q, parents.data(), count, many.data(), scratch.data());
        for (std::size_t v = 0; v < count; ++v) {
          b.subdivide(q, parents.data() + v * s, one.data(), scratch.data());
          EXPECT_EQ(std::memcmp(one.data(), many.data() + v * s, s * sizeof(double)), 0)
              << family_name(family) << " order " << order << " child " << q << " vector " << v;
        }
      }
    }
  }
}

}  // namespace
}  // namespace quadval
