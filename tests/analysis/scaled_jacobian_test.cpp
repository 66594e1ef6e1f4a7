// Certified scaled-Jacobian bounds (scaled_jacobian.hpp) against oracles that share no
// code with them: closed forms of straight elements, hand-derived corner values, and the
// pointwise definition evaluated straight from the Lagrange shape-function gradients
// (lagrange_basis.hpp) at dense points.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "check_alone_test_util.hpp"
#include "jacobian_test_util.hpp"
#include "lanes_test_util.hpp"
#include "scaled_jacobian_test_util.hpp"
#include "quadval/io.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/scaled_jacobian.hpp"
#include "analysis/scaled_jacobian_probe.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "analysis/linear_pyramid_sj.hpp"
#include "analysis/trilinear_hex_sj.hpp"

namespace quadval {
namespace {

using test::combo;
using test::cross;
using test::dot;
using test::minus;
using test::norm;
using test::straight_element;
using test::Vec;

// The corner of a simplex (vertices v[0..n-1]) whose edge lengths from it multiply to the
// most where sign >= 0 and to the least where sign < 0: dividing a value of that sign by
// it gives the least over the corners, the definition's minimum over the frames.
double corner_product(const Vec* v, int n, double sign) {
  double best = sign >= 0 ? 0 : INFINITY;
  for (int k = 0; k < n; ++k) {
    double prod = 1;
    for (int m = 0; m < n; ++m)
      if (m != k) prod *= norm(minus(v[m], v[k]));
    best = sign >= 0 ? std::max(best, prod) : std::min(best, prod);
  }
  return best;
}
// The pointwise scaled Jacobian by the vertex formulation: the affinely mapped reference
// element spanned by the columns c_j, its corner edge products, J's sign as in
// jacobian_bounds.hpp (`normal` for 2D, `tangent` for 1D).
double sj_at(const ElementType& type, const std::vector<double>& x, const RefPoint& p,
             const Vec& normal, const Vec& tangent) {
  const LagrangeBasis& lb = lagrange_basis(type);
  const int n = lb.num_nodes();
  std::vector<double> g(static_cast<std::size_t>(3 * n));
  lb.evaluate_gradients(p, g);
  std::array<Vec, 3> c{};
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      for (int j = 0; j < 3; ++j) c[d][j] += g[static_cast<std::size_t>(3 * i + d)] * x[static_cast<std::size_t>(3 * i + j)];
  const double s2 = 2 / std::sqrt(3.0);
  switch (type.family) {
    case ElementFamily::line: return dot(c[0], tangent) / norm(c[0]);
    case ElementFamily::quadrangle: {
      const Vec w = cross(c[0], c[1]);
      const double sign = dot(w, normal) > 0 ? 1 : dot(w, normal) < 0 ? -1 : 0;
      return sign * norm(w) / (norm(c[0]) * norm(c[1]));
    }
    case ElementFamily::triangle: {
      const Vec w = cross(c[0], c[1]);
      const double sign = dot(w, normal) > 0 ? 1 : dot(w, normal) < 0 ? -1 : 0;
      const Vec v[3] = {{0, 0, 0}, c[0], c[1]};
      return s2 * sign * norm(w) / corner_product(v, 3, sign);
    }
    case ElementFamily::hexahedron:
      return dot(c[0], cross(c[1], c[2])) / (norm(c[0]) * norm(c[1]) * norm(c[2]));
    case ElementFamily::tetrahedron: {
      const double j = dot(c[0], cross(c[1], c[2]));
      const Vec v[4] = {{0, 0, 0}, c[0], c[1], c[2]};
      return std::sqrt(2.0) * j / corner_product(v, 4, j);
    }
    case ElementFamily::prism: {
      const double j = dot(c[0], cross(c[1], c[2]));
      const Vec v[3] = {{0, 0, 0}, c[0], c[1]};
      return s2 * j / (corner_product(v, 3, j) * norm(c[2]));
    }
    case ElementFamily::pyramid: {
      // The four base-corner frames E_k (half base edges to the next and previous vertex,
      // the edge to the apex, det E_k = 1).
      const double base[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      double worst = INFINITY;
      for (int k = 0; k < 4; ++k) {
        const double* v = base[k];
        const double* next = base[(k + 1) % 4];
        const double* prev = base[(k + 3) % 4];
        Vec e[3] = {{(next[0] - v[0]) / 2, (next[1] - v[1]) / 2, 0}, {(prev[0] - v[0]) / 2, (prev[1] - v[1]) / 2, 0}, {-v[0], -v[1], 1}};
        if (dot(e[0], cross(e[1], e[2])) < 0) std::swap(e[0], e[1]);
        Vec w[3];
        for (std::size_t j = 0; j < 3; ++j) w[j] = combo(c, e[j]);
        worst = std::min(worst, std::sqrt(2.0) * dot(w[0], cross(w[1], w[2])) / (norm(w[0]) * norm(w[1]) * norm(w[2])));
      }
      return worst;
    }
    default: return NAN;
  }
}

// The unit chord from node 0 to node 1 (the 1D reference direction of the tests' elements).
Vec chord(const std::vector<double>& x) {
  const Vec d = {x[3] - x[0], x[4] - x[1], x[5] - x[2]};
  return Vec{d[0] / norm(d), d[1] / norm(d), d[2] / norm(d)};
}

// The least pointwise sj at the points (planar 2D: n = +z).
double sampled_min(const ElementType& t, const std::vector<double>& x, const std::vector<RefPoint>& pts) {
  double m = INFINITY;
  for (const RefPoint& p : pts) m = std::min(m, sj_at(t, x, p, {0, 0, 1}, chord(x)));
  return m;
}

QualityBounds bounds(const ElementType& t, const std::vector<double>& x, double tol = 1e-6,
                     bool planar = true) {
  QualityOptions o;
  o.abs_tol = tol;
  o.max_subdivisions = 2000;
  return scaled_jacobian_bounds(t, x, o, planar);
}

// The general path's bounds (closed forms and root formulas off) overlap b: both enclose sj(E).
void expect_overlaps_general_path(const ElementType& t, const std::vector<double>& x, const QualityBounds& b) {
  scaled_jacobian_use_straight_path(false);
  const QualityBounds g = bounds(t, x, 1e-6);
  scaled_jacobian_use_straight_path(true);
  EXPECT_LE(b.lower, g.upper);
  EXPECT_LE(g.lower, b.upper);
}

void expect_value(const ElementType& t, const std::vector<double>& x, double want, bool planar = true) {
  SCOPED_TRACE(std::string(t.name));
  const QualityBounds b = bounds(t, x, 1e-9, planar);
  EXPECT_LE(b.lower, want + 1e-12);
  EXPECT_GE(b.upper, want - 1e-12);
  EXPECT_LE(b.upper - b.lower, 1e-9);
  EXPECT_TRUE(b.tolerance_met);
}

const ElementType& type_of(ElementFamily f, int order, bool complete = true) {
  return *find_element_type(f, order, complete);
}

TEST(ScaledJacobian, ParallelogramIsSineOfItsAngle) {
  for (int order = 1; order <= 3; ++order)
    for (double angle : {0.3, 1.0, M_PI / 2, 2.5}) {
      const double c = std::cos(angle), s = std::sin(angle);
      const std::vector<Vec> q = {{1, 2, 0}, {4, 2, 0}, {4 + 1.5 * c, 2 + 1.5 * s, 0}, {1 + 1.5 * c, 2 + 1.5 * s, 0}};
      expect_value(type_of(ElementFamily::quadrangle, order), straight_element(type_of(ElementFamily::quadrangle, order), q), s);
      // The mirror image is inverted: -sin.
      std::vector<Vec> m = q;
      for (Vec& v : m) v[0] = -v[0];
      expect_value(type_of(ElementFamily::quadrangle, order), straight_element(type_of(ElementFamily::quadrangle, order), m), -s);
    }
}

TEST(ScaledJacobian, TiltedPlanarQuadIsNotPenalisedForItsTilt) {
  // A rectangle with an angle of 1 rad, rotated out of the z = 0 plane: same value.
  const double c = std::cos(1.0), s = std::sin(1.0), ct = std::cos(0.7), st = std::sin(0.7);
  std::vector<Vec> q = {{0, 0, 0}, {2, 0, 0}, {2 + c, s, 0}, {c, s, 0}};
  for (Vec& v : q) v = {v[0], ct * v[1], st * v[1]};
  const ElementType& t = type_of(ElementFamily::quadrangle, 2);
  expect_value(t, straight_element(t, q), s, /*planar=*/false);
}

TEST(ScaledJacobian, ParallelepipedIsDetOverEdgeLengths) {
  const Vec e1 = {2, 0.3, 0.1}, e2 = {0.4, 1.5, -0.2}, e3 = {0.3, -0.5, 1.2};
  const Vec o = {5, -3, 7};
  const auto p = [&](int a, int b, int c) {
    return Vec{o[0] + a * e1[0] + b * e2[0] + c * e3[0], o[1] + a * e1[1] + b * e2[1] + c * e3[1],
               o[2] + a * e1[2] + b * e2[2] + c * e3[2]};
  };
  // Gmsh hexahedron vertex order.
  const std::vector<Vec> h = {p(0, 0, 0), p(1, 0, 0), p(1, 1, 0), p(0, 1, 0), p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)};
  const double want = dot(e1, cross(e2, e3)) / (norm(e1) * norm(e2) * norm(e3));
  for (int order = 1; order <= 2; ++order) {
    const ElementType& t = type_of(ElementFamily::hexahedron, order);
    expect_value(t, straight_element(t, h), want);
  }
}

TEST(ScaledJacobian, IdealSimplicesAndPrismAreOne) {
  const double r3 = std::sqrt(3.0);
  const std::vector<Vec> tri = {{0, 0, 0}, {1, 0, 0}, {0.5, r3 / 2, 0}};
  for (int order = 1; order <= 4; ++order)
    expect_value(type_of(ElementFamily::triangle, order), straight_element(type_of(ElementFamily::triangle, order), tri), 1);
  const std::vector<Vec> tet = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  // (1,1,1),(1,-1,-1),(-1,1,-1),(-1,-1,1) is regular; order it to positive volume.
  const double vol = dot(minus(tet[1], tet[0]), cross(minus(tet[2], tet[0]), minus(tet[3], tet[0])));
  std::vector<Vec> tet_pos = tet;
  if (vol < 0) std::swap(tet_pos[1], tet_pos[2]);
  for (int order = 1; order <= 2; ++order)
    expect_value(type_of(ElementFamily::tetrahedron, order), straight_element(type_of(ElementFamily::tetrahedron, order), tet_pos), 1);
  const std::vector<Vec> prism = {{0, 0, 0}, {1, 0, 0}, {0.5, r3 / 2, 0}, {0, 0, 3}, {1, 0, 3}, {0.5, r3 / 2, 3}};
  for (int order = 1; order <= 2; ++order)
    expect_value(type_of(ElementFamily::prism, order), straight_element(type_of(ElementFamily::prism, order), prism), 1);
  const std::vector<Vec> line = {{1, 2, 3}, {2, 4, 5}};
  expect_value(type_of(ElementFamily::line, 3), straight_element(type_of(ElementFamily::line, 3), line), 1);
}

TEST(ScaledJacobian, RightCornersByHand) {
  // Right isosceles triangle: angles 90, 45, 45: min sine sin 45, times 2/sqrt 3.
  const double want_tri = std::sqrt(0.5) * 2 / std::sqrt(3.0);
  const std::vector<Vec> tri = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  expect_value(type_of(ElementFamily::triangle, 2), straight_element(type_of(ElementFamily::triangle, 2), tri), want_tri);
  // Corner tetrahedron: corner 0 gives 1; corner (1,0,0) has edges 1, sqrt 2, sqrt 2 and
  // |det| 1: 1/2; times sqrt 2.
  const std::vector<Vec> tet = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  expect_value(type_of(ElementFamily::tetrahedron, 1), straight_element(type_of(ElementFamily::tetrahedron, 1), tet), std::sqrt(0.5));
  // Right prism on the right triangle: the triangle's value.
  const std::vector<Vec> prism = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  expect_value(type_of(ElementFamily::prism, 1), straight_element(type_of(ElementFamily::prism, 1), prism), want_tri);
}

// Dense sampling of random curved elements: the certified lower bound is never above a
// sampled value, and the gap meets the tolerance.
TEST(ScaledJacobian, DenseSamplingNeverBelowLowerBound) {
  std::mt19937 rng(20261122);
  std::size_t elements = 0, met = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.order > 3) continue;
    SCOPED_TRACE(std::string(t.name));
    // Inverted 3D elements of order 3 cost up to a second each (hundreds of subdivisions
    // of 455-4913 coefficients): at order 3 fewer elements, curved but mostly valid, keep
    // the test in seconds; lower orders cover the inverted ones.
    const bool costly = t.dim == 3 && t.order == 3;
    const int count = t.dim < 3 ? 150 : t.order == 1 ? 100 : t.order == 2 ? 40 : 10;
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, t.dim == 3 ? 60 : 100, rng);
    for (int e = 0; e < count; ++e) {
      const double amplitude = costly ? 0.08 : e % 3 == 0 ? (t.dim == 3 ? 0.15 : 0.25) : 0.08;
      const std::vector<double> x = test::random_element(t, amplitude, rng);
      const Vec tangent = [&] {
        Vec d = {x[3] - x[0], x[4] - x[1], x[5] - x[2]};
        const double l = norm(d);
        return Vec{d[0] / l, d[1] / l, d[2] / l};
      }();
      const QualityBounds b = bounds(t, x, 1e-3, /*planar=*/true);
      double sampled = INFINITY;
      for (const RefPoint& p : pts) sampled = std::min(sampled, sj_at(t, x, p, {0, 0, 1}, tangent));
      ASSERT_LE(b.lower, sampled + 1e-12) << "element " << e;
      ASSERT_LE(b.lower, b.upper) << "element " << e;
      ASSERT_GE(b.lower, -std::sqrt(2.0) * (1 + 1e-15));
      if (b.tolerance_met) {
        ++met;
        ASSERT_LE(b.upper - b.lower, 1e-3);
      }
      ++elements;
    }
  }
  EXPECT_GT(elements, 2000u);
  EXPECT_GE(met, elements * 98 / 100);
}

