// The closed forms of mu for constant W (src/analysis/mu_constant.hpp) against Eigen's SVD
// (the exact singular values of affine elements and of sampled matrices of the box) and
// against the general path of mu_bounds on thousands of random affine elements.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

#include "analysis/mu_constant.hpp"
#include "analysis/mu_space.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "jacobian_test_util.hpp"
#include "scaled_jacobian_test_util.hpp"

namespace quadval {
namespace {

double svd_ratio(const Eigen::MatrixXd& w) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(w);
  const auto s = svd.singularValues();
  return s(s.size() - 1) / s(0);
}

// Control values of a constant W in the layout of MuMetric::lower_bound.
std::vector<double> constant_controls(const MuSpace& space, const Eigen::MatrixXd& w) {
  const auto ws = static_cast<std::size_t>(space.w_size());
  std::vector<double> out(static_cast<std::size_t>(space.dim() * 3) * ws);
  for (int j = 0; j < space.dim(); ++j)
    for (int c = 0; c < 3; ++c)
      for (std::size_t k = 0; k < ws; ++k) out[(static_cast<std::size_t>(j) * 3 + static_cast<std::size_t>(c)) * ws + k] = w(c, j);
  return out;
}

TEST(MuConstant, RatioBoundEnclosesSvdOfEveryMatrixOfTheBox) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const int id : {2, 4}) {  // triangle 3 (3 x 2 W), tetrahedron 4 (3 x 3 W)
    const MuSpace& space = mu_space(*find_element_type(id));
    const int dim = space.dim();
    for (int trial = 0; trial < 2000; ++trial) {
      Eigen::MatrixXd w(3, dim);
      for (int c = 0; c < 3; ++c)
        for (int j = 0; j < dim; ++j) w(c, j) = u(rng);
      if (trial % 3 == 0) w.col(0) = w.col(dim - 1) * (1 + 1e-3 * u(rng)) + 1e-3 * Eigen::Vector3d::Random();  // near-degenerate
      if (trial % 5 == 0) w = w.householderQr().householderQ() * Eigen::MatrixXd::Identity(3, dim) * 2.0;  // ideal: R = 1
      const double delta = trial % 2 == 0 ? 0.0 : 1e-6;
      const auto ctrl = constant_controls(space, w);
      const double lo = constant_ratio_lower(space, ctrl.data(), delta);
      const RatioBounds both = constant_ratio_bounds(space, ctrl.data(), delta);
      const double exact = svd_ratio(w);
      // The eigenvector-free bounds: around the exact ratio, and as tight as the above.
      ASSERT_LE(both.lower, exact * exact * (1 + 1e-14)) << "trial " << trial;
      ASSERT_GE(both.upper, exact * exact * (1 - 1e-14)) << "trial " << trial;
      if (exact > 1e-3) {
        EXPECT_LE(both.upper - both.lower, 1e-7 * exact * exact + 1e-11 + 200 * delta) << "trial " << trial;
      }
      ASSERT_LE(std::sqrt(lo), exact * (1 + 1e-14)) << "trial " << trial;
      // Tight: the closed form loses only rounding (relative, amplified near degeneracy)
      // and delta.
      if (exact > 1e-3) {
        EXPECT_GE(std::sqrt(lo), exact * (1 - 1e-8) - 50 * delta / exact) << "trial " << trial;
      }
      // Matrices of the box (its corners and random points) are never below the bound.
      for (int s = 0; s < 8 && delta > 0; ++s) {
        Eigen::MatrixXd p = w;
        for (int c = 0; c < 3; ++c)
          for (int j = 0; j < dim; ++j) p(c, j) += delta * (s < 4 ? (u(rng) > 0 ? 1.0 : -1.0) : u(rng));
        const double r = svd_ratio(p) * svd_ratio(p);
        ASSERT_LE(lo, r * (1 + 1e-14)) << "trial " << trial;
        ASSERT_LE(both.lower, r * (1 + 1e-14)) << "trial " << trial;
        ASSERT_GE(both.upper, r * (1 - 1e-14)) << "trial " << trial;
      }
    }
  }
}

