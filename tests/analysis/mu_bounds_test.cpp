// Closed-form and reference cases of the certified quality measure mu (thesis, Paper V):
// the twisted hexahedron of §7.1, ideal and affinely stretched ideal elements, straight
// simplices (SVD of their constant W), invalid elements, and node renumberings.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <random>
#include <string>
#include <vector>

#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "lanes_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/error.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

using test::affine_ideal_element;
using test::pointwise_mu;

// The types handled before issue 5 (2D to order 6, 3D to mu_certificate_max_order); the
// higher orders are tested in mu_high_order_test.cpp (smooth warps instead of node noise,
// which makes elements of orders 8-9 invalid at any visible amplitude).
std::vector<const ElementType*> mu_types() {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types())
    if (t.family != ElementFamily::line && t.has_lagrange_basis && mu_supported(t) &&
        t.order <= (t.dim == 2 ? 6 : mu_certificate_max_order(t.family)))
      out.push_back(&t);
  return out;
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

TEST(MuBounds, TwistedHexahedronOfPaperV) {
  const ElementType& hex = *find_element_type(5);
  const std::vector<double> x{-0.5, -1, -1, 1, -1, -1, 1, 1, -1, -0.5, 1, -1,
                              1,    -1, 1,  1, 1, 1,  -1, 1, 1, -1,  -1, 1};
  // Corner values of the pointwise measure, by SVD (Paper V: minimum 0.3233).
  const LagrangeBasis& basis = lagrange_basis(hex);
  double corner_min = 1;
  for (const auto& v : reference_vertices(ElementFamily::hexahedron))
    corner_min = std::min(corner_min, pointwise_mu(basis, x, v));
  EXPECT_NEAR(corner_min, 0.3233, 5e-5);

  QualityOptions opt;
  opt.abs_tol = 2e-7;
  opt.max_subdivisions = 20000;
  const QualityBounds b = mu_bounds(hex, x, opt);
  std::printf("[twisted hex] mu in [%.10f, %.10f], %d subdivisions\n", b.lower, b.upper, b.subdivisions);
  EXPECT_TRUE(b.tolerance_met) << b.lower << " " << b.upper << " after " << b.subdivisions;
  EXPECT_LE(b.upper - b.lower, 2e-7);
  EXPECT_LE(b.lower, 0.2700453384);
  EXPECT_GE(b.upper, 0.2700452884);
}

TEST(MuBounds, IdealElementsAndTheirSimilaritiesHaveMuOne) {
  std::mt19937 rng(5);
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  for (const ElementType* t : mu_types()) {
    SCOPED_TRACE(std::string(t->name));
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      if (trial > 0) {
        const double scale = trial == 1 ? 1e-3 : 250.0;
        a = scale * (t->dim == 3 ? random_rotation(rng) : Eigen::Matrix3d(Eigen::AngleAxisd(0.7 * trial, Eigen::Vector3d::UnitZ())));
        b = Eigen::Vector3d(3.5, -2, t->dim == 3 ? 7 : 0);
      }
      const auto x = affine_ideal_element(*t, a, b);
      const QualityBounds r = mu_bounds(*t, x, opt, t->dim == 2);
      EXPECT_TRUE(r.tolerance_met);
      EXPECT_GE(r.lower, 1 - 1e-6);
      EXPECT_LE(r.lower, 1.0);
      // Rounding the nodes (size 1e-3 at offset 3.5) distorts the element by ~1e-12.
      EXPECT_GE(r.upper, 1 - 1e-9) << std::setprecision(17) << r.lower << " " << r.upper << " " << r.subdivisions;
    }
  }
}

TEST(MuBounds, StretchedIdealElementHasRatioOfStretches) {
  QualityOptions opt;
  opt.abs_tol = 1e-6;
  const double s[3] = {0.3, 1.7, 2.5};
  for (const ElementType* t : mu_types()) {
    SCOPED_TRACE(std::string(t->name));
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    a(0, 0) = s[1];
    a(1, 1) = t->dim == 3 ? s[2] : s[0];
    a(2, 2) = t->dim == 3 ? s[0] : 1.0;
    const double want = t->dim == 3 ? s[0] / s[2] : s[0] / s[1];
    const auto x = affine_ideal_element(*t, a, Eigen::Vector3d(1, 2, 0));
    const QualityBounds r = mu_bounds(*t, x, opt, t->dim == 2);
    EXPECT_TRUE(r.tolerance_met);
    EXPECT_LE(r.lower, want);
    EXPECT_GE(r.upper, want);
    EXPECT_LE(r.upper - r.lower, 1e-6);
  }
}