// Folded quadratic prisms of a Gmsh mesh (J changes sign inside): the subdomains across
// the fold are bounded by s J_lo / sqrt(min D_k), which ignores the positive side, so they
// converge in a few subdivisions (199 to 414 each when bounded by N = J^2 alone, whose
// maximum comes from the positive side), and the bounds still hold against dense sampling.
TEST(ScaledJacobian, FoldedPrismsConvergeQuickly) {
  const Mesh mesh = read_mesh(std::string(QUADVAL_SHARED_DIR) + "/data/curved/warped_prism_o2_N6_a0.25.msh");
  std::mt19937 rng(7);
  const ElementType& prism = *find_element_type(13);
  const auto pts = test::dense_points(prism.family, 10, 200, rng);
  int checked = 0;
  for (const ElementBlock& b : mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) {
      const Tag tag = b.tags[e];
      if (b.type != &prism || (tag != 107 && tag != 137 && tag != 179 && tag != 209)) continue;
      SCOPED_TRACE(tag);
      const std::vector<double> x = test::element_coordinates(mesh, b, e);
      const QualityBounds q = bounds(prism, x, 1e-2, /*planar=*/false);
      double sampled = INFINITY;
      for (const RefPoint& p : pts) sampled = std::min(sampled, sj_at(prism, x, p, {0, 0, 1}, {1, 0, 0}));
      EXPECT_LT(sampled, 0);  // folded
      EXPECT_LE(q.lower, sampled + 1e-12);
      EXPECT_TRUE(q.tolerance_met);
      EXPECT_LE(q.subdivisions, 40);
      ++checked;
    }
  EXPECT_EQ(checked, 4);
}