TEST(MuConstant, AffineElementsMatchSvdAndTheGeneralPath) {
  // Straight simplices, parallelograms, parallelepipeds, prisms of every order: W is
  // constant, mu = sigma_min(A) / sigma_max(A) of the affine map (A's first two columns in
  // 2D). The fast path must enclose it within the tolerance and agree with the general
  // path (constant path off).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  int fast = 0;
  for (const int id : {2, 9, 3, 10, 4, 11, 6, 5, 12}) {
    const ElementType& type = *find_element_type(id);
    const int count = type.order == 1 ? 1000 : 150;
    for (int e = 0; e < count; ++e) {
      Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a(i, j) += 0.6 * u(rng);
      if (type.dim == 2) a(0, 2) = a(1, 2) = a(2, 0) = a(2, 1) = 0, a(2, 2) = 1;
      if (a.determinant() < 0.05) continue;  // valid, orientation kept
      const Eigen::Vector3d b(u(rng), u(rng), type.dim == 2 ? 0.0 : u(rng));
      const auto x = test::affine_ideal_element(type, a, b);
      const double exact = svd_ratio(type.dim == 2 ? Eigen::MatrixXd(a.leftCols(2)) : Eigen::MatrixXd(a));
      mu_use_constant_path(true);
      const QualityBounds q = mu_bounds(type, x, opt, true);
      mu_use_constant_path(false);
      const QualityBounds g = mu_bounds(type, x, opt, true);
      mu_use_constant_path(true);
      ASSERT_TRUE(q.tolerance_met && g.tolerance_met) << type.name << " element " << e;
      EXPECT_LE(q.lower, exact * (1 + 1e-14)) << type.name << " element " << e;
      EXPECT_GE(q.upper, exact * (1 - 1e-14)) << type.name << " element " << e;
      EXPECT_LE(q.lower, g.upper) << type.name << " element " << e;
      EXPECT_LE(g.lower, q.upper) << type.name << " element " << e;
      fast += q.subdivisions == 0 && q.upper - q.lower < 1e-9;
    }
  }
  // The closed form settled (nearly) all of them, to far better than the tolerance.
  EXPECT_GT(fast, 4000);
}

TEST(MuConstant, StraightSidedSimplicesWithTinyDeviations) {
  // Straight simplices of orders 2-4 whose high-order nodes are 1e-10 off their straight
  // positions: the straight-sided closed form (mu_bounds.cpp, straight_sided.hpp margins)
  // holds every sampled pointwise mu above its lower bound and overlaps the general path.
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  for (const int id : {9, 21, 23, 11, 29}) {  // triangles of orders 2-4, tetrahedra 2-3
    const ElementType& type = *find_element_type(id);
    const LagrangeBasis& basis = lagrange_basis(type);
    const auto points = test::dense_points(type.family, 6, 50, rng);
    for (int e = 0; e < 20; ++e) {
      Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a(i, j) += 0.6 * u(rng);
      if (type.dim == 2) a(0, 2) = a(1, 2) = a(2, 0) = a(2, 1) = 0, a(2, 2) = 1;
      if (a.determinant() < 0.05) continue;
      auto x = test::affine_ideal_element(type, a, Eigen::Vector3d(u(rng), u(rng), type.dim == 2 ? 0.0 : u(rng)));
      for (std::size_t i = 3 * static_cast<std::size_t>(type.dim + 1); i < x.size(); ++i)
        if (!(type.dim == 2 && i % 3 == 2)) x[i] += 1e-10 * u(rng);
      const QualityBounds q = mu_bounds(type, x, opt, true);
      mu_use_constant_path(false);
      const QualityBounds g = mu_bounds(type, x, opt, true);
      mu_use_constant_path(true);
      const test::SampledMu sampled = test::sample_mu(basis, x, points);
      EXPECT_TRUE(q.tolerance_met) << type.name << " element " << e;
      EXPECT_LE(q.lower, sampled.lo * (1 + 1e-12)) << type.name << " element " << e;
      EXPECT_LE(q.lower, g.upper) << type.name << " element " << e;
      EXPECT_LE(g.lower, q.upper) << type.name << " element " << e;
    }
  }
}

