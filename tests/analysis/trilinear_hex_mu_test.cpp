// The lane kernel of mu for first-order hexahedra (src/analysis/trilinear_hex_mu.hpp):
// against singular values of W sampled densely and at the corners (Eigen's SVD through the
// Lagrange basis, mu_test_util.hpp: no code shared with src/analysis/mu_*), the closed form
// of parallelepipeds, and the general path of mu_bounds on the same elements; its
// refinement (refine_trilinear_hex_ratio) against the same samples and the general path's.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "analysis/trilinear_hex_mu.hpp"
#include "first_order_mu_test_util.hpp"

namespace quadval {
namespace {

const ElementType& hexahedron8() { return test::first_order(ElementFamily::hexahedron); }

std::vector<double> random_hexahedron(int e, double amplitude, std::mt19937& rng) {
  return test::random_scaled_element(hexahedron8(), e, amplitude, rng);
}

TEST(TrilinearHexMu, BoundsEncloseSampledAndCornerValues) {
  std::mt19937 rng(17);
  const auto points = test::dense_points(ElementFamily::hexahedron, 10, 200, rng);
  const auto corners = reference_vertices(ElementFamily::hexahedron);
  test::check_against_samples(
      hexahedron8(), [](std::span<const double> x) { return trilinear_hex_ratio(x); },
      [](int e, std::mt19937& r) { return random_hexahedron(e, e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.15 : 0.4, r); },
      600, 500, points, {corners.begin(), corners.end()}, rng);
}

// The control matrices of M = W^T W, independently: M sampled (through the Lagrange
// basis) at the 3 x 3 x 3 grid of {-1, 0, 1}^3, then the tensor Bernstein interpolation of
// degree 2 (c_0 = g_0, c_2 = g_2, c_1 = 2 g_1 - (g_0 + g_2) / 2 along each direction). The
// kernel's lower bound is their least eigenvalue ratio (up to its certification margins):
// not higher (every control matrix counts) and not lower.
TEST(TrilinearHexMu, LowerBoundIsTheLeastControlMatrixRatio) {
  std::mt19937 rng(23);
  const ElementType& t = hexahedron8();
  const LagrangeBasis& basis = lagrange_basis(t);
  int interior = 0;
  for (int e = 0; e < 600; ++e) {
    const auto x = random_hexahedron(e, e % 2 == 0 ? 0.3 : 0.6, rng);
    const CertifiedRatio r = trilinear_hex_ratio(x);
    if (!r.ok) continue;
    Eigen::Matrix3d g[3][3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        for (int c = 0; c < 3; ++c) {
          const Eigen::MatrixXd j = test::physical_jacobian(basis, x, {a - 1.0, b - 1.0, c - 1.0});
          g[a][b][c] = j.transpose() * j;
        }
    const auto interpolate = [](Eigen::Matrix3d* v) {  // v[0], v[1], v[2] along one line
      v[1] = 2 * v[1] - 0.5 * (v[0] + v[2]);
    };
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3d line[3] = {g[0][b][c], g[1][b][c], g[2][b][c]};
        interpolate(line);
        for (int a = 0; a < 3; ++a) g[a][b][c] = line[a];
      }
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3d line[3] = {g[a][0][c], g[a][1][c], g[a][2][c]};
        interpolate(line);
        for (int b = 0; b < 3; ++b) g[a][b][c] = line[b];
      }
    double least = 1;
    bool least_inside = false;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        interpolate(g[a][b]);
        for (int c = 0; c < 3; ++c) {
          const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(g[a][b][c]);
          const double ratio = std::max(0.0, eig.eigenvalues()(0) / eig.eigenvalues()(2));
          if (ratio < least) {
            least = ratio;
            least_inside = a == 1 || b == 1 || c == 1;
          }
        }
      }
    interior += least_inside ? 1 : 0;
    EXPECT_NEAR(r.lower, least, 1e-9) << "element " << e;
  }
  EXPECT_GE(interior, 20);  // the least control matrix is not always at a corner
}

TEST(TrilinearHexMu, ParallelepipedsGetTheirStretchRatio) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1), s(0.05, 3);
  const ElementType& t = hexahedron8();
  for (int e = 0; e < 200; ++e) {
    // A rotation times a diagonal stretch: R = (s_min / s_max)^2 exactly.
    const Eigen::Matrix3d q = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized())
                                  .toRotationMatrix();
    const Eigen::Vector3d d(s(rng), s(rng), s(rng));
    const auto x = test::affine_ideal_element(t, q * d.asDiagonal(), Eigen::Vector3d(u(rng), u(rng), 7 * u(rng)));
    const CertifiedRatio r = trilinear_hex_ratio(x);
    ASSERT_TRUE(r.ok) << "element " << e;
    const double exact = std::pow(d.minCoeff() / d.maxCoeff(), 2);
    EXPECT_LE(r.lower, exact * (1 + 1e-14));
    EXPECT_GE(r.upper, exact * (1 - 1e-14));
    EXPECT_NEAR(r.lower, exact, 1e-11);
    EXPECT_NEAR(r.upper, exact, 1e-11);
  }
}