// The local search's bound (scaled_jacobian_probe.hpp) against this file's own pointwise
// formula at the point it reports: never below that value (it is a certified upper bound
// there), within rounding of it, and never above what the search started from.
TEST(ScaledJacobian, ProbeBoundsTheValueAtItsPoint) {
  std::mt19937 rng(23);
  const std::vector<const ElementType*> types = {&type_of(ElementFamily::triangle, 2), &type_of(ElementFamily::quadrangle, 2),
                                                 &type_of(ElementFamily::tetrahedron, 2), &type_of(ElementFamily::prism, 2),
                                                 &type_of(ElementFamily::hexahedron, 2)};
  for (const ElementType* t : types) {
    SCOPED_TRACE(std::string(t->name));
    int probed = 0;
    for (int e = 0; e < 60; ++e) {
      const std::vector<double> x = test::random_element(*t, 0.35, rng);
      const SjProbe r = scaled_jacobian_probe(*t, x, -INFINITY);
      if (!(r.upper < 0)) continue;
      ++probed;
      const std::array<double, 3>& p = r.point;
      RefPoint gmsh{p[0], p[1], p[2]};  // simplices: the same coordinates
      if (t->family == ElementFamily::quadrangle || t->family == ElementFamily::hexahedron)
        for (int c = 0; c < t->dim; ++c) gmsh[static_cast<std::size_t>(c)] = 2 * p[static_cast<std::size_t>(c)] - 1;
      if (t->family == ElementFamily::prism) gmsh[2] = 2 * p[2] - 1;
      const double value = sj_at(*t, x, gmsh, {0, 0, 1}, {1, 0, 0});
      EXPECT_GE(r.upper, value - 1e-13) << "element " << e;
      EXPECT_LE(r.upper, value + 1e-6) << "element " << e;
      // The certified bounds of the whole element enclose sj(E) <= that value.
      EXPECT_LE(bounds(*t, x, 1e-6).lower, r.upper) << "element " << e;
    }
    EXPECT_GE(probed, 5);
  }
}