TEST(MuBounds, StraightSimplicesMatchSvdOfTheirConstantW) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-9;
  for (int id : {2, 4}) {
    const ElementType& t = *find_element_type(id);
    const LagrangeBasis& basis = lagrange_basis(t);
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<double> x;
      for (int i = 0; i < t.num_nodes; ++i)
        for (int c = 0; c < 3; ++c) x.push_back((c == 2 && t.dim == 2) ? 0.0 : u(rng));
      const double want = pointwise_mu(basis, x, {0.2, 0.2, 0.2});
      const QualityBounds r = mu_bounds(t, x, opt, true);
      if (r.upper == 0) continue;  // inverted: tested below
      EXPECT_LE(r.lower, want * (1 + 1e-12) + 1e-15) << trial;
      EXPECT_GE(r.upper, want * (1 - 1e-12)) << trial;
      EXPECT_LE(r.upper - r.lower, 1e-9) << id << " " << trial << " want " << want << " " << r.lower << " " << r.upper << " " << r.subdivisions;
    }
  }
}

TEST(MuBounds, InvalidElementsGetZero) {
  QualityOptions opt;
  // Inverted triangle (clockwise in the plane), tetrahedron with two vertices swapped,
  // a quadrangle folded into a bow tie, a hexahedron with one corner pushed through.
  const std::vector<std::pair<int, std::vector<double>>> cases{
      {2, {0, 0, 0, 0, 1, 0, 1, 0, 0}},
      {4, {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1}},
      {3, {0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0}},
      {5, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 0.2, 0.2, -0.5, 0, 1, 1}},
  };
  for (const auto& [id, x] : cases) {
    const ElementType& t = *find_element_type(id);
    SCOPED_TRACE(std::string(t.name));
    const QualityBounds r = mu_bounds(t, x, opt, true);
    EXPECT_EQ(r.lower, 0.0);
    EXPECT_EQ(r.upper, 0.0);
    EXPECT_TRUE(r.tolerance_met);
  }
}

// The same element with its nodes renumbered by an orientation-preserving symmetry T of
// the reference element: new node i is the old node at T(reference node i).
std::vector<double> renumbered(const ElementType& t, const std::vector<double>& x) {
  const auto ref = reference_nodes(t);
  const auto map = [&](const RefPoint& p) -> RefPoint {
    switch (t.family) {
      case ElementFamily::triangle: return {1 - p[0] - p[1], p[0], 0};
      case ElementFamily::tetrahedron: return {1 - p[0] - p[1] - p[2], p[0], p[2]};
      case ElementFamily::prism: return {1 - p[0] - p[1], p[0], p[2]};
      case ElementFamily::quadrangle: return {-p[1], p[0], 0};
      case ElementFamily::hexahedron: return {-p[1], p[0], p[2]};
      default: return p;
    }
  };
  std::vector<double> out;
  for (const auto& p : ref) {
    const RefPoint q = map(p);
    std::size_t j = 0;
    while (j < ref.size() && std::abs(ref[j][0] - q[0]) + std::abs(ref[j][1] - q[1]) + std::abs(ref[j][2] - q[2]) > 1e-9) ++j;
    EXPECT_LT(j, ref.size()) << "no node at the image of a node";
    if (j == ref.size()) return x;
    out.insert(out.end(), x.begin() + static_cast<std::ptrdiff_t>(3 * j), x.begin() + static_cast<std::ptrdiff_t>(3 * j + 3));
  }
  return out;
}

TEST(MuBounds, RenumberingTheNodesKeepsTheBounds) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-4;
  opt.max_subdivisions = 5000;
  for (const ElementType* t : mu_types()) {
    // Gmsh's incomplete simplex-based spaces (monomials on the edges of Pascal's triangle)
    // are not invariant under the vertex rotation: renumbering would change the element.
    if (!t->complete && t->family != ElementFamily::quadrangle && t->family != ElementFamily::hexahedron)
      continue;
    // Pyramids: tests/analysis/pyramid_quality_test.cpp (skipped before any random draw,
    // so the other types keep their elements).
    if (t->family == ElementFamily::pyramid) continue;
    SCOPED_TRACE(std::string(t->name));
    const Eigen::Matrix3d a = Eigen::Matrix3d::Identity() + 0.15 * Eigen::Matrix3d::Random();
    auto x = affine_ideal_element(*t, t->dim == 2 ? Eigen::Matrix3d(Eigen::Matrix3d::Identity()) : a, Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < x.size(); ++i)
      if (!(t->dim == 2 && i % 3 == 2)) x[i] += 0.05 / t->order * u(rng);
    const auto y = renumbered(*t, x);
    const QualityBounds r1 = mu_bounds(*t, x, opt, true);
    const QualityBounds r2 = mu_bounds(*t, y, opt, true);
    ASSERT_TRUE(r1.tolerance_met && r2.tolerance_met);
    EXPECT_GT(r1.lower, 0.0);
    // Both enclose the same number: the intervals meet, and their lower ends are within tol.
    EXPECT_LE(r1.lower, r2.upper);
    EXPECT_LE(r2.lower, r1.upper);
    EXPECT_NEAR(r1.lower, r2.lower, opt.abs_tol);
  }
}

