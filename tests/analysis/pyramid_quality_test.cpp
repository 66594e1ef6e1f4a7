// mu and the scaled Jacobian on pyramids (orders 1 and 2). mu: closed forms (the ideal
// pyramid and its similarities give 1, an affine image x = A y of the ideal gives
// sigma_min(A) / sigma_max(A), inverted pyramids give 0), the same value under a
// renumbering that keeps the orientation, and dense sampling of sigma_min / sigma_max of
// W = J_p J_i^-1 on random curved pyramids. Scaled Jacobian: 1 on the ideal pyramid, the
// corner-tetrahedron formula from the vertices on affine images, -1 on the mirrored ideal,
// and dense sampling of the pointwise corner-frame definition (scaled_jacobian.hpp). The
// oracles use Gmsh's rational pyramid shape functions (lagrange_basis.hpp) and Eigen,
// never the cube-coordinate polynomials under test; their points avoid the apex, where
// J_p is undefined.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/mu_constant.hpp"
#include "cli_run.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

// The ideal pyramid (mu_bounds.hpp) in Gmsh vertex order: unit square base, apex above its
// centre at height 1/sqrt 2, so that all eight edges have length 1.
std::vector<Eigen::Vector3d> ideal_pyramid() {
  return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1 / std::sqrt(2.0)}};
}

// J_i: Gmsh's reference pyramid (base [-1,1]^2 at zeta = 0, apex (0,0,1)) onto the ideal
// one is affine: columns (v1 - v0) / 2, (v3 - v0) / 2, apex - base centre.
Eigen::Matrix3d ideal_jacobian() {
  const auto v = ideal_pyramid();
  Eigen::Matrix3d j;
  j.col(0) = (v[1] - v[0]) / 2;
  j.col(1) = (v[3] - v[0]) / 2;
  j.col(2) = v[4] - (v[0] + v[1] + v[2] + v[3]) / 4;
  return j;
}

// Nodes of `type`: x = A y + b, y the ideal pyramid's point of each reference node.
std::vector<double> affine_ideal(const ElementType& type, const Eigen::Matrix3d& a, const Eigen::Vector3d& b) {
  const Eigen::Matrix3d ji = ideal_jacobian();
  const Eigen::Vector3d base_centre(0.5, 0.5, 0);
  std::vector<double> x;
  for (const auto& p : reference_nodes(type)) {
    const Eigen::Vector3d y = base_centre + ji * Eigen::Vector3d(p[0], p[1], p[2]);
    const Eigen::Vector3d z = a * y + b;
    x.insert(x.end(), {z(0), z(1), z(2)});
  }
  return x;
}

Eigen::Matrix3d jacobian_matrix(const LagrangeBasis& basis, const std::vector<double>& x, const RefPoint& p) {
  std::vector<double> g(static_cast<std::size_t>(3 * basis.num_nodes()));
  basis.evaluate_gradients(p, g);
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (int i = 0; i < basis.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) j(a, c) += g[static_cast<std::size_t>(3 * i + c)] * x[static_cast<std::size_t>(3 * i + a)];
  return j;
}

double ratio_of_singular_values(const Eigen::Matrix3d& w) {
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(w).singularValues();
  return s(2) / s(0);
}

// Points of the pyramid without its apex: cube coordinates (u, v, t), t >= t_min > 0,
// xi = (2u - 1) t, eta = (2v - 1) t, zeta = 1 - t; t down to 1e-4 approaches the apex
// along rays (the limits that the cube face t = 0 of the bounds holds).
std::vector<RefPoint> pyramid_points(int m, int random_count, std::mt19937& rng) {
  std::vector<RefPoint> pts;
  const auto add = [&](double u, double v, double t) { pts.push_back({(2 * u - 1) * t, (2 * v - 1) * t, 1 - t}); };
  const double ts[] = {1e-4, 1e-2};
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= m; ++j) {
      for (double t : ts) add(double(i) / m, double(j) / m, t);
      for (int k = 1; k <= m; ++k) add(double(i) / m, double(j) / m, double(k) / m);
    }
  std::uniform_real_distribution<double> u(0, 1);
  for (int r = 0; r < random_count; ++r) add(u(rng), u(rng), std::max(1e-4, u(rng)));
  return pts;
}