// quad_h0.4_o2's four most inverted quadrangles (Gmsh, the plate with holes) reach the
// floor -1 of the scaled Jacobian at a fold: the signed stage's lower bound is -1 there,
// and the local search's upper bound settles them with no subdivision (26-30 each without
// it). The bounds hold against dense sampling, and the upper bound is not below -1.
TEST(ScaledJacobian, FoldedQuadranglesAtTheFloorSettleWithoutSubdivisions) {
  const Mesh mesh = read_mesh(std::string(QUADVAL_SHARED_DIR) + "/data/curved/quad_h0.4_o2.msh");
  std::mt19937 rng(3);
  const ElementType& quad = type_of(ElementFamily::quadrangle, 2);
  const auto pts = test::dense_points(quad.family, 40, 2000, rng);
  int checked = 0;
  for (const ElementBlock& b : mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) {
      const Tag tag = b.tags[e];
      if (b.type != &quad || (tag != 135 && tag != 139 && tag != 145 && tag != 149)) continue;
      SCOPED_TRACE(tag);
      const std::vector<double> x = test::element_coordinates(mesh, b, e);
      const QualityBounds q = bounds(quad, x, 1e-2);
      EXPECT_LE(q.lower, sampled_min(quad, x, pts) + 1e-12);
      EXPECT_GE(q.upper, -1.0);
      EXPECT_TRUE(q.tolerance_met);
      EXPECT_EQ(q.subdivisions, 0);
      ++checked;
    }
  EXPECT_EQ(checked, 4);
}

// Rotating the node numbering (same orientation) leaves the measure unchanged.
TEST(ScaledJacobian, RotatedNumberingGivesTheSameValue) {
  std::mt19937 rng(7);
  struct Case {
    const ElementType* type;
    std::vector<int> perm;  // new node i = old node perm[i]
  };
  const std::vector<Case> cases = {
      {&type_of(ElementFamily::triangle, 2), {1, 2, 0, 4, 5, 3}},
      {&type_of(ElementFamily::quadrangle, 2), {1, 2, 3, 0, 5, 6, 7, 4, 8}},
      {&type_of(ElementFamily::quadrangle, 1), {1, 2, 3, 0}},
      {&type_of(ElementFamily::tetrahedron, 1), {1, 2, 0, 3}},
      {&type_of(ElementFamily::hexahedron, 1), {1, 2, 3, 0, 5, 6, 7, 4}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.type->name));
    for (int e = 0; e < 20; ++e) {
      const std::vector<double> x = test::random_element(*c.type, 0.15, rng);
      std::vector<double> y(x.size());
      for (std::size_t i = 0; i < c.perm.size(); ++i)
        for (std::size_t j = 0; j < 3; ++j) y[3 * i + j] = x[3 * static_cast<std::size_t>(c.perm[i]) + j];
      const QualityBounds a = bounds(*c.type, x, 1e-6), b = bounds(*c.type, y, 1e-6);
      // Both enclose the same value.
      EXPECT_LE(a.lower, b.upper);
      EXPECT_LE(b.lower, a.upper);
      EXPECT_NEAR(a.lower, b.lower, 2e-6);
    }
  }
}

TEST(ScaledJacobian, InvertedCornerGivesNegativeBounds) {
  // A quadrangle with one vertex pulled across the diagonal: J < 0 near it.
  const std::vector<Vec> q = {{0, 0, 0}, {1, 0, 0}, {0.2, 0.2, 0}, {0, 1, 0}};
  const ElementType& t = type_of(ElementFamily::quadrangle, 1);
  const QualityBounds b = bounds(t, straight_element(t, q), 1e-4);
  EXPECT_LT(b.upper, 0);
  EXPECT_TRUE(b.tolerance_met);
  // At vertex 2 the columns are (v2 - v3) and (v2 - v1) up to positive factors: its value.
  const Vec a = minus(q[2], q[3]), c = minus(q[2], q[1]);
  const double corner = cross(a, c)[2] / (norm(a) * norm(c));
  EXPECT_LE(b.lower, corner);
}

// The first stage (J and the frame columns alone) on straight elements, where J and the
// columns are constant: both bounds equal the closed form, for every order.
TEST(ScaledJacobian, FirstStageIsExactOnStraightElements) {
  std::mt19937 rng(11);
  int checked = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.family == ElementFamily::pyramid || t.order > 4) continue;
    SCOPED_TRACE(std::string(t.name));
    for (int e = 0; e < 5; ++e) {
      const std::vector<double> x = test::random_element(t, 0.0, rng);
      const double want = sj_at(t, x, reference_nodes(t)[0], {0, 0, 1}, chord(x));
      const QualityBounds b = scaled_jacobian_quotient_stage(t, x, /*planar=*/true, 1.0, 0);
      EXPECT_LE(b.lower, want + 1e-12);
      EXPECT_GE(b.upper, want - 1e-12);
      EXPECT_LE(b.upper - b.lower, 1e-7);  // the rounding bounds of order-4 products
      ++checked;
    }
  }
  EXPECT_GT(checked, 150);
}

