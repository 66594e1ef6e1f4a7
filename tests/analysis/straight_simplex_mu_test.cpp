// The lane-parallel closed form of mu for straight-sided tetrahedra and planar triangles
// (src/analysis/straight_simplex_mu.hpp): against the singular values of W in long double
// (an oracle sharing no code with it), lane by lane the same whatever the lane, and in the
// check (kNativeLanes elements at a time) bit for bit what mu_bounds gives each element
// alone; and the scaled Jacobian's closed form of straight-sided simplices in lanes, likewise.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

#include "analysis/lane_vector.hpp"
#include "analysis/mu_space.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "analysis/straight_simplex_mu.hpp"
#include "check_alone_test_util.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

using Matrix3l = Eigen::Matrix<long double, 3, 3>;

// R = (sigma_min / sigma_max)^2 of W = [edges] Jinv, in long double.
long double exact_ratio(const double* edges, const std::array<double, 9>& jinv) {
  Matrix3l a, j;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      a(k, c) = edges[3 * c + k];  // column c: edge c
      j(c, k) = jinv[static_cast<std::size_t>(c * 3 + k)];
    }
  const Eigen::JacobiSVD<Matrix3l> svd(a * j);
  const auto s = svd.singularValues();
  return (s(2) / s(0)) * (s(2) / s(0));
}

// R of a triangle in a plane z = const: W = [edges] Jinv is 3 x 2 (the z row zero), its
// two singular values in long double.
long double exact_triangle_ratio(const double* edges, const std::array<double, 9>& jinv) {
  Eigen::Matrix<long double, 3, 2> a;
  Eigen::Matrix<long double, 2, 2> j;
  for (int c = 0; c < 2; ++c) {
    for (int k = 0; k < 3; ++k) a(k, c) = edges[3 * c + k];
    for (int k = 0; k < 2; ++k) j(c, k) = jinv[static_cast<std::size_t>(c * 3 + k)];
  }
  const Eigen::JacobiSVD<Eigen::Matrix<long double, 3, 2>> svd(a * j);
  const auto s = svd.singularValues();
  return (s(1) / s(0)) * (s(1) / s(0));
}

// Edges of a random tetrahedron: well shaped, stretched, nearly flat or with a nearly
// vanishing edge, at scales from 1e-9 to 1e6.
std::array<double, 9> random_edges(int e, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  const double scale = e % 7 == 0 ? 1e-9 : e % 11 == 0 ? 1e6 : 1;
  std::array<double, 9> a{};
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t k = 0; k < 3; ++k) a[3 * c + k] = scale * ((c == k ? 1.0 : 0.0) + 0.6 * u(rng));
  if (e % 5 == 1)  // nearly flat: edge 2 close to a combination of the others
    for (std::size_t k = 0; k < 3; ++k) a[6 + k] = 0.4 * a[k] + 0.5 * a[3 + k] + scale * 1e-5 * u(rng);
  if (e % 5 == 2)  // stretched along one axis
    for (std::size_t c = 0; c < 3; ++c) a[3 * c] *= 50;
  if (e % 13 == 3)  // one edge almost nothing
    for (std::size_t k = 0; k < 3; ++k) a[k] *= 1e-7;
  return a;
}