std::vector<const ElementType*> pyramid_types() {
  return {find_element_type(7), find_element_type(14), find_element_type(19)};  // P1, P2, P2 incomplete
}

Eigen::Matrix3d rotation(double a, double b) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(b, Eigen::Vector3d(1, 2, 3).normalized()))
      .toRotationMatrix();
}

TEST(MuPyramid, SupportedForEveryOrderOfTheJacobianBounds) {
  for (const ElementType& t : element_types()) {
    if (t.family == ElementFamily::pyramid && t.has_lagrange_basis && t.order >= 1) {
      EXPECT_EQ(mu_supported(t), jacobian_bounds_supported(t)) << t.name;
    }
  }
  EXPECT_TRUE(mu_supported(*find_element_type(118)));  // order 3
}

TEST(MuPyramid, IdealPyramidAndItsSimilaritiesHaveMuOne) {
  QualityOptions opt;
  opt.abs_tol = 1e-9;
  for (const ElementType* t : pyramid_types())
    for (bool constant_path : {true, false}) {
      SCOPED_TRACE(std::string(t->name) + (constant_path ? " closed form" : " subdivision"));
      mu_use_constant_path(constant_path);
      for (const auto& [a, s] : {std::pair{rotation(0, 0), 1.0}, std::pair{rotation(0.7, -1.9), 3.5e-3}}) {
        const auto x = affine_ideal(*t, s * a, Eigen::Vector3d(4, -2, 7));
        const QualityBounds b = mu_bounds(*t, x, opt);
        EXPECT_TRUE(b.tolerance_met);
        EXPECT_LE(b.lower, 1.0);
        EXPECT_GE(b.upper, 1.0 - 1e-10);  // the nodes are rounded to doubles
        EXPECT_GE(b.lower, 1.0 - opt.abs_tol);
      }
    }
  mu_use_constant_path(true);
}

TEST(MuPyramid, AffineImageOfTheIdealGivesTheRatioOfItsStretches) {
  QualityOptions opt;
  opt.abs_tol = 1e-7;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const ElementType* t : pyramid_types())
    for (int k = 0; k < 6; ++k) {
      // Stretches (s1, s2, s3) along rotated axes: mu = min s / max s.
      const Eigen::Vector3d s(1.0, 0.5 + 0.4 * (k % 3), 0.3 + 0.25 * k);
      Eigen::Matrix3d a = rotation(u(rng), u(rng)) * s.asDiagonal() * rotation(u(rng), u(rng)).transpose();
      if (k == 5) {  // a general (sheared) map: its singular values
        a << 1, 0.4, -0.3, 0.1, 0.8, 0.5, 0.2, -0.1, 1.3;
      }
      const double want = ratio_of_singular_values(a);
      if (k < 5) {
        EXPECT_NEAR(want, s.minCoeff() / s.maxCoeff(), 1e-14);
      }
      for (bool constant_path : {true, false}) {
        mu_use_constant_path(constant_path);
        SCOPED_TRACE(std::string(t->name) + " k " + std::to_string(k) + (constant_path ? " closed" : " subdivision"));
        const QualityBounds b = mu_bounds(*t, affine_ideal(*t, a, Eigen::Vector3d(1, 2, 3)), opt);
        EXPECT_TRUE(b.tolerance_met);
        EXPECT_LE(b.lower, want * (1 + 1e-14));
        EXPECT_GE(b.upper, want * (1 - 1e-14));
        EXPECT_LE(b.upper - b.lower, opt.abs_tol);
      }
    }
  mu_use_constant_path(true);
}