// Valid straight-sided simplices get closed-form bounds (scaled_jacobian.cpp: the edges as
// columns, within the straight-sided margin): they hold the pointwise value (constant per
// frame on an affine element) and overlap the general path's, also with the high-order
// nodes 1e-10 off their straight positions.
TEST(ScaledJacobian, StraightSimplicesInClosedFormHoldTheValue) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (const ElementType& t : element_types()) {
    const bool simplex = t.family == ElementFamily::triangle || t.family == ElementFamily::tetrahedron;
    if (!simplex || !scaled_jacobian_supported(t) || t.order > (t.dim == 2 ? 5 : 3)) continue;
    SCOPED_TRACE(std::string(t.name));
    const auto points = test::dense_points(t.family, 6, 50, rng);
    for (int e = 0; e < 6; ++e) {
      std::vector<double> x = test::random_element(t, 0.0, rng);
      if (e % 2 == 1)
        for (std::size_t i = 3 * static_cast<std::size_t>(t.dim + 1); i < x.size(); ++i)
          if (!(t.dim == 2 && i % 3 == 2)) x[i] += 1e-10 * u(rng);
      const QualityBounds b = bounds(t, x, 1e-6);
      // Never above a sampled value; straight (e even): sj is constant, both bounds hold it.
      EXPECT_LE(b.lower, sampled_min(t, x, points) + 1e-12);
      if (e % 2 == 0) {
        const double want = sj_at(t, x, reference_nodes(t)[0], {0, 0, 1}, chord(x));
        EXPECT_GE(b.upper, want - 1e-12);
        EXPECT_LE(b.upper - b.lower, 1e-10);
      }
      EXPECT_EQ(b.subdivisions, 0);
      EXPECT_TRUE(b.tolerance_met);
      expect_overlaps_general_path(t, x, b);
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);
}

// Valid planar quadrangles with a bilinear geometry get closed-form bounds
// (bilinear_quad_quality.hpp: the minimum of sj is at a corner): the least corner value, which
// dense sampling never finds below (the theorem, checked here independently), lies within
// them, without subdivisions; with the high-order nodes 1e-10 off the bilinear map the
// bounds still hold the sampled minimum and overlap the general path's.
TEST(ScaledJacobian, BilinearQuadrangleMinimumIsAtACorner) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int order = 1; order <= 4; ++order) {
    const ElementType& t = type_of(ElementFamily::quadrangle, order);
    SCOPED_TRACE(std::string(t.name));
    const auto points = test::dense_points(t.family, 24, 200, rng);
    for (int e = 0; e < 40; ++e) {
      const double z = 5 * u(rng), scale = std::pow(10.0, 3 * u(rng));
      std::vector<Vec> q = {{0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}};
      for (Vec& v : q)
        for (int j = 0; j < 2; ++j) v[static_cast<std::size_t>(j)] = scale * (v[static_cast<std::size_t>(j)] + 0.4 * u(rng));
      std::vector<double> x = straight_element(t, q);
      for (std::size_t i = 2; i < x.size(); i += 3) x[i] = z;  // exactly, as a 2D mesher writes it
      const bool off = order > 1 && e % 2 == 1;
      if (off)
        for (std::size_t i = 12; i < x.size(); ++i)
          if (i % 3 != 2) x[i] += 1e-10 * scale * u(rng);
      double corner_min = INFINITY;
      for (int k = 0; k < 4; ++k) corner_min = std::min(corner_min, sj_at(t, x, reference_nodes(t)[static_cast<std::size_t>(k)], {0, 0, 1}, chord(x)));
      if (!(corner_min > 0.05)) continue;  // not convex enough: the general path's case
      const double sampled = sampled_min(t, x, points);
      if (!off) {
        EXPECT_GE(sampled, corner_min - 1e-12);  // the minimum is at a corner
      }
      const QualityBounds b = bounds(t, x, 1e-6);
      EXPECT_LE(b.lower, sampled + 1e-12);
      EXPECT_LE(b.lower, corner_min + 1e-12);
      EXPECT_GE(b.upper, corner_min - (off ? 1e-6 : 1e-12));
      EXPECT_LE(b.upper - b.lower, off ? 1e-6 : 1e-9);  // the margins of rounding and of the nodes
      EXPECT_EQ(b.subdivisions, 0);
      EXPECT_TRUE(b.tolerance_met);
      expect_overlaps_general_path(t, x, b);
      ++checked;
    }
  }
  EXPECT_GE(checked, 100);
}

// The fixed-size root bound of valid first-order hexahedra (trilinear_hex_sj.hpp) against
// dense sampling and the general path (at 1e-6): never above a sampled value nor above the
// general upper bound, its upper bound (a corner value) never below the general lower one;
// and it settles most distorted hexahedra at the default tolerance, as the general path's
// root does.
TEST(ScaledJacobian, FirstOrderHexahedronRootBoundHoldsTheMinimum) {
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = type_of(ElementFamily::hexahedron, 1);
  const auto points = test::dense_points(t.family, 10, 300, rng);
  int checked = 0, settled = 0;
  for (int e = 0; e < 300; ++e) {
    const double scale = std::pow(10.0, 2 * u(rng)), amplitude = e % 3 == 0 ? 0.05 : 0.3;
    const Vec shift = {10 * u(rng), 10 * u(rng), 10 * u(rng)};
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(t))
      for (std::size_t j = 0; j < 3; ++j) x.push_back(scale * (p[j] + amplitude * u(rng)) + shift[j]);
    const double sampled = sampled_min(t, x, points);
    if (!(sampled > 0.02)) continue;  // invalid or nearly so: not this path's case
    const auto root = trilinear_hex_sj_bounds(x, 1.0);
    ASSERT_TRUE(root.has_value()) << "element " << e;
    scaled_jacobian_use_straight_path(false);
    const QualityBounds g = bounds(t, x, 1e-6);
    scaled_jacobian_use_straight_path(true);
    EXPECT_LE(root->lower, sampled + 1e-12) << "element " << e;
    EXPECT_LE(root->lower, g.upper) << "element " << e;
    EXPECT_LE(g.lower, root->upper) << "element " << e;
    EXPECT_GE(root->upper, sampled - 1e-12 - (root->upper - g.lower)) << "element " << e;
    if (trilinear_hex_sj_bounds(x, 1e-2)) ++settled;
    ++checked;
  }
  EXPECT_GE(checked, 200);
  EXPECT_GE(settled, checked * 3 / 4);
}