// Valid planar quadrangles with a bilinear geometry get closed-form bounds
// (bilinear_quad_quality.hpp: the minimum of mu is at a corner): the least corner value
// (Eigen's SVD), which dense sampling never finds below (the theorem, checked here
// independently), lies within them; with the high-order nodes 1e-10 off the bilinear map
// the bounds still hold the sampled minimum and overlap the general path's.
TEST(MuConstant, BilinearQuadrangleMinimumIsAtACorner) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  int checked = 0;
  for (int order = 1; order <= 4; ++order) {
    const ElementType& type = *find_element_type(ElementFamily::quadrangle, order, true);
    const LagrangeBasis& basis = lagrange_basis(type);
    const auto points = test::dense_points(type.family, 24, 200, rng);
    for (int e = 0; e < 40; ++e) {
      const double z = 5 * u(rng), scale = std::pow(10.0, 3 * u(rng));
      std::vector<test::Vec> q = {{0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}};
      for (test::Vec& v : q)
        for (std::size_t j = 0; j < 2; ++j) v[j] = scale * (v[j] + 0.4 * u(rng));
      std::vector<double> x = test::straight_element(type, q);
      for (std::size_t i = 2; i < x.size(); i += 3) x[i] = z;  // exactly, as a 2D mesher writes it
      const bool off = order > 1 && e % 2 == 1;
      if (off)
        for (std::size_t i = 12; i < x.size(); ++i)
          if (i % 3 != 2) x[i] += 1e-10 * scale * u(rng);
      double corner_min = 1;
      for (std::size_t k = 0; k < 4; ++k) corner_min = std::min(corner_min, test::pointwise_mu(basis, x, reference_nodes(type)[k]));
      const test::SampledMu sampled = test::sample_mu(basis, x, points);
      if (sampled.j_nonpositive || !(corner_min > 0.05)) continue;  // the general path's case
      if (!off) {
        EXPECT_GE(sampled.lo, corner_min * (1 - 1e-12)) << type.name << " element " << e;  // the theorem
      }
      const QualityBounds b = mu_bounds(type, x, opt, true);
      EXPECT_LE(b.lower, sampled.lo * (1 + 1e-12)) << type.name << " element " << e;
      EXPECT_LE(b.lower, corner_min * (1 + 1e-12)) << type.name << " element " << e;
      EXPECT_GE(b.upper, corner_min - (off ? 1e-6 : 1e-12)) << type.name << " element " << e;
      EXPECT_LE(b.upper - b.lower, off ? 1e-6 : 1e-9) << type.name << " element " << e;
      EXPECT_EQ(b.subdivisions, 0) << type.name << " element " << e;
      EXPECT_TRUE(b.tolerance_met) << type.name << " element " << e;
      mu_use_constant_path(false);
      const QualityBounds g = mu_bounds(type, x, opt, true);
      mu_use_constant_path(true);
      EXPECT_LE(b.lower, g.upper) << type.name << " element " << e;
      EXPECT_LE(g.lower, b.upper) << type.name << " element " << e;
      ++checked;
    }
  }
  EXPECT_GE(checked, 100);
}

TEST(MuConstant, CurvedElementsAreNotTakenForConstant) {
  // Elements with one edge node moved: W varies, the general path answers (the same
  // bounds with the constant path on and off; the closed form's would be far narrower).
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  for (const int id : {11, 10, 12}) {
    const ElementType& type = *find_element_type(id);
    auto x = test::affine_ideal_element(type, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    x[3 * static_cast<std::size_t>(family_num_vertices(type.family)) + 1] += 0.05;
    mu_use_constant_path(false);
    const QualityBounds g = mu_bounds(type, x, opt, true);
    mu_use_constant_path(true);
    const QualityBounds q = mu_bounds(type, x, opt, true);
    EXPECT_EQ(q.lower, g.lower) << type.name;
    EXPECT_EQ(q.upper, g.upper) << type.name;
    EXPECT_LT(q.upper, 1.0) << type.name;
  }
}

}  // namespace
}  // namespace quadval
