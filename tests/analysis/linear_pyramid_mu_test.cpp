// The lane kernel of mu for first-order pyramids (src/analysis/linear_pyramid_mu.hpp):
// against singular values of W sampled densely and at the base corners (Eigen's SVD
// through the Lagrange basis, mu_test_util.hpp: no code shared with src/analysis/mu_*), its
// control matrices computed independently, the constant W of a parallelogram base, and the
// general path of mu_bounds on the same elements.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "analysis/linear_pyramid_mu.hpp"
#include "analysis/mu_space.hpp"
#include "check_alone_test_util.hpp"
#include "first_order_mu_test_util.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

const ElementType& pyramid5() { return test::first_order(ElementFamily::pyramid); }

const std::array<double, 9>& jinv() { return mu_space(pyramid5()).ideal_inverse(); }

std::vector<double> random_pyramid(int e, double amplitude, std::mt19937& rng) {
  return test::random_scaled_element(pyramid5(), e, amplitude, rng);
}

// Points of the base square at zeta = 0, where W takes every value it takes on the pyramid.
std::vector<RefPoint> base_points(int n) {
  std::vector<RefPoint> p;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) p.push_back({-1.0 + 2.0 * i / n, -1.0 + 2.0 * j / n, 0.0});
  return p;
}

TEST(LinearPyramidMu, BoundsEncloseSampledAndCornerValues) {
  std::mt19937 rng(41);
  auto points = test::dense_points(ElementFamily::pyramid, 8, 200, rng);
  const auto square = base_points(16);
  points.insert(points.end(), square.begin(), square.end());
  test::check_against_samples(
      pyramid5(), [](std::span<const double> x) { return linear_pyramid_ratio(x, jinv()); },
      [](int e, std::mt19937& r) { return random_pyramid(e, e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.15 : 0.4, r); }, 600,
      300, points, base_points(1), rng);
}

// The control matrices of M = W^T W, independently: M sampled at the 3 x 3 grid of the base
// square, then the tensor Bernstein interpolation of degree 2 (c_1 = 2 g_1 - (g_0 + g_2) / 2
// along each direction). The kernel's lower bound is their least eigenvalue ratio.
TEST(LinearPyramidMu, LowerBoundIsTheLeastControlMatrixRatio) {
  std::mt19937 rng(43);
  const ElementType& t = pyramid5();
  const LagrangeBasis& basis = lagrange_basis(t);
  const Eigen::Matrix3d ji_inv = test::ideal_jacobian(ElementFamily::pyramid).inverse();
  int interior = 0, general = 0;
  for (int e = 0; e < 600; ++e) {
    const auto x = random_pyramid(e, e % 2 == 0 ? 0.2 : 0.4, rng);
    const CertifiedRatio r = linear_pyramid_ratio(x, jinv());
    if (!r.ok) continue;
    Eigen::Matrix3d g[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const Eigen::Matrix3d w = test::physical_jacobian(basis, x, {a - 1.0, b - 1.0, 0.0}) * ji_inv;
        g[a][b] = w.transpose() * w;
      }
    for (int b = 0; b < 3; ++b) g[1][b] = 2 * g[1][b] - 0.5 * (g[0][b] + g[2][b]);
    for (int a = 0; a < 3; ++a) g[a][1] = 2 * g[a][1] - 0.5 * (g[a][0] + g[a][2]);
    double least = 1;
    bool least_inside = false;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(g[a][b]);
        const double ratio = std::max(0.0, eig.eigenvalues()(0) / eig.eigenvalues()(2));
        if (ratio < least) {
          least = ratio;
          least_inside = a == 1 || b == 1;
        }
      }
    ++general;
    interior += least_inside ? 1 : 0;
    EXPECT_NEAR(r.lower, least, 1e-9) << "element " << e;
  }
  EXPECT_GE(general, 300);
  EXPECT_GE(interior, 10);  // the least control matrix is not always at a corner
}

// A parallelogram base makes W constant, whatever the apex: R is that of W at any point.
TEST(LinearPyramidMu, ParallelogramBasesGetTheirConstantRatio) {
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = pyramid5();
  int checked = 0;
  for (int e = 0; e < 300; ++e) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(i, j) = (i == j ? 1.0 : 0.0) + 0.4 * u(rng);
    std::vector<double> x = test::affine_ideal_element(t, a, Eigen::Vector3d(u(rng), u(rng), 5 * u(rng)));
    for (int k = 0; k < 3; ++k) x[static_cast<std::size_t>(12 + k)] += 0.2 * u(rng);  // the apex anywhere
    const auto kernel = [](std::span<const double> y) { return linear_pyramid_ratio(y, jinv()); };
    if (test::check_constant_ratio(t, x, kernel, {0.3, -0.2, 0.4}, e)) ++checked;
  }
  EXPECT_GE(checked, 150);
}

TEST(LinearPyramidMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(53);
  test::check_against_general_path(
      pyramid5(), [](int e, std::mt19937& r) { return random_pyramid(e, e % 2 == 0 ? 0.05 : 0.2, r); }, 300, 100, rng);
}

// The check computes mu of first-order pyramids with a parallelogram base four at a time
// (linear_pyramid_mu_lanes): every element gets the bits mu_bounds gives it alone, whether
// its neighbours in the lanes have a constant W, a general one, or are inverted.
TEST(LinearPyramidMu, CheckChunksMatchEachElementAloneBitForBit) {
  std::mt19937 rng(61);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = pyramid5();
  std::vector<std::vector<double>> elements;
  int parallelograms = 0;
  for (int e = 0; e < 1200; ++e) {
    if (e % 3 == 2) {
      elements.push_back(random_pyramid(e, e % 2 == 0 ? 0.05 : 0.3, rng));
      continue;
    }
    Eigen::Matrix3d a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(i, j) = (i == j ? 1.0 : 0.0) + 0.4 * u(rng);
    if (e % 17 == 0) a.col(2) *= -1;  // inverted
    std::vector<double> x = test::affine_ideal_element(t, a, Eigen::Vector3d(u(rng), u(rng), 5 * u(rng)));
    for (int k = 0; k < 3; ++k) x[static_cast<std::size_t>(12 + k)] += 0.2 * u(rng);  // the apex anywhere
    elements.push_back(x);
    ++parallelograms;
  }
  EXPECT_GT(parallelograms, 700);
  EXPECT_GT(test::expect_check_matches_alone(
                t, elements, CheckMeasure::mu,
                [&](const std::vector<double>& x, const QualityOptions& q) { return mu_bounds(t, x, q, false); }),
            900);
}

}  // namespace
}  // namespace quadval