TEST(MuPyramid, InvertedPyramidsHaveMuZero) {
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  for (const ElementType* t : pyramid_types()) {
    SCOPED_TRACE(t->name);
    // Mirror image: J < 0 everywhere.
    const auto mirrored = affine_ideal(*t, Eigen::Vector3d(1, 1, -1).asDiagonal(), Eigen::Vector3d::Zero());
    // A non-convex base (vertex 2 pushed inside the triangle 0 1 3): the corner
    // tetrahedron at vertex 2 is inverted, the one at vertex 0 is not, so J changes sign.
    // Order 2: the nodes are the order-1 map's images of the reference nodes (Bergot's
    // order-1 space lies in the order-2 one, so this is the same map).
    std::vector<double> corners = affine_ideal(*find_element_type(7), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    corners[6] = corners[7] = 0.3;
    std::vector<double> sheared;
    {
      const LagrangeBasis& p1 = lagrange_basis(*find_element_type(7));
      std::vector<double> n(5);
      for (const auto& r : reference_nodes(*t)) {
        p1.evaluate(r, n);
        for (int c = 0; c < 3; ++c) {
          double v = 0;
          for (int i = 0; i < 5; ++i) v += n[static_cast<std::size_t>(i)] * corners[static_cast<std::size_t>(3 * i + c)];
          sheared.push_back(v);
        }
      }
    }
    const LagrangeBasis& basis = lagrange_basis(*t);
    EXPECT_LT(test::jacobian_at(basis, sheared, {0.999, 0.999, 1e-3}, false), 0);
    EXPECT_GT(test::jacobian_at(basis, sheared, {-0.999, -0.999, 1e-3}, false), 0);
    for (const auto& x : {mirrored, sheared}) {
      const QualityBounds b = mu_bounds(*t, x, opt);
      EXPECT_EQ(b.lower, 0.0);
      EXPECT_EQ(b.upper, 0.0);
      EXPECT_TRUE(b.tolerance_met);
    }
  }
}

// The nodes of the same element numbered after the rotation (xi, eta, zeta) ->
// (-eta, xi, zeta) of the reference pyramid (det +1: orientation kept): new node i is the
// old node at the image of reference node i.
std::vector<double> rotated_numbering(const ElementType& t, const std::vector<double>& x) {
  const auto ref = reference_nodes(t);
  std::vector<double> out;
  for (const auto& p : ref) {
    const RefPoint q{-p[1], p[0], p[2]};
    std::size_t j = 0;
    while (j < ref.size() && std::abs(ref[j][0] - q[0]) + std::abs(ref[j][1] - q[1]) + std::abs(ref[j][2] - q[2]) > 1e-9) ++j;
    EXPECT_LT(j, ref.size());
    if (j == ref.size()) return x;
    out.insert(out.end(), x.begin() + static_cast<std::ptrdiff_t>(3 * j), x.begin() + static_cast<std::ptrdiff_t>(3 * j + 3));
  }
  return out;
}

TEST(PyramidQuality, RotatingTheNumberingKeepsTheValues) {
  QualityOptions opt;
  opt.abs_tol = 1e-5;
  opt.max_subdivisions = 2000;
  std::mt19937 rng(11);
  for (const ElementType* t : pyramid_types()) {
    SCOPED_TRACE(t->name);
    for (int e = 0; e < 6; ++e) {
      const auto x = test::random_element(*t, 0.1 / t->order, rng);
      const auto y = rotated_numbering(*t, x);
      ASSERT_NE(x, y);
      const QualityBounds a = mu_bounds(*t, x, opt), b = mu_bounds(*t, y, opt);
      ASSERT_TRUE(a.tolerance_met && b.tolerance_met);
      EXPECT_GT(a.lower, 0.0);
      EXPECT_LE(a.lower, b.upper);
      EXPECT_LE(b.lower, a.upper);
      const QualityBounds c = scaled_jacobian_bounds(*t, x, opt), d = scaled_jacobian_bounds(*t, y, opt);
      ASSERT_TRUE(c.tolerance_met && d.tolerance_met);
      EXPECT_LE(c.lower, d.upper);
      EXPECT_LE(d.lower, c.upper);
    }
  }
}

TEST(MuPyramid, SampledMinimumNeverBelowLowerBound) {
  std::mt19937 rng(2026);
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  opt.max_subdivisions = 200;
  const Eigen::Matrix3d ji_inv = ideal_jacobian().inverse();
  for (const ElementType* t : pyramid_types()) {
    SCOPED_TRACE(t->name);
    const LagrangeBasis& basis = lagrange_basis(*t);
    const auto pts = pyramid_points(8, 200, rng);
    const int count = t->order == 1 ? 150 : 40;
    int valid = 0, met = 0, close = 0;
    for (int e = 0; e < count; ++e) {
      const double amplitude = (e % 3 == 0 ? 0.05 : (e % 3 == 1 ? 0.2 : 0.4)) / t->order;
      const auto x = test::random_element(*t, amplitude, rng);
      const QualityBounds b = mu_bounds(*t, x, opt);
      ASSERT_LE(b.lower, b.upper);
      ASSERT_GE(b.lower, 0.0);
      ASSERT_LE(b.upper, 1.0);
      if (b.tolerance_met) {
        ++met;
        EXPECT_LE(b.upper - b.lower, opt.abs_tol);
      }
      double lo = 1;
      bool negative = false;
      for (const auto& p : pts) {
        const Eigen::Matrix3d jp = jacobian_matrix(basis, x, p);
        if (jp.determinant() <= 0) negative = true;
        lo = std::min(lo, ratio_of_singular_values(jp * ji_inv));
      }
      if (negative) {
        EXPECT_EQ(b.lower, 0.0) << "element " << e << ": J <= 0 at a sample";
        continue;
      }
      if (b.upper == 0) continue;  // invalid where no sample looked
      ++valid;
      EXPECT_GE(lo, b.lower * (1 - 1e-12)) << "element " << e;
      // The samples (8 steps per direction, 1e-4 from the apex) find the minimum
      // within a few percent of its value.
      if (b.tolerance_met && lo - b.lower <= opt.abs_tol + 0.03 * lo) ++close;
    }
    EXPECT_GE(valid, count / 2);
    EXPECT_GE(met, count * 9 / 10);
    EXPECT_GE(close, valid * 9 / 10);
    std::printf("[mu pyramid %s] %d elements, %d valid, %d met, %d sampled within the gap\n", std::string(t->name).c_str(), count, valid,
                met, close);
  }
}

// Pointwise scaled Jacobian of a pyramid (scaled_jacobian.hpp): frames at the four base
// corners of Gmsh's reference pyramid (half base edges to the next and previous corner,
// the edge to the apex), s = sqrt 2.
double pointwise_sj(const Eigen::Matrix3d& jp) {
  const double base[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  double best = 1e300;
  for (int k = 0; k < 4; ++k) {
    const double* v = base[k];
    const double* nx = base[(k + 1) % 4];
    const double* pv = base[(k + 3) % 4];
    Eigen::Matrix3d e;
    e.col(0) = Eigen::Vector3d((nx[0] - v[0]) / 2, (nx[1] - v[1]) / 2, 0);
    e.col(1) = Eigen::Vector3d((pv[0] - v[0]) / 2, (pv[1] - v[1]) / 2, 0);
    e.col(2) = Eigen::Vector3d(-v[0], -v[1], 1);
    EXPECT_NEAR(e.determinant(), 1.0, 1e-15);
    const Eigen::Matrix3d f = jp * e;
    const double val = std::sqrt(2.0) * f.determinant() / (f.col(0).norm() * f.col(1).norm() * f.col(2).norm());
    best = std::min(best, val);
  }
  return best;
}

// The corner-tetrahedron value of a straight pyramid from its five vertices:
// sqrt 2 min_k det[x_k+1 - x_k, x_k-1 - x_k, apex - x_k] / (product of the three lengths).
double corner_sj(const std::vector<double>& x) {
  const auto vertex = [&](int i) { return Eigen::Vector3d(x[static_cast<std::size_t>(3 * i)], x[static_cast<std::size_t>(3 * i + 1)], x[static_cast<std::size_t>(3 * i + 2)]); };
  double best = 1e300;
  for (int k = 0; k < 4; ++k) {
    Eigen::Matrix3d f;
    f.col(0) = vertex((k + 1) % 4) - vertex(k);
    f.col(1) = vertex((k + 3) % 4) - vertex(k);
    f.col(2) = vertex(4) - vertex(k);
    best = std::min(best, std::sqrt(2.0) * f.determinant() / (f.col(0).norm() * f.col(1).norm() * f.col(2).norm()));
  }
  return best;
}

TEST(ScaledJacobianPyramid, SupportedToOrderFour) {
  for (const ElementType* t : pyramid_types()) EXPECT_TRUE(scaled_jacobian_supported(*t)) << t->name;
  EXPECT_TRUE(scaled_jacobian_supported(*find_element_type(118)));   // order 3
  EXPECT_TRUE(scaled_jacobian_supported(*find_element_type(119)));   // order 4
  EXPECT_FALSE(scaled_jacobian_supported(*find_element_type(120)));  // order 5
}

TEST(ScaledJacobianPyramid, ClosedFormsOnStraightPyramids) {
  QualityOptions opt;
  opt.abs_tol = 1e-9;
  for (const ElementType* t : pyramid_types()) {
    SCOPED_TRACE(t->name);
    // The ideal pyramid and a similarity of it: 1.
    for (const auto& [a, s] : {std::pair{rotation(0, 0), 1.0}, std::pair{rotation(0.7, -1.9), 3.5e-3}}) {
      const QualityBounds b = scaled_jacobian_bounds(*t, affine_ideal(*t, s * a, Eigen::Vector3d(4, -2, 7)), opt);
      EXPECT_TRUE(b.tolerance_met);
      EXPECT_GE(b.upper, 1.0 - 1e-10);
      EXPECT_GE(b.lower, 1.0 - opt.abs_tol - 1e-10);
    }
    // Apex height scaled by h: every corner gives h sqrt 2 / sqrt(1 + h^2) (edges 1, 1,
    // sqrt((1 + h^2) / 2), volume term h / sqrt 2).
    for (double h : {0.3, 0.8, 2.5}) {
      const auto x = affine_ideal(*t, Eigen::Vector3d(1, 1, h).asDiagonal(), Eigen::Vector3d::Zero());
      const double want = h * std::sqrt(2.0) / std::sqrt(1 + h * h);
      EXPECT_NEAR(corner_sj(x), want, 1e-14);
      const QualityBounds b = scaled_jacobian_bounds(*t, x, opt);
      EXPECT_TRUE(b.tolerance_met) << h;
      EXPECT_LE(b.lower, want + 1e-14);
      EXPECT_GE(b.upper, want - 1e-14);
    }
    // A general affine image: the corner formula from its vertices.
    Eigen::Matrix3d a;
    a << 1, 0.4, -0.3, 0.1, 0.8, 0.5, 0.2, -0.1, 1.3;
    const auto x = affine_ideal(*t, a, Eigen::Vector3d(1, 2, 3));
    const double want = corner_sj(x);
    const QualityBounds b = scaled_jacobian_bounds(*t, x, opt);
    EXPECT_TRUE(b.tolerance_met);
    EXPECT_LE(b.lower, want + 1e-14);
    EXPECT_GE(b.upper, want - 1e-14);
    // The mirrored ideal: J < 0 everywhere, sj = -1.
    const QualityBounds m = scaled_jacobian_bounds(*t, affine_ideal(*t, Eigen::Vector3d(1, 1, -1).asDiagonal(), Eigen::Vector3d::Zero()), opt);
    EXPECT_LE(m.lower, -1.0 + 1e-14);
    EXPECT_GE(m.upper, -1.0 - 1e-14);
    EXPECT_TRUE(m.tolerance_met);
  }
}

TEST(ScaledJacobianPyramid, SampledMinimumNeverBelowLowerBound) {
  std::mt19937 rng(77);
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  opt.max_subdivisions = 200;
  for (const ElementType* t : pyramid_types()) {
    SCOPED_TRACE(t->name);
    const LagrangeBasis& basis = lagrange_basis(*t);
    const auto pts = pyramid_points(8, 200, rng);
    const int count = t->order == 1 ? 150 : 40;
    int met = 0, close = 0, negative = 0;
    for (int e = 0; e < count; ++e) {
      const double amplitude = (e % 3 == 0 ? 0.05 : (e % 3 == 1 ? 0.2 : 0.4)) / t->order;
      const auto x = test::random_element(*t, amplitude, rng);
      const QualityBounds b = scaled_jacobian_bounds(*t, x, opt);
      ASSERT_LE(b.lower, b.upper);
      ASSERT_GE(b.lower, -std::sqrt(2.0) * (1 + 1e-15));
      double lo = 1e300;
      for (const auto& p : pts) lo = std::min(lo, pointwise_sj(jacobian_matrix(basis, x, p)));
      if (lo < 0) ++negative;
      EXPECT_GE(lo, b.lower - 1e-12) << "element " << e;
      if (b.tolerance_met) {
        ++met;
        EXPECT_LE(b.upper - b.lower, opt.abs_tol * (1 + 1e-12));
        if (lo - b.lower <= opt.abs_tol + 0.03 * std::abs(lo)) ++close;
      }
    }
    EXPECT_GE(met, count * 9 / 10);
    EXPECT_GE(close, met * 9 / 10);
    std::printf("[sj pyramid %s] %d elements, %d met, %d sampled within the gap, %d with sj < 0 at a sample\n",
                std::string(t->name).c_str(), count, met, close, negative);
  }
}

// `quadval check --measure all` computes both measures on pyramids (no "skipped"), and the
// per-element CSV holds numbers for them within [0, 1] (mu) and [-sqrt 2, sqrt 2] (sj).
TEST(PyramidQualityCli, CheckMeasureAllNoLongerSkipsPyramids) {
  namespace fs = std::filesystem;
  const std::string mesh = std::string(QUADVAL_SHARED_DIR) + "/data/curved/warped_pyramid_o1_N6_a0.1.msh";
  const fs::path csv = fs::temp_directory_path() / ("quadval_pyramid_quality_" + std::to_string(::getpid()) + ".csv");
  const testing_cli::CliRun v = testing_cli::run_cli("check " + mesh + " -q");
  const testing_cli::CliRun r = testing_cli::run_cli("check " + mesh + " --measure all -o " + csv.string());
  EXPECT_EQ(r.code, v.code) << r.output;
  EXPECT_EQ(r.output.find("skipped for"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("computed 0,"), std::string::npos) << r.output;
  std::istringstream in(testing_cli::slurp(csv));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) head.push_back(c);
  }
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(head.begin(), head.end(), name) - head.begin());
  };
  const std::size_t mu_lo = column("mu_lower"), mu_hi = column("mu_upper"), sj_lo = column("sj_lower"), sj_hi = column("sj_upper");
  ASSERT_LT(std::max({mu_lo, mu_hi, sj_lo, sj_hi}), head.size());
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), head.size()) << line;
    const double a = std::stod(cells[mu_lo]), b = std::stod(cells[mu_hi]);
    const double c = std::stod(cells[sj_lo]), d = std::stod(cells[sj_hi]);
    EXPECT_TRUE(0 <= a && a <= b && b <= 1) << line;
    EXPECT_TRUE(-std::sqrt(2.0) <= c && c <= d && d <= std::sqrt(2.0) * (1 + 1e-15)) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 1296);
  fs::remove(csv);
}

}  // namespace
}  // namespace quadval