// `count` first-order elements of t: the reference nodes each moved at random by up to
// amplitude(e) per axis, then scaled by 10^[-2, 2] and shifted by up to 10.
template <class Amplitude>
std::vector<std::vector<double>> perturbed_reference_elements(const ElementType& t, int count, Amplitude amplitude,
                                                              std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::vector<double>> elements;
  for (int e = 0; e < count; ++e) {
    const double scale = std::pow(10.0, 2 * u(rng)), a = amplitude(e);
    const Vec shift = {10 * u(rng), 10 * u(rng), 10 * u(rng)};
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(t))
      for (std::size_t j = 0; j < 3; ++j) x.push_back(scale * (p[j] + a * u(rng)) + shift[j]);
    elements.push_back(x);
  }
  return elements;
}

// The check bounds the scaled Jacobian of valid first-order hexahedra four at a time
// (trilinear_hex_sj_lanes): every element gets the bits scaled_jacobian_bounds gives it
// alone, beside neighbours that the root bound settles and ones it leaves to the general
// path (strongly perturbed, some of them inverted).
TEST(ScaledJacobian, FirstOrderHexahedronChunksMatchEachElementAloneBitForBit) {
  std::mt19937 rng(52);
  const ElementType& t = type_of(ElementFamily::hexahedron, 1);
  const auto elements =
      perturbed_reference_elements(t, 1500, [](int e) { return e % 5 == 0 ? 0.45 : e % 3 == 0 ? 0.05 : 0.25; }, rng);
  int settled = 0;
  for (const auto& x : elements)
    if (trilinear_hex_sj_bounds(x, 1e-2)) ++settled;
  EXPECT_GT(settled, 900);
  EXPECT_GT(test::expect_check_matches_alone(t, elements, CheckMeasure::scaled_jacobian,
                                             [&](const std::vector<double>& x, const QualityOptions& q) {
                                               return scaled_jacobian_bounds(t, x, q, false);
                                             }),
            900);
}

// Likewise first-order pyramids (linear_pyramid_sj_lanes), bilinear bases and
// parallelograms, some inverted.
TEST(ScaledJacobian, FirstOrderPyramidChunksMatchEachElementAloneBitForBit) {
  std::mt19937 rng(53);
  const ElementType& t = type_of(ElementFamily::pyramid, 1);
  const auto elements =
      perturbed_reference_elements(t, 1500, [](int e) { return e % 5 == 0 ? 0.45 : e % 3 == 0 ? 0.0 : 0.15; }, rng);
  const ScaledJacobianSpace& space = scaled_jacobian_space(t);
  int settled = 0;
  for (const auto& x : elements)
    if (linear_pyramid_sj_bounds(space, x, 1e-2)) ++settled;
  EXPECT_GT(settled, 300);
  EXPECT_GT(test::expect_check_matches_alone(t, elements, CheckMeasure::scaled_jacobian,
                                             [&](const std::vector<double>& x, const QualityOptions& q) {
                                               return scaled_jacobian_bounds(t, x, q, false);
                                             }),
            700);
}

// The pointwise scaled Jacobian of a first-order pyramid by its definition (sj_at).
double pyramid_sj_at(const std::vector<double>& x, const RefPoint& p) {
  return sj_at(*find_element_type(ElementFamily::pyramid, 1, true), x, p, {0, 0, 1}, {1, 0, 0});
}

// The fixed-size first stage of valid first-order pyramids (linear_pyramid_sj.hpp) against
// the definition at dense points and the general path (at 1e-6): never above a sampled
// value nor the general upper bound, its upper bound never below the general lower one; and
// it settles at the default tolerance every element the general first stage settles
// without splitting (the same bound, but for its rounding margins).
TEST(ScaledJacobian, FirstOrderPyramidFirstStageHoldsTheMinimum) {
  std::mt19937 rng(61);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = type_of(ElementFamily::pyramid, 1);
  const ScaledJacobianSpace& space = scaled_jacobian_space(t);
  const auto points = test::dense_points(t.family, 10, 300, rng);
  int checked = 0, settled = 0;
  for (int e = 0; e < 300; ++e) {
    const double scale = std::pow(10.0, 2 * u(rng)), amplitude = e % 3 == 0 ? 0.02 : 0.2;
    const Vec shift = {10 * u(rng), 10 * u(rng), 10 * u(rng)};
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(t))
      for (std::size_t j = 0; j < 3; ++j) x.push_back(scale * (p[j] + amplitude * u(rng)) + shift[j]);
    double sampled = INFINITY;
    for (const RefPoint& p : points) sampled = std::min(sampled, pyramid_sj_at(x, p));
    if (!(sampled > 0.05)) continue;  // invalid or nearly so: not this path's case
    const auto first = linear_pyramid_sj_bounds(space, x, 1.0);
    ASSERT_TRUE(first.has_value()) << "element " << e;
    EXPECT_LE(first->lower, sampled + 1e-12) << "element " << e;
    expect_overlaps_general_path(t, x, *first);
    scaled_jacobian_use_paired_stage(false);  // the same bound as linear_pyramid_sj's
    const bool general_settles = scaled_jacobian_quotient_stage(t, x, false, 1e-2, 0).tolerance_met;
    scaled_jacobian_use_paired_stage(true);
    if (general_settles) {
      EXPECT_TRUE(linear_pyramid_sj_bounds(space, x, 1e-2 * (1 + 1e-6)).has_value()) << "element " << e;
      ++settled;
    }
    ++checked;
  }
  EXPECT_GE(checked, 200);
  EXPECT_GE(settled, 20);
}

// The first stage's bounds `stage` of element e enclose sj(E): lower <= upper, lower never
// above the full certified upper bound nor the sampled minimum, upper never below the full
// certified lower bound.
void expect_encloses(const ElementType& t, const std::vector<double>& x, const std::vector<RefPoint>& pts,
                     const QualityBounds& stage, int e) {
  const QualityBounds full = bounds(t, x, 1e-6);
  EXPECT_LE(stage.lower, stage.upper);
  EXPECT_LE(full.lower, stage.upper) << "element " << e;
  EXPECT_LE(stage.lower, full.upper) << "element " << e;
  EXPECT_LE(stage.lower, sampled_min(t, x, pts) + 1e-12) << "element " << e;
}