// Four valid planar elements at once (mu_valid_planar4, check_mesh's way): wherever it
// answers, exactly the bits of the element's own mu_bounds_given, whatever the other lanes
// hold (neighbours shuffled between two runs); it answers for most curved triangles and
// quadrangles of orders 2 to 6 (their root, or a closed form for the straight ones).
TEST(MuBounds, FourPlanarElementsInLanesGiveTheirOwnBounds) {
  std::mt19937 rng(4343);
  QualityOptions o;
  o.abs_tol = 1e-2;
  std::size_t elements = 0, answered = 0;
  for (const ElementType& t : element_types()) {
    if (!mu_supported(t) || t.dim != 2 || t.order < 2 || t.order > 6) continue;
    SCOPED_TRACE(std::string(t.name));
    std::vector<std::vector<double>> xs;
    for (int e = 0; xs.size() < 30 && e < 200; ++e) {
      std::vector<double> x = test::smooth_random_element(t, 0.01 + 0.02 * (e % 4), rng);
      if (e % 7 == 0) x = test::random_element(t, 0.0, rng);  // straight: a closed form
      if (mu_bounds(t, x, o, true).lower > 0) xs.push_back(std::move(x));  // valid
    }
    ASSERT_GE(xs.size(), 20u);
    std::vector<QualityBounds> own;
    for (const auto& x : xs) own.push_back(mu_bounds_given(t, x, o, true, Validity::valid));
    const std::vector<int> answers = test::check_four_at_once(
        xs, own, rng, [&](const auto& x, auto& out) { return mu_valid_planar4(t, x, o, {}, out); });
    for (std::size_t i = 0; i < xs.size(); ++i) {
      EXPECT_NE(answers[i], 1) << "element " << i << " answered in one run only";
      ++elements;
      answered += answers[i] == 2;
    }
    // With an element off its plane z = const among them (its last node at z = 1e-3),
    // whatever is answered is still each element's own bounds.
    std::vector<std::vector<double>> tilted(xs.begin(), xs.begin() + 4);
    tilted[1].back() = 1e-3;
    std::vector<QualityBounds> tilted_own;
    for (const auto& x : tilted) tilted_own.push_back(mu_bounds_given(t, x, o, true, Validity::valid));
    test::check_four_at_once(tilted, tilted_own, rng,
                             [&](const auto& x, auto& out) { return mu_valid_planar4(t, x, o, {}, out); });
  }
  EXPECT_GT(elements, 150u);
  EXPECT_GT(answered, elements * 3 / 4);
}

TEST(MuBounds, LinesAreOneWhenValid) {
  const ElementType& line3 = *find_element_type(8);
  const std::vector<double> x{0, 0, 0, 2, 1, 0, 1, 0.6, 0};
  const QualityBounds r = mu_bounds(line3, x, QualityOptions{});
  EXPECT_EQ(r.lower, 1.0);
  EXPECT_EQ(r.upper, 1.0);
  const std::vector<double> folded{0, 0, 0, 2, 0, 0, 3, 0, 0};  // middle node beyond the end
  const QualityBounds f = mu_bounds(line3, folded, QualityOptions{});
  EXPECT_EQ(f.lower, 0.0);
  EXPECT_EQ(f.upper, 0.0);
}

TEST(MuBounds, UnsupportedTypesAreReported) {
  EXPECT_FALSE(mu_supported(*find_element_type(94)));  // hexahedron of order 5
  EXPECT_FALSE(mu_supported(*find_element_type(15)));  // point
  EXPECT_THROW(mu_bounds(*find_element_type(94), std::vector<double>(648, 0.0), QualityOptions{}),
               InternalError);
}

}  // namespace
}  // namespace quadval
