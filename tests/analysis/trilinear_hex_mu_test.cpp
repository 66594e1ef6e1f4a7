// The lane kernel of mu for first-order hexahedra (src/analysis/trilinear_hex_mu.hpp):
// against singular values of W sampled densely and at the corners (Eigen's SVD through the
// Lagrange basis, mu_test_util.hpp: no code shared with src/analysis/mu_*), the closed form
// of parallelepipeds, and the general path of mu_bounds on the same elements.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "analysis/mu_constant.hpp"
#include "analysis/trilinear_hex_mu.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

const ElementType& hexahedron8() {
  for (const ElementType& t : element_types())
    if (t.family == ElementFamily::hexahedron && t.num_nodes == 8) return t;
  throw std::logic_error("no first-order hexahedron");
}

// A random first-order hexahedron: an affine image of the reference cube (random_element)
// with its vertices moved by up to `amplitude`, at scales from 1e-6 to 1e5.
std::vector<double> random_hexahedron(int e, double amplitude, std::mt19937& rng) {
  std::vector<double> x = test::random_element(hexahedron8(), amplitude, rng);
  const double scale = e % 7 == 0 ? 1e-6 : e % 11 == 0 ? 1e5 : 1;
  for (double& v : x) v *= scale;
  return x;
}

std::vector<RefPoint> corner_points() {
  std::vector<RefPoint> p;
  for (const RefPoint& v : reference_vertices(ElementFamily::hexahedron)) p.push_back(v);
  return p;
}

TEST(TrilinearHexMu, BoundsEncloseSampledAndCornerValues) {
  std::mt19937 rng(17);
  const ElementType& t = hexahedron8();
  const LagrangeBasis& basis = lagrange_basis(t);
  const auto points = test::dense_points(ElementFamily::hexahedron, 10, 200, rng);
  const auto corners = corner_points();
  BoundsOptions bounds_options;
  BoundsWorkspace workspace;
  int valid = 0, ok = 0, settled = 0;
  for (int e = 0; e < 600; ++e) {
    const double amplitude = e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.15 : 0.4;
    const auto x = random_hexahedron(e, amplitude, rng);
    if (jacobian_bounds(t, x, bounds_options, workspace).validity != Validity::valid) continue;
    ++valid;
    const CertifiedRatio r = trilinear_hex_ratio(x);
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
    // lower <= R everywhere; upper >= the least corner value (>= min R), and within
    // rounding of it (Rayleigh quotients at good eigenvectors).
    EXPECT_LE(r.lower, sampled.lo * sampled.lo * (1 + 1e-12)) << "element " << e;
    EXPECT_GE(r.upper, corner_r * (1 - 1e-12)) << "element " << e;
    EXPECT_LE(r.upper, corner_r * (1 + 1e-9)) << "element " << e;
    if (std::sqrt(r.upper) - std::sqrt(r.lower) <= 1e-2) ++settled;
  }
  std::printf("[trilinear hex mu] %d valid, %d certified, %d within 1e-2\n", valid, ok, settled);
  EXPECT_GE(valid, 500);
  EXPECT_GE(ok, valid * 98 / 100);
  EXPECT_GE(settled, valid / 2);
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

// mu_bounds with the kernel (the default) and with the general path alone: overlapping
// intervals, the same elements settled at the root, and bounds equal to rounding.
TEST(TrilinearHexMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(31);
  const ElementType& t = hexahedron8();
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  int root = 0;
  for (int e = 0; e < 300; ++e) {
    const auto x = random_hexahedron(e, e % 2 == 0 ? 0.05 : 0.2, rng);
    const QualityBounds fast = mu_bounds(t, x, opt, false);
    mu_use_constant_path(false);
    const QualityBounds general = mu_bounds(t, x, opt, false);
    mu_use_constant_path(true);
    EXPECT_LE(fast.lower, general.upper) << "element " << e;
    EXPECT_LE(general.lower, fast.upper) << "element " << e;
    EXPECT_EQ(fast.subdivisions == 0, general.subdivisions == 0) << "element " << e;
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