// straight_tet_ratio (dim 3) or straight_triangle_ratio (dim 2, edges 0 and 1 of
// random_edges in the plane: z differences 0) at the checks' width, on random simplices:
// each lane the same bits as the element alone (in both lanes of two), enclosing the
// singular-value ratio, and tight.
template <class Ratio>
void expect_lanes_enclose_the_singular_value_ratio(int dim, unsigned seed, Ratio ratio) {
  std::mt19937 rng(seed);
  const std::array<double, 9>& jinv = mu_space(*find_element_type(dim == 3 ? 4 : 2)).ideal_inverse();
  constexpr int kW = kNativeLanes;  // the width the checks run at
  int ok = 0, total = 0;
  for (int block = 0; block < 400; ++block) {
    std::array<std::array<double, 9>, kW> edges;
    std::array<double, kW> margin{};
    Lanes<kW> a[9] = {}, beta[3] = {};
    for (int l = 0; l < kW; ++l) {
      auto& x = edges[static_cast<std::size_t>(l)];
      x = random_edges(block * kW + l, rng);
      if (dim == 2) {
        x[2] = x[5] = x[6] = x[7] = x[8] = 0;
        if ((block * kW + l) % 5 == 1)  // nearly flat: edge 1 close to a multiple of edge 0
          for (std::size_t k = 0; k < 2; ++k) x[3 + k] = 0.7 * x[k] + 1e-5 * std::abs(x[0]) * (k == 0 ? 1 : -1);
      }
      // Half the blocks with a straight-sided margin on the columns (higher-order nodes).
      margin[static_cast<std::size_t>(l)] = block % 2 == 0 ? 0.0 : 1e-9 * std::abs(x[0]);
      for (int v = 0; v < 3 * dim; ++v) a[v][l] = x[static_cast<std::size_t>(v)];
      for (int c = 0; c < dim; ++c) beta[c][l] = margin[static_cast<std::size_t>(l)];
    }
    const StraightSimplexRatio<kW> r = ratio(a, beta, jinv);
    for (int l = 0; l < kW; ++l) {
      ++total;
      const auto& x = edges[static_cast<std::size_t>(l)];
      Lanes<2> a2[9] = {}, b2[3] = {};
      for (int v = 0; v < 3 * dim; ++v) a2[v] = broadcast_lanes<2>(x[static_cast<std::size_t>(v)]);
      for (int c = 0; c < dim; ++c) b2[c] = broadcast_lanes<2>(margin[static_cast<std::size_t>(l)]);
      const StraightSimplexRatio<2> alone = ratio(a2, b2, jinv);
      ASSERT_EQ((r.ok >> l) & 1u, alone.ok & 1u) << "element " << block * kW + l;
      if (((r.ok >> l) & 1u) == 0) continue;
      ++ok;
      EXPECT_EQ(r.lower[l], alone.lower[0]);
      EXPECT_EQ(r.upper[l], alone.upper[0]);
      const long double exact = dim == 3 ? exact_ratio(x.data(), jinv) : exact_triangle_ratio(x.data(), jinv);
      EXPECT_LE(r.lower[l], exact * (1 + 1e-15L)) << "element " << block * kW + l;
      EXPECT_GE(r.upper[l], exact * (1 - 1e-15L)) << "element " << block * kW + l;
      EXPECT_LE(r.lower[l], r.upper[l]);
      // Tight: to rounding without a margin, within a few margins (relative 1e-9) with one.
      const double gap = margin[static_cast<std::size_t>(l)] == 0 ? 1e-7 : 1e-4;
      if (exact > 1e-3L) {
        EXPECT_LE(r.upper[l] - r.lower[l], gap * static_cast<double>(exact)) << "element " << block * kW + l;
      }
    }
  }
  EXPECT_GT(ok, total * 3 / 4);  // the rest: nearly degenerate, left to the general path
}

TEST(StraightSimplexMu, LanesEncloseTheSingularValueRatioAndAgreeAcrossLanes) {
  expect_lanes_enclose_the_singular_value_ratio(3, 5150, [](const auto* a, const auto* beta, const auto& jinv) {
    constexpr int kWidth = sizeof(*a) / sizeof(double);
    return straight_tet_ratio<kWidth>(a, beta, jinv);
  });
}