// The first stage on curved valid elements of every family (pyramids included) up to
// order 3: its lower bound is never above the sampled minimum, its upper bound never below
// the full certified lower bound (both enclose sj(E)); and on barely curved ones (node
// displacements of 1e-3 of the element size) it is sharp enough to settle most at the
// default tolerance 1e-2, which is what it is for (straight-sided interior elements are
// most of a curved mesh). Its gap grows about linearly with the curvature: at 2e-2 it
// settles few, and the full bounds take over.
TEST(ScaledJacobian, FirstStageBoundsEncloseSampledAndFullBounds) {
  std::mt19937 rng(2026);
  std::size_t elements = 0, barely = 0, settled = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.order > 3) continue;
    SCOPED_TRACE(std::string(t.name));
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 40, rng);
    for (int e = 0; e < (t.dim == 3 ? 12 : 24); ++e) {
      const double amplitude = e % 2 == 0 ? 1e-3 : 2e-2;
      const std::vector<double> x = test::smooth_random_element(t, amplitude, rng);
      const QualityBounds first = scaled_jacobian_quotient_stage(t, x, /*planar=*/true, 1.0, 0);
      if (!std::isfinite(first.lower)) continue;  // J's least coefficient not positive
      expect_encloses(t, x, pts, first, e);
      ++elements;
      if (amplitude == 1e-3) {
        ++barely;
        if (first.upper - first.lower <= 1e-2) ++settled;
      }
    }
  }
  EXPECT_GT(elements, 500u);
  EXPECT_GT(settled, barely * 9 / 10);
}

// The first stage refined (J and the columns split best-first) on curved valid elements of
// every family up to order 3: still enclosing the sampled minimum and the full bounds, the
// gap within the tolerance whenever it says so, and closing it on most of the elements it
// refines (those whose first gap is within twice the tolerance) in 16 splits.
TEST(ScaledJacobian, FirstStageRefinedEnclosesAndConverges) {
  std::mt19937 rng(77);
  scaled_jacobian_use_paired_stage(false);  // this bound's own refinement (the paired one: below)
  std::size_t elements = 0, refined = 0, met = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.order > 3) continue;
    SCOPED_TRACE(std::string(t.name));
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 40, rng);
    for (int e = 0; e < (t.dim == 3 ? 12 : 24); ++e) {
      const std::vector<double> x = test::smooth_random_element(t, 0.002 + 0.004 * (e % 3), rng);
      const QualityBounds root = scaled_jacobian_quotient_stage(t, x, /*planar=*/true, 1e-2, 0);
      const QualityBounds q = scaled_jacobian_quotient_stage(t, x, /*planar=*/true, 1e-2, 16);
      if (!std::isfinite(q.lower)) continue;
      expect_encloses(t, x, pts, q, e);
      EXPECT_LE(q.subdivisions, 16);
      EXPECT_GE(q.lower, root.lower) << "element " << e;  // refining never loosens
      if (q.tolerance_met) {
        EXPECT_LE(q.upper - q.lower, 1e-2);
      }
      ++elements;
      if (q.subdivisions > 0) {
        ++refined;
        if (q.tolerance_met) ++met;
      }
    }
  }
  scaled_jacobian_use_paired_stage(true);
  EXPECT_GT(elements, 500u);
  EXPECT_GT(refined, 30u);
  EXPECT_GT(met, refined * 9 / 10);
}

// The paired first stage of valid 3D elements (J's coefficients over products of upper
// bounds of the columns' norms, scaled_jacobian_quotient.cpp) on clearly curved ones, where
// the bound of J's least coefficient over the largest norms is far from the tolerance: its
// bounds enclose sj(E) (the sampled minimum, an oracle sharing no code with it, and the full
// bounds), the gap is within the tolerance whenever it says so, its root bound is never
// below the unpaired one, and refining settles most of these within 8 splits, far more
// than the unpaired stage does.
TEST(ScaledJacobian, PairedStageEnclosesSampledMinimumOnCurvedValidElements) {
  std::mt19937 rng(9090);
  std::size_t elements = 0, met = 0, unpaired_met = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.dim < 2 || t.order > 3 || t.order < 2) continue;
    SCOPED_TRACE(std::string(t.name));
    const bool planar = t.dim == 2;
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 40, rng);
    for (int e = 0; e < 24; ++e) {
      const std::vector<double> x = test::smooth_random_element(t, 0.02 + 0.02 * (e % 4), rng);
      if (!(sampled_min(t, x, pts) > 0)) continue;
      const QualityBounds q = scaled_jacobian_quotient_stage(t, x, planar, 1e-2, 8);
      if (!std::isfinite(q.lower)) continue;  // J's least coefficient not positive
      expect_encloses(t, x, pts, q, e);
      EXPECT_LE(q.subdivisions, 8);
      ++elements;
      if (q.tolerance_met) {
        EXPECT_LE(q.upper - q.lower, 1e-2);
        ++met;
      }
      const QualityBounds root = scaled_jacobian_quotient_stage(t, x, planar, 1e-2, 0);
      scaled_jacobian_use_paired_stage(false);
      const QualityBounds unpaired_root = scaled_jacobian_quotient_stage(t, x, planar, 1e-2, 0);
      if (scaled_jacobian_quotient_stage(t, x, planar, 1e-2, 8).tolerance_met) ++unpaired_met;
      scaled_jacobian_use_paired_stage(true);
      EXPECT_GE(root.lower, unpaired_root.lower) << "element " << e;
    }
  }
  EXPECT_GT(elements, 150u);
  EXPECT_GT(met, elements * 2 / 3);  // 280 of 360: a root beyond 4 tolerances is not refined
  EXPECT_GT(met, 2 * unpaired_met);  // 14
}

