// Certified Jacobian bounds against oracles that share no code with the Bézier pipeline:
// Algorithm 1 of Paper III (exact J_min of quadratic triangles), dense sampling of J from
// the Lagrange shape-function gradients, closed forms (affine elements), and hand-built
// elements with J > 0 on the boundary but J < 0 inside, or J_min = +-1e-12.
#include "quadval/jacobian_bounds.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "jacobian_test_util.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using test::dense_points;
using test::jacobian_at;
using test::random_element;
using test::smooth_random_element;

// min over x in [0,1] of a x^2 + b x + c (eq. 7).
double minq(double a, double b, double c) {
  double m = std::min(c, a + b + c);
  if (a > 0) {
    const double x = -b / (2 * a);
    if (x > 0 && x < 1) m = std::min(m, a * x * x + b * x + c);
  }
  return m;
}

// Algorithm 1 of Paper III, with one correction: the interior stationary point competes
// with the three edge minima (the paper compares it with the corners only, which is
// wrong when the stationary point is a saddle or a maximum).
double exact_jmin_quadratic_triangle(const double j[6]) {
  const double a11 = 4 * (j[0] + j[1] - 2 * j[3]);
  const double a12 = 4 * (j[0] - j[3] + j[4] - j[5]);
  const double a22 = 4 * (j[0] + j[2] - 2 * j[5]);
  const double r1 = -(-3 * j[0] - j[1] + 4 * j[3]);
  const double r2 = -(-3 * j[0] - j[2] + 4 * j[5]);
  double m = minq(2 * (j[0] + j[1] - 2 * j[3]), -3 * j[0] - j[1] + 4 * j[3], j[0]);
  m = std::min(m, minq(2 * (j[0] + j[2] - 2 * j[5]), -3 * j[0] - j[2] + 4 * j[5], j[0]));
  m = std::min(m, minq(2 * (j[1] + j[2] - 2 * j[4]), -3 * j[1] - j[2] + 4 * j[4], j[1]));
  const double det = a11 * a22 - a12 * a12;
  if (det != 0) {
    const double xs = (r1 * a22 - a12 * r2) / det;
    const double ys = (a11 * r2 - a12 * r1) / det;
    if (xs > 0 && ys > 0 && 1 - xs - ys > 0) {
      // eq. (8)
      const double v = j[0] + (-3 * j[0] - j[1] + 4 * j[3]) * xs + (-3 * j[0] - j[2] + 4 * j[5]) * ys +
                       4 * (j[0] - j[3] + j[4] - j[5]) * xs * ys + 2 * (j[0] + j[1] - 2 * j[3]) * xs * xs +
                       2 * (j[0] + j[2] - 2 * j[5]) * ys * ys;
      m = std::min(m, v);
    }
  }
  return m;
}

// J of a planar quadratic triangle at (xi, eta) from the closed-form P2 shape functions
// (eq. 4), node order 1,2,3 corners, 4 mid 12, 5 mid 23, 6 mid 31 (= Gmsh's).
double p2_jacobian(const std::vector<double>& x, double xi, double eta) {
  const double l = 1 - xi - eta;
  const double dxi[6] = {-(4 * l - 1), 4 * xi - 1, 0, 4 * (l - xi), 4 * eta, -4 * eta};
  const double deta[6] = {-(4 * l - 1), 0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l - eta)};
  double xx = 0, xe = 0, yx = 0, ye = 0;
  for (int i = 0; i < 6; ++i) {
    xx += dxi[i] * x[static_cast<std::size_t>(3 * i)];
    xe += deta[i] * x[static_cast<std::size_t>(3 * i)];
    yx += dxi[i] * x[static_cast<std::size_t>(3 * i + 1)];
    ye += deta[i] * x[static_cast<std::size_t>(3 * i + 1)];
  }
  return xx * ye - xe * yx;
}