TEST(StraightSimplexMu, TriangleLanesEncloseTheSingularValueRatioAndAgreeAcrossLanes) {
  expect_lanes_enclose_the_singular_value_ratio(2, 5152, [](const auto* a, const auto* beta, const auto& jinv) {
    constexpr int kWidth = sizeof(*a) / sizeof(double);
    return straight_triangle_ratio<kWidth>(a, beta, jinv);
  });
  constexpr int kW = kNativeLanes;
  const std::array<double, 9>& jinv = mu_space(*find_element_type(2)).ideal_inverse();
  // Closed forms, each at scales 2^-15 .. 2^15: the equilateral triangle R = 1; stretched
  // by 3 along x, R = 1/9 (the ratio of its stretches, squared); the right isosceles one
  // with legs along the axes, W = Jinv = [1, -1/sqrt 3; 0, 2/sqrt 3], W^T W with
  // eigenvalues 2 and 2/3, R = 1/3.
  const double h = std::sqrt(3.0) / 2;
  const std::array<std::pair<std::array<double, 4>, double>, 3> cases{{
      {{1, 0, 0.5, h}, 1.0}, {{3, 0, 1.5, h}, 1.0 / 9}, {{1, 0, 0, 1}, 1.0 / 3}}};
  for (const auto& [e, exact] : cases) {
    Lanes<kW> a[9] = {}, beta[3] = {};
    for (int l = 0; l < kW; ++l) {
      const double scale = std::ldexp(1.0, 10 * l - 15);
      a[0][l] = e[0] * scale;
      a[1][l] = e[1] * scale;
      a[3][l] = e[2] * scale;
      a[4][l] = e[3] * scale;
    }
    const StraightSimplexRatio<kW> r = straight_triangle_ratio<kW>(a, beta, jinv);
    ASSERT_EQ(r.ok, (1u << kW) - 1) << exact;
    for (int l = 0; l < kW; ++l) {
      EXPECT_LE(r.lower[l], exact * (1 + 1e-15)) << exact;
      EXPECT_GE(r.upper[l], exact * (1 - 1e-15)) << exact;
      EXPECT_LT(r.upper[l] - r.lower[l], 1e-12) << exact;
    }
  }
}

// Simplices of `type` at random, tetrahedra or triangles in the plane z = 0.25:
// straight-sided (edge nodes straight, off by a rounding-sized deviation in the element's
// coordinates, which gives a margin) or curved, some inverted.
std::vector<std::vector<double>> random_simplices(const ElementType& type, int count, std::mt19937& rng) {
  const std::size_t dim = type.dim == 2 ? 2 : 3;
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::vector<double>> elements;
  for (int e = 0; e < count; ++e) {
    const auto a = random_edges(e, rng);
    double origin[3] = {0, 0, 0.25};
    for (std::size_t k = 0; k < dim; ++k) origin[k] = u(rng);
    const double sign = e % 6 == 4 ? -1 : 1;
    const double deviation = e % 4 == 0 ? 0.0 : e % 4 == 1 ? 1e-13 : e % 4 == 2 ? 1e-9 : 1e-2;
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(type))
      for (std::size_t k = 0; k < 3; ++k) {
        double v = origin[k];
        if (k < dim) {
          for (std::size_t c = 0; c < dim; ++c) v += sign * p[c] * a[3 * c + k];
          const bool vertex = x.size() < 3 * (dim + 1);
          if (!vertex) v += deviation * std::abs(a[k]) * u(rng);
        }
        x.push_back(v);
      }
    elements.push_back(std::move(x));
  }
  return elements;
}

// The check's chunks (mu and the scaled Jacobian of valid straight-sided tetrahedra and
// planar triangles, kNativeLanes at a time) give each element exactly what mu_bounds and
// scaled_jacobian_bounds give it alone, the fallbacks included, for first-order elements
// and quadratic and cubic ones (straight, with a margin, or curved).
TEST(StraightSimplexMu, CheckChunksMatchEachElementAloneBitForBit) {
  std::mt19937 rng(77);
  for (const int id : {4, 11, 29, 2, 9, 21}) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    const bool planar = type.dim == 2;
    const auto elements = random_simplices(type, 1500, rng);
    EXPECT_GT(test::expect_check_matches_alone(
                  type, elements, CheckMeasure::mu,
                  [&](const std::vector<double>& x, const QualityOptions& q) { return mu_bounds(type, x, q, planar); }),
              700);
    EXPECT_GT(test::expect_check_matches_alone(type, elements, CheckMeasure::scaled_jacobian,
                                               [&](const std::vector<double>& x, const QualityOptions& q) {
                                                 return scaled_jacobian_bounds(type, x, q, planar);
                                               }),
              700);
  }
}