TEST(TrilinearHexMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(31);
  test::check_against_general_path(
      hexahedron8(), [](int e, std::mt19937& r) { return random_hexahedron(e, e % 2 == 0 ? 0.05 : 0.2, r); }, 300,
      100, rng);
}

// Elements the root does not settle, refined in the kernel (refine_trilinear_hex_ratio)
// and compared with pointwise R: the lower bound never above a sampled value; the upper
// bound never below every value of the grid of box corners it can come from (spacing
// 2^-ceil(h/3) per direction after h halvings in turn); both within tol of each other when
// settled, and no worse than the root's.
TEST(TrilinearHexMu, RefinementEnclosesSampledValues) {
  std::mt19937 rng(41);
  const ElementType& t = hexahedron8();
  const LagrangeBasis& basis = lagrange_basis(t);
  const auto points = test::dense_points(ElementFamily::hexahedron, 10, 200, rng);
  BoundsWorkspace workspace;
  int refined = 0, settled = 0, gridded = 0;
  for (int e = 0; e < 1500; ++e) {
    const auto x = random_hexahedron(e, e % 2 == 0 ? 0.7 : 0.9, rng);
    if (jacobian_bounds(t, x, BoundsOptions{}, workspace).validity != Validity::valid) continue;
    const double tol = e % 3 == 0 ? 1e-3 : 1e-2;
    const CertifiedRatio root = trilinear_hex_ratio(x);
    if (!root.ok || std::sqrt(root.upper) - std::sqrt(root.lower) <= tol) continue;
    ++refined;
    const RefinedRatio r = refine_trilinear_hex_ratio(x, root, tol, 72);
    ASSERT_TRUE(r.ratio.ok) << "element " << e;
    ASSERT_GT(r.halvings, 0);
    const test::SampledMu sampled = test::sample_mu(basis, x, points);
    EXPECT_LE(r.ratio.lower, sampled.lo * sampled.lo * (1 + 1e-12)) << "element " << e;
    EXPECT_GE(r.ratio.lower, root.lower) << "element " << e;
    EXPECT_LE(r.ratio.upper, root.upper) << "element " << e;
    if (r.settled) {
      ++settled;
      EXPECT_LE(std::sqrt(r.ratio.upper) - std::sqrt(r.ratio.lower), tol * (1 + 1e-9)) << "element " << e;
    }
    if (r.halvings <= 9) {
      ++gridded;
      const int n = 1 << ((r.halvings + 2) / 3);
      double grid_min = 1;
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
          for (int k = 0; k <= n; ++k) {
            const double m = test::pointwise_mu(basis, x, {-1 + 2.0 * i / n, -1 + 2.0 * j / n, -1 + 2.0 * k / n});
            grid_min = std::min(grid_min, m * m);
          }
      EXPECT_GE(r.ratio.upper, grid_min * (1 - 1e-9)) << "element " << e;
    }
  }
  std::printf("[hexahedron refinement] %d refined, %d settled, %d checked on their grid\n", refined, settled, gridded);
  EXPECT_GE(refined, 100);
  EXPECT_GE(settled, refined * 95 / 100);
  EXPECT_GE(gridded, refined / 2);
}

// mu_bounds refines first-order hexahedra in the kernel (the default) or on the general
// path (mu_use_constant_path(false)): both meet the tolerance and their intervals overlap.
TEST(TrilinearHexMu, RefinementAgreesWithTheGeneralPath) {
  std::mt19937 rng(43);
  const ElementType& t = hexahedron8();
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  int subdivided = 0, valid = 0;
  for (int e = 0; e < 1000; ++e) {
    const auto [fast, general] = test::mu_both_paths(t, random_hexahedron(e, 0.8, rng), opt);
    EXPECT_EQ(fast.tolerance_met, general.tolerance_met) << "element " << e;
    EXPECT_LE(fast.lower, general.upper) << "element " << e;
    EXPECT_LE(general.lower, fast.upper) << "element " << e;
    if (fast.upper > 0) ++valid;
    if (fast.subdivisions > 0 && fast.upper > 0) ++subdivided;
  }
  std::printf("[hexahedron refinement] %d valid, %d subdivided\n", valid, subdivided);
  EXPECT_GE(subdivided, 50);
}

}  // namespace
}  // namespace quadval