TEST(JacobianBoundsAlgorithm1, QuadraticTrianglesContainExactMinimumWithinTolerance) {
  const ElementType& t6 = *find_element_type(9);
  std::mt19937 rng(2012);
  BoundsWorkspace ws;
  BoundsOptions measure;
  measure.goal = BoundsGoal::measure;
  measure.rel_tol = 1e-3;
  int invalid = 0, valid = 0;
  for (int e = 0; e < 3000; ++e) {
    const double amp = (e % 3 == 0) ? 0.05 : (e % 3 == 1 ? 0.2 : 0.4);
    const std::vector<double> x = random_element(t6, amp, rng);
    const double nodes_uv[6][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
    double j[6];
    for (int i = 0; i < 6; ++i) j[i] = p2_jacobian(x, nodes_uv[i][0], nodes_uv[i][1]);
    const double exact = exact_jmin_quadratic_triangle(j);
    double scale = 0;
    for (double v : j) scale = std::max(scale, std::abs(v));
    const double slack = 1e-12 * scale;  // rounding of the oracle itself

    const JacobianBounds b = jacobian_bounds(t6, x, measure, ws, /*planar=*/true);
    ASSERT_LE(b.jmin_lower, exact + slack) << "element " << e;
    ASSERT_GE(b.jmin_upper, exact - slack) << "element " << e;
    ASSERT_TRUE(b.tolerance_met);
    EXPECT_LE(b.jmin_upper - b.jmin_lower, measure.rel_tol * std::max(std::abs(b.jmin_upper), std::abs(b.jmax_lower)) * 1.0001 + 1e-300);

    const JacobianBounds v = jacobian_bounds(t6, x, BoundsOptions{}, ws, true);
    if (exact > slack) {
      ASSERT_EQ(v.validity, Validity::valid) << "element " << e << " exact " << exact;
      ++valid;
    } else if (exact < -slack) {
      ASSERT_EQ(v.validity, Validity::invalid) << "element " << e << " exact " << exact;
      ++invalid;
    }
  }
  // The random set exercises both answers.
  EXPECT_GT(valid, 500);
  EXPECT_GT(invalid, 100);
}

// Dense sampling: the sampled minimum is never below our lower bound (nor the sampled
// maximum above our upper bound), and measured gaps meet the tolerance.
class DenseSamplingTest : public testing::TestWithParam<const ElementType*> {};

TEST_P(DenseSamplingTest, SampledExtremaInsideBounds) {
  const ElementType& type = *GetParam();
  const LagrangeBasis& lb = lagrange_basis(type);
  std::mt19937 rng(static_cast<unsigned>(type.gmsh_id));
  const int big = type.num_nodes > 60 ? 1 : type.num_nodes > 20 ? 2 : 4;
  const int count = 80 / big;
  const auto pts = dense_points(type.family, type.dim == 3 ? 8 / (big > 1 ? 2 : 1) + 2 : 24, 150 / big, rng);
  BoundsWorkspace ws;
  BoundsOptions measure;
  measure.goal = BoundsGoal::measure;
  measure.rel_tol = 1e-2;
  int kinds[3] = {0, 0, 0};
  for (int e = 0; e < count; ++e) {
    // Above order 6 independent noise at the nodes makes nearly every element invalid
    // (the equispaced interpolant amplifies it): curve those by a smooth field instead.
    const double amp = 0.04 * (1 + e % 6) / type.order;  // node spacing shrinks as 1/p
    const auto x = type.order > 6 ? smooth_random_element(type, 0.05 * (1 + e % 6), rng)
                                  : random_element(type, amp, rng);
    const bool planar = type.dim == 2;
    double smin = INFINITY, smax = -INFINITY, scale = 0;
    for (const auto& p : pts) {
      const double j = jacobian_at(lb, x, p, planar);
      smin = std::min(smin, j);
      smax = std::max(smax, j);
      scale = std::max(scale, std::abs(j));
    }
    const double slack = 1e-11 * scale;  // rounding of the sampled values
    const JacobianBounds v = jacobian_bounds(type, x, BoundsOptions{}, ws, planar);
    ASSERT_LE(v.jmin_lower, smin + slack) << type.name << " element " << e;
    ASSERT_GE(v.jmax_upper, smax - slack) << type.name << " element " << e;
    if (smin < -slack) {
      ASSERT_NE(v.validity, Validity::valid) << type.name << " element " << e;
    }
    ++kinds[static_cast<int>(v.validity)];
    const JacobianBounds m = jacobian_bounds(type, x, measure, ws, planar);
    ASSERT_LE(m.jmin_lower, smin + slack) << type.name << " element " << e;
    ASSERT_GE(m.jmax_upper, smax - slack) << type.name << " element " << e;
    ASSERT_LE(m.jmax_lower, m.jmax_upper);
    ASSERT_LE(m.jmin_lower, m.jmin_upper);
    if (m.tolerance_met) {
      const double tol = measure.rel_tol * std::max(std::abs(m.jmin_upper), std::abs(m.jmax_lower));
      EXPECT_LE(m.jmin_upper - m.jmin_lower, tol * 1.0001);
      EXPECT_LE(m.jmax_upper - m.jmax_lower, tol * 1.0001);
    }
    // validity agrees between the two goals whenever both decided
    if (m.validity != Validity::undetermined && v.validity != Validity::undetermined) {
      EXPECT_EQ(m.validity, v.validity);
    }
  }
  EXPECT_GT(kinds[0], 0) << type.name << ": no valid element in the random set";
}

std::string type_name(const testing::TestParamInfo<const ElementType*>& i) {
  std::string s(i.param->name);
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(AllTypes, DenseSamplingTest,
                         testing::ValuesIn(test::analysed_types(10, 4)), type_name);

// Affine elements: J is constant, det(A) in Gmsh's reference coordinates.
TEST(JacobianBoundsKnown, AffineElementsHaveConstantJacobian) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  BoundsWorkspace ws;
  for (const ElementType* type : test::analysed_types(10, 4)) {
    double a[3][3] = {{2, 0.3, 0.1}, {-0.2, 1.5, 0.4}, {0.1, 0.2, 1.2}};
    if (type->dim == 2) a[0][2] = a[1][2] = a[2][0] = a[2][1] = 0, a[2][2] = 1;
    const auto ref = reference_nodes(*type);
    std::vector<double> x;
    for (const auto& p : ref)
      for (int i = 0; i < 3; ++i) {
        double v = 100.0 * (i + 1);
        for (int j = 0; j < 3; ++j) v += a[i][j] * p[static_cast<std::size_t>(j)];
        x.push_back(type->dim == 2 && i == 2 ? 0.0 : v);
      }
    double want;
    if (type->dim == 3)
      want = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
             a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    else if (type->dim == 2)
      want = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    else
      want = std::sqrt(a[0][0] * a[0][0] + a[1][0] * a[1][0] + a[2][0] * a[2][0]);
    BoundsOptions measure;
    measure.goal = BoundsGoal::measure;
    measure.rel_tol = 1e-2;
    const JacobianBounds b = jacobian_bounds(*type, x, measure, ws, type->dim == 2);
    EXPECT_EQ(b.validity, Validity::valid) << type->name;
    // Slack 1e-12: the nodes are rounded at magnitude ~300 for an element of size ~2, so
    // the exact J of the doubles differs from the closed form by ~300 u / 2 per derivative.
    EXPECT_LE(b.jmin_lower, want * (1 + 1e-12)) << type->name;
    EXPECT_GE(b.jmin_upper, want * (1 - 1e-12)) << type->name;
    // The certified margin is the conversion's norm times the samples' rounding bound:
    // small, but far above 1 ulp for high orders (the equispaced Lagrange-to-Bézier
    // conversion is ill-conditioned: its norm is ~1e3 at degree 8 per direction).
    const double margin = type->order <= 2 ? 1e-6 : type->order <= 4 ? 1e-3 : 1e-2;
    EXPECT_NEAR(b.jmin_lower, want, margin * want) << type->name;
    EXPECT_NEAR(b.jmax_upper, want, margin * want) << type->name;
    const DistortionBounds d = distortion_bounds(*type, x, b, ws, type->dim == 2);
    EXPECT_NEAR(d.lower, 1.0, margin) << type->name;
    EXPECT_LE(d.lower, 1.0 + 1e-14) << type->name;
    // Mirrored element (3D: swap x and y; 2D planar: negate y): J = -det, invalid at once.
    std::vector<double> m = x;
    for (std::size_t i = 0; i < m.size(); i += 3) {
      if (type->dim == 3) std::swap(m[i], m[i + 1]);
      if (type->dim == 2) m[i + 1] = -m[i + 1];
    }
    if (type->dim >= 2) {
      const JacobianBounds bm = jacobian_bounds(*type, m, BoundsOptions{}, ws, type->dim == 2);
      EXPECT_EQ(bm.validity, Validity::invalid) << type->name;
      EXPECT_EQ(bm.stage, 0) << type->name;
    }
  }
}

// Bilinear quadrangle: J is bilinear, so its extrema are the corner values (closed form:
// J at corner i = cross of its two edges / 4 in Gmsh coordinates).
TEST(JacobianBoundsKnown, BilinearQuadrangleExtremaAreCornerValues) {
  const ElementType& q4 = *find_element_type(3);
  const std::vector<double> x = {0, 0, 0, 2, 0, 0, 1.5, 1, 0, 0.2, 1.3, 0};
  double corner[4];
  for (int i = 0; i < 4; ++i) {
    const int n = (i + 1) % 4, p = (i + 3) % 4;
    const double ax = x[3 * n] - x[3 * i], ay = x[3 * n + 1] - x[3 * i + 1];
    const double bx = x[3 * p] - x[3 * i], by = x[3 * p + 1] - x[3 * i + 1];
    corner[i] = (ax * by - ay * bx) / 4;
  }
  BoundsWorkspace ws;
  BoundsOptions measure;
  measure.goal = BoundsGoal::measure;
  measure.rel_tol = 1e-12;
  const JacobianBounds b = jacobian_bounds(q4, x, measure, ws, true);
  const double lo = *std::min_element(corner, corner + 4), hi = *std::max_element(corner, corner + 4);
  EXPECT_LE(b.jmin_lower, lo);
  EXPECT_GE(b.jmin_upper, lo);
  EXPECT_LE(b.jmax_lower, hi);
  EXPECT_GE(b.jmax_upper, hi);
  EXPECT_NEAR(b.jmin_lower, lo, 1e-12);
  EXPECT_NEAR(b.jmax_upper, hi, 1e-12);
}

// A cubic triangle x = xi + alpha f(xi, eta), y = eta with
// J = 1 + alpha ((xi - c)^2 + (eta - c)^2 - r^2): positive on the whole boundary (the
// circle of radius r about (c, c) is inside the triangle) but 1 - alpha r^2 at (c, c).
std::vector<double> bubble_triangle(double alpha, double c, double r2) {
  const ElementType& t10 = *find_element_type(21);
  std::vector<double> x;
  for (const auto& p : reference_nodes(t10)) {
    const double xi = p[0], eta = p[1];
    const double f = (xi - c) * (xi - c) * (xi - c) / 3 + xi * ((eta - c) * (eta - c) - r2);
    x.push_back(xi + alpha * f);
    x.push_back(eta);
    x.push_back(0);
  }
  return x;
}

TEST(JacobianBoundsKnown, PositiveOnEdgesNegativeInsideIsInvalid) {
  const ElementType& t10 = *find_element_type(21);
  const double alpha = 50, c = 0.28125, r2 = 0.04;  // J(c, c) = 1 - 2 = -1
  const auto x = bubble_triangle(alpha, c, r2);
  const LagrangeBasis& lb = lagrange_basis(t10);
  // J > 0 on the whole boundary: vertices, edge nodes and 300 points along the edges
  for (int i = 0; i < 9; ++i) EXPECT_GT(jacobian_at(lb, x, reference_nodes(t10)[static_cast<std::size_t>(i)], true), 0);
  for (int k = 0; k <= 100; ++k) {
    const double s = k / 100.0;
    EXPECT_GT(jacobian_at(lb, x, {s, 0, 0}, true), 0);
    EXPECT_GT(jacobian_at(lb, x, {0, s, 0}, true), 0);
    EXPECT_GT(jacobian_at(lb, x, {s, 1 - s, 0}, true), 0);
  }
  BoundsWorkspace ws;
  const JacobianBounds b = jacobian_bounds(t10, x, BoundsOptions{}, ws, true);
  EXPECT_EQ(b.validity, Validity::invalid);
  EXPECT_LE(b.jmin_upper, 0);
  EXPECT_LE(b.jmin_lower, -1 + 1e-9);
  // moving the bump's depth above zero makes it valid
  const auto y = bubble_triangle(alpha, c, 0.019);  // J(c, c) = 0.05
  EXPECT_EQ(jacobian_bounds(t10, y, BoundsOptions{}, ws, true).validity, Validity::valid);
}

TEST(JacobianBoundsKnown, MinimumOfOneTrillionthBothSigns) {
  const ElementType& t10 = *find_element_type(21);
  const double alpha = 50, c = 0.28;  // (c, c) is no dyadic subdivision vertex
  BoundsWorkspace ws;
  BoundsOptions opts;
  opts.max_subdivisions = 5000;
  for (const double target : {1e-12, -1e-12}) {
    // 1 - alpha r2 = target
    const auto x = bubble_triangle(alpha, c, (1 - target) / alpha);
    const JacobianBounds b = jacobian_bounds(t10, x, opts, ws, true);
    EXPECT_EQ(b.validity, target > 0 ? Validity::valid : Validity::invalid) << target;
    EXPECT_LE(b.jmin_lower, target * (1 + 1e-2)) << target;
    EXPECT_GE(b.jmin_upper, target * (1 - 1e-2) - 1e-300) << target;
  }
}

// The subdivision limit gives undetermined, never valid or invalid.
TEST(JacobianBoundsKnown, SubdivisionLimitGivesUndetermined) {
  const ElementType& t10 = *find_element_type(21);
  const auto x = bubble_triangle(50, 0.28125, (1 - 1e-12) / 50);
  BoundsWorkspace ws;
  BoundsOptions opts;
  opts.max_subdivisions = 3;
  const JacobianBounds b = jacobian_bounds(t10, x, opts, ws, true);
  EXPECT_EQ(b.validity, Validity::undetermined);
  EXPECT_EQ(b.stage, -1);
  EXPECT_LE(b.jmin_lower, 1e-12);
  EXPECT_GE(b.jmin_upper, 1e-12);
}

}  // namespace
}  // namespace quadval
