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
#include "analysis/mu_constant.hpp"
#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

const ElementType& pyramid5() {
  for (const ElementType& t : element_types())
    if (t.family == ElementFamily::pyramid && t.num_nodes == 5) return t;
  throw std::logic_error("no first-order pyramid");
}

const std::array<double, 9>& jinv() { return mu_space(pyramid5()).ideal_inverse(); }

// A random first-order pyramid (random_element: an affine image of the reference one, its
// nodes moved by up to `amplitude`), at scales from 1e-6 to 1e5.
std::vector<double> random_pyramid(int e, double amplitude, std::mt19937& rng) {
  std::vector<double> x = test::random_element(pyramid5(), amplitude, rng);
  const double scale = e % 7 == 0 ? 1e-6 : e % 11 == 0 ? 1e5 : 1;
  for (double& v : x) v *= scale;
  return x;
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
  const ElementType& t = pyramid5();
  const LagrangeBasis& basis = lagrange_basis(t);
  auto points = test::dense_points(ElementFamily::pyramid, 8, 200, rng);
  const auto square = base_points(16);
  points.insert(points.end(), square.begin(), square.end());
  const auto corners = base_points(1);
  BoundsOptions bounds_options;
  BoundsWorkspace workspace;
  int valid = 0, ok = 0, settled = 0;
  for (int e = 0; e < 600; ++e) {
    const double amplitude = e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.15 : 0.4;
    const auto x = random_pyramid(e, amplitude, rng);
    if (jacobian_bounds(t, x, bounds_options, workspace).validity != Validity::valid) continue;
    ++valid;
    const CertifiedRatio r = linear_pyramid_ratio(x, jinv());
    if (!r.ok) continue;
    ++ok;
    ASSERT_LE(0.0, r.lower);
    ASSERT_LE(r.lower, r.upper);
    ASSERT_LE(r.upper, 1.0);
    const test::SampledMu sampled = test::sample_mu(basis, x, points);
    ASSERT_FALSE(sampled.j_nonpositive);
    double corner_min = 1;
    for (const RefPoint& p : corners) corner_min = std::min(corner_min, test::pointwise_mu(basis, x, p));
    const double corner_r = corner_min * corner_min;
    EXPECT_LE(r.lower, sampled.lo * sampled.lo * (1 + 1e-12)) << "element " << e;
    EXPECT_GE(r.upper, corner_r * (1 - 1e-12)) << "element " << e;
    EXPECT_LE(r.upper, corner_r * (1 + 1e-9)) << "element " << e;
    if (std::sqrt(r.upper) - std::sqrt(r.lower) <= 1e-2) ++settled;
  }
  std::printf("[linear pyramid mu] %d valid, %d certified, %d within 1e-2\n", valid, ok, settled);
  EXPECT_GE(valid, 300);
  EXPECT_GE(ok, valid * 98 / 100);
  EXPECT_GE(settled, valid / 2);
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
  const LagrangeBasis& basis = lagrange_basis(t);
  int checked = 0;
  for (int e = 0; e < 300; ++e) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(i, j) = (i == j ? 1.0 : 0.0) + 0.4 * u(rng);
    std::vector<double> x = test::affine_ideal_element(t, a, Eigen::Vector3d(u(rng), u(rng), 5 * u(rng)));
    for (int k = 0; k < 3; ++k) x[static_cast<std::size_t>(12 + k)] += 0.2 * u(rng);  // the apex anywhere
    BoundsOptions bo;
    BoundsWorkspace ws;
    if (jacobian_bounds(t, x, bo, ws).validity != Validity::valid) continue;
    const CertifiedRatio r = linear_pyramid_ratio(x, jinv());
    ASSERT_TRUE(r.ok) << "element " << e;
    const double mu = test::pointwise_mu(basis, x, {0.3, -0.2, 0.4});
    EXPECT_LE(r.lower, mu * mu * (1 + 1e-12));
    EXPECT_GE(r.upper, mu * mu * (1 - 1e-12));
    EXPECT_NEAR(r.lower, mu * mu, 1e-8);
    EXPECT_NEAR(r.upper, mu * mu, 1e-8);
    ++checked;
  }
  EXPECT_GE(checked, 150);
}

// mu_bounds with the kernel (the default) and with the general path alone.
TEST(LinearPyramidMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(53);
  const ElementType& t = pyramid5();
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  int root = 0;
  for (int e = 0; e < 300; ++e) {
    const auto x = random_pyramid(e, e % 2 == 0 ? 0.05 : 0.2, rng);
    const QualityBounds fast = mu_bounds(t, x, opt, false);
    mu_use_constant_path(false);
    const QualityBounds general = mu_bounds(t, x, opt, false);
    mu_use_constant_path(true);
    EXPECT_LE(fast.lower, general.upper) << "element " << e;
    EXPECT_LE(general.lower, fast.upper) << "element " << e;
    if (fast.subdivisions == 0 && general.subdivisions == 0 && fast.upper > 0) {
      ++root;
      EXPECT_NEAR(fast.lower, general.lower, 1e-10) << "element " << e;
      EXPECT_NEAR(fast.upper, general.upper, 1e-10) << "element " << e;
    }
  }
  EXPECT_GE(root, 100);
}

}  // namespace
}  // namespace quadval