// straight_simplex_sj_lanes lane by lane: what scaled_jacobian_bounds_given gives the element
// alone (with the same margins), whatever its neighbours; a lane whose margin is infinite, or
// whose closed form misses the tolerance, is left to that call. The closed form of a
// straight tetrahedron is the scaled Jacobian's exact value up to rounding: sj of the
// regular tetrahedron is 1, at every scale and orientation.
TEST(StraightSimplexMu, ScaledJacobianLanesAreEachElementsOwnBounds) {
  std::mt19937 rng(5151);
  const ElementType& type = *find_element_type(4);
  constexpr int kW = kNativeLanes;
  QualityOptions q;
  q.abs_tol = 1e-2;
  int taken = 0, declined = 0;
  for (int block = 0; block < 400; ++block) {
    std::array<std::vector<double>, kW> x;
    Lanes<kW> a[9], beta[3] = {}, margin{};
    for (int l = 0; l < kW; ++l) {
      const auto edges = random_edges(block * kW + l, rng);
      auto& xl = x[static_cast<std::size_t>(l)];
      xl.assign(12, 0.0);
      for (std::size_t v = 0; v < 9; ++v) xl[3 + v] = edges[v];
      for (int v = 0; v < 9; ++v) a[v][l] = xl[static_cast<std::size_t>(3 + v)] - xl[static_cast<std::size_t>(v % 3)];
      if (block % 9 == 4 && l == 1) margin[l] = INFINITY;
    }
    std::array<QualityBounds, kW> out{};
    const unsigned done = straight_simplex_sj_lanes(type, a, beta, margin, q.abs_tol, out.data());
    for (int l = 0; l < kW; ++l) {
      const auto& xl = x[static_cast<std::size_t>(l)];
      if (!std::isfinite(margin[l])) {
        EXPECT_EQ((done >> l) & 1u, 0u);
        continue;
      }
      const QualityBounds alone = scaled_jacobian_bounds(type, xl, q, false);
      if (((done >> l) & 1u) == 0) {
        ++declined;
        continue;
      }
      ++taken;
      EXPECT_EQ(out[static_cast<std::size_t>(l)].lower, alone.lower) << "element " << block * kW + l;
      EXPECT_EQ(out[static_cast<std::size_t>(l)].upper, alone.upper) << "element " << block * kW + l;
      EXPECT_TRUE(out[static_cast<std::size_t>(l)].tolerance_met);
      EXPECT_EQ(alone.subdivisions, 0);
    }
  }
  EXPECT_GT(taken, 1000);
  EXPECT_GT(declined, 0);  // inverted and nearly flat ones: the general path
  // The regular tetrahedron, scaled and placed anywhere: sj = 1 in every lane.
  Lanes<kW> a[9], beta[3] = {}, margin{};
  const double regular[9] = {1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0, 0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)};
  for (int l = 0; l < kW; ++l)
    for (int v = 0; v < 9; ++v) a[v][l] = std::ldexp(regular[v], 10 * l - 15);
  std::array<QualityBounds, kW> out{};
  ASSERT_EQ(straight_simplex_sj_lanes(type, a, beta, margin, 1e-2, out.data()), (1u << kW) - 1);
  for (const QualityBounds& b : out) {
    EXPECT_LE(b.lower, 1.0);
    EXPECT_GE(b.upper, 1.0);
    EXPECT_LT(b.upper - b.lower, 1e-9);
  }
}

}  // namespace
}  // namespace quadval