// Four valid planar elements at once (scaled_jacobian_valid_planar4, check_mesh's way):
// wherever it answers, exactly the bits of the element's own scaled_jacobian_bounds_given,
// whatever the other lanes hold (a lane's neighbours are shuffled between two runs), and it
// answers for most curved triangles and quadrangles of orders 2 to 6 (their first stage's
// root, or a closed form for the few nearly straight ones).
TEST(ScaledJacobian, FourPlanarElementsInLanesGiveTheirOwnBounds) {
  std::mt19937 rng(4242);
  QualityOptions o;
  o.abs_tol = 1e-2;
  std::size_t elements = 0, answered = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.dim != 2 || t.order < 2 || t.order > 6) continue;
    SCOPED_TRACE(std::string(t.name));
    std::vector<std::vector<double>> xs;
    BoundsWorkspace bw;
    for (int e = 0; xs.size() < 30 && e < 200; ++e) {
      std::vector<double> x = test::smooth_random_element(t, 0.01 + 0.02 * (e % 4), rng);
      if (e % 7 == 0) x = test::random_element(t, 0.0, rng);  // straight: a closed form
      if (jacobian_bounds(t, x, {}, bw, true).validity == Validity::valid) xs.push_back(std::move(x));
    }
    ASSERT_GE(xs.size(), 20u);
    std::vector<QualityBounds> own;
    for (const auto& x : xs) own.push_back(scaled_jacobian_bounds_given(t, x, o, true, Validity::valid));
    const std::vector<int> answers = test::check_four_at_once(
        xs, own, rng, [&](const auto& x, auto& out) { return scaled_jacobian_valid_planar4(t, x, o, {}, out); });
    for (std::size_t i = 0; i < xs.size(); ++i) {
      EXPECT_NE(answers[i], 1) << "element " << i << " answered in one run only";
      elements += 1;
      answered += answers[i] == 2;
    }
  }
  EXPECT_GT(elements, 150u);
  EXPECT_GT(answered, elements * 3 / 4);
}

// An element off its plane z = const among four (a planar mesh's element tilted in z):
// the lanes do not answer for its curved neighbours, which then take their own calls;
// whatever they do answer is still the elements' own bounds.
TEST(ScaledJacobian, FourPlanarElementsWithOneOffThePlaneAnswerNothingWrong) {
  std::mt19937 rng(77);
  QualityOptions o;
  o.abs_tol = 1e-2;
  const ElementType& t = *find_element_type(ElementFamily::triangle, 3, true);
  BoundsWorkspace bw;
  std::vector<std::vector<double>> xs;
  while (xs.size() < 4) {
    std::vector<double> x = test::smooth_random_element(t, 0.02, rng);
    if (jacobian_bounds(t, x, {}, bw, true).validity == Validity::valid) xs.push_back(std::move(x));
  }
  std::array<std::span<const double>, 4> x{xs[0], xs[1], xs[2], xs[3]};
  std::array<QualityBounds, 4> out;
  EXPECT_EQ(scaled_jacobian_valid_planar4(t, x, o, {}, out), 15u);  // all curved, all in z = 0
  xs[2][3 * 5 + 2] = 1e-3;  // node 5 off the plane
  x[2] = xs[2];
  EXPECT_EQ(scaled_jacobian_valid_planar4(t, x, o, {}, out), 0u);
}

// The signed first stage (J's coefficients with their signs, over products of the columns
// along their mean directions) on inverted curved 3D elements up to order 3: its lower
// bound never above the sampled minimum (an oracle sharing no code with it), its upper
// bound negative and never below the full bounds' lower bound, the gap within the
// tolerance whenever it says so; it settles a good share of these strongly curved ones in
// 8 splits (those of the warped meshes in ../shared/data nearly all).
TEST(ScaledJacobian, SignedStageEnclosesSampledMinimumOnInvertedElements) {
  std::mt19937 rng(4242);
  std::size_t inverted = 0, met = 0;
  for (const ElementType& t : element_types()) {
    if (!scaled_jacobian_supported(t) || t.dim < 2 || t.order > 3) continue;
    SCOPED_TRACE(std::string(t.name));
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 40, rng);
    for (int e = 0; e < 40; ++e) {
      const std::vector<double> x = test::smooth_random_element(t, 0.3 + 0.1 * (e % 4), rng);
      const double sampled = sampled_min(t, x, pts);
      if (!(sampled < 0)) continue;  // J < 0 at a sample: the stage's precondition
      const QualityBounds q = scaled_jacobian_signed_stage(t, x, 1e-2, 8);
      ++inverted;
      const QualityBounds full = bounds(t, x, 1e-2);
      EXPECT_LE(q.lower, sampled + 1e-12) << "element " << e;
      EXPECT_LE(q.upper, 0) << "element " << e;
      EXPECT_LE(full.lower, q.upper) << "element " << e;
      EXPECT_LE(q.lower, full.upper) << "element " << e;
      EXPECT_LE(q.subdivisions, 8);
      if (q.tolerance_met) {
        EXPECT_LE(q.upper - q.lower, 1e-2);
        ++met;
      }
    }
  }
  EXPECT_GT(inverted, 100u);
  EXPECT_GT(met, inverted / 3);  // 124 of 300
}

TEST(ScaledJacobian, SupportedTypes) {
  EXPECT_TRUE(scaled_jacobian_supported(type_of(ElementFamily::hexahedron, 2)));
  EXPECT_TRUE(scaled_jacobian_supported(*find_element_type(ElementFamily::quadrangle, 2, false)));
  EXPECT_TRUE(scaled_jacobian_supported(type_of(ElementFamily::pyramid, 1)));
  EXPECT_FALSE(scaled_jacobian_supported(type_of(ElementFamily::pyramid, 5)));
  for (const ElementType& t : element_types()) {
    if (scaled_jacobian_supported(t)) {
      EXPECT_TRUE(jacobian_bounds_supported(t)) << t.name;
    }
  }
}

}  // namespace
}  // namespace quadval
