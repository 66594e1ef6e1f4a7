// Straight-sided high-order elements (src/analysis/straight_sided.hpp): the margin against
// J and the first-order J sampled from the Lagrange shape-function gradients (no code in
// common with the margin's Bézier row sums), and `check`'s answers on such elements against
// the general path and dense samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "analysis/straight_sided.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

// The curved types with a straight-sided path: triangles and quadrangles (planar) to order
// 5, tetrahedra and hexahedra to 3, complete and serendipity.
std::vector<const ElementType*> straight_types() {
  std::vector<const ElementType*> out;
  for (const ElementType* t : test::analysed_types(5, 3))
    if (t->order >= 2 && (t->family == ElementFamily::triangle || t->family == ElementFamily::quadrangle ||
                          t->family == ElementFamily::tetrahedron || t->family == ElementFamily::hexahedron))
      out.push_back(t);
  return out;
}

const ElementType& first_order(const ElementType& type) {
  const ElementType* t = find_element_type(type.family, 1, true);
  EXPECT_NE(t, nullptr);
  return *t;
}

// A straight-sided element: random vertices (a random affine map of the reference ones,
// each vertex moved by up to `vertex_noise`: quadrangles and hexahedra become bilinear and
// trilinear), the other nodes where the first-order element puts them, then each of their
// coordinates (x, y in 2D) moved by up to `deviation`.
std::vector<double> straight_element(const ElementType& type, double vertex_noise, double deviation,
                                     std::mt19937& rng) {
  const ElementType& lin = first_order(type);
  const std::vector<double> v = test::random_element(lin, vertex_noise, rng);
  const LagrangeBasis& basis = lagrange_basis(lin);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto ref = reference_nodes(type);
  std::vector<double> x(v.begin(), v.end()), shape(static_cast<std::size_t>(lin.num_nodes));
  for (std::size_t i = static_cast<std::size_t>(lin.num_nodes); i < ref.size(); ++i) {
    basis.evaluate(ref[i], shape);
    for (std::size_t j = 0; j < 3; ++j) {
      double c = 0;
      for (std::size_t k = 0; k < shape.size(); ++k) c += shape[k] * v[3 * k + j];
      if (!(type.dim == 2 && j == 2)) c += deviation * u(rng);
      x.push_back(c);
    }
  }
  return x;
}

// StraightSidedMargin::margins of `count` elements given node by node (count x #nodes x 3),
// as a mesh whose nodes are listed in reverse, so that an element's connectivity differs
// from its position.
std::vector<double> margins_of(const StraightSidedMargin& straight, const ElementType& type,
                               const std::vector<double>& nodes, std::size_t count) {
  const std::size_t total = nodes.size() / 3;
  std::vector<double> coords(nodes.size());
  std::vector<NodeIndex> conn(total);
  for (std::size_t k = 0; k < total; ++k) {
    conn[k] = static_cast<NodeIndex>(total - 1 - k);
    std::copy_n(nodes.begin() + static_cast<std::ptrdiff_t>(3 * k), 3,
                coords.begin() + static_cast<std::ptrdiff_t>(3 * conn[k]));
  }
  EXPECT_EQ(total, count * static_cast<std::size_t>(type.num_nodes));
  std::vector<double> m(count);
  straight.margins(coords.data(), conn.data(), count, m.data());
  return m;
}

TEST(StraightSided, MarginBoundsJMinusTheFirstOrderJ) {
  std::mt19937 rng(11);
  for (const ElementType* type : straight_types()) {
    const StraightSidedMargin straight(*type, jacobian_space(*type), /*planar=*/true);
    ASSERT_NE(straight.kind(), LinearKind::none) << type->name;
    const ElementType& lin = first_order(*type);
    const LagrangeBasis& basis = lagrange_basis(*type);
    const auto points = test::dense_points(type->family, 8, 200, rng);
    for (double deviation : {0.0, 2e-10}) {
      double worst_ratio = 0;  // largest |J - J_1| / margin seen
      for (int e = 0; e < 20; ++e) {
        const std::vector<double> x = straight_element(*type, 0.15, deviation, rng);
        const double m = margins_of(straight, *type, x, 1)[0];
        ASSERT_TRUE(std::isfinite(m)) << type->name << " deviation " << deviation;
        const std::vector<double> vertices(x.begin(), x.begin() + 3 * lin.num_nodes);
        for (const RefPoint& p : points) {
          const double j = test::jacobian_at(basis, x, p, true);
          const double j1 = test::jacobian_at(lagrange_basis(lin), vertices, p, true);
          // the samples' own rounding: a few ulps of terms of size |J_1|
          EXPECT_LE(std::abs(j - j1), m + 1e-13 * std::abs(j1)) << type->name << " element " << e;
          worst_ratio = std::max(worst_ratio, std::abs(j - j1) / m);
        }
      }
      // The margin is an overestimate, but not a wild one: deviations of 2e-10 show.
      if (deviation > 0) {
        EXPECT_GT(worst_ratio, 1e-3) << type->name;
      }
    }
  }
}

// beta_c bounds the distance of column c of the Jacobian matrix (from the Lagrange
// gradients) from the first-order element's, everywhere.
TEST(StraightSided, BetaBoundsTheColumnsDistanceFromTheFirstOrderColumns) {
  std::mt19937 rng(14);
  for (const ElementType* type : straight_types()) {
    const StraightSidedMargin straight(*type, jacobian_space(*type), true);
    const ElementType& lin = first_order(*type);
    const auto points = test::dense_points(type->family, 6, 100, rng);
    const auto columns = [](const ElementType& t, const std::vector<double>& x, const RefPoint& p) {
      const LagrangeBasis& b = lagrange_basis(t);
      std::vector<double> g(static_cast<std::size_t>(3 * b.num_nodes()));
      b.evaluate_gradients(p, g);
      std::array<std::array<double, 3>, 3> c{};
      for (std::size_t i = 0; i < static_cast<std::size_t>(b.num_nodes()); ++i)
        for (std::size_t d = 0; d < 3; ++d)
          for (std::size_t j = 0; j < 3; ++j) c[d][j] += g[3 * i + d] * x[3 * i + j];
      return c;
    };
    double worst_ratio = 0;
    for (int e = 0; e < 10; ++e) {
      const std::vector<double> x = straight_element(*type, 0.15, 2e-10, rng);
      std::array<double, 3> beta{};
      ASSERT_TRUE(std::isfinite(straight.margin(x.data(), beta))) << type->name;
      const std::vector<double> vertices(x.begin(), x.begin() + 3 * lin.num_nodes);
      for (const RefPoint& p : points) {
        const auto c = columns(*type, x, p), c1 = columns(lin, vertices, p);
        for (std::size_t d = 0; d < static_cast<std::size_t>(type->dim); ++d) {
          const double dist = std::hypot(c[d][0] - c1[d][0], c[d][1] - c1[d][1], c[d][2] - c1[d][2]);
          const double slack = 1e-13 * std::hypot(c1[d][0], c1[d][1], c1[d][2]);  // the samples' rounding
          EXPECT_LE(dist, beta[d] + slack) << type->name << " column " << d;
          worst_ratio = std::max(worst_ratio, dist / beta[d]);
        }
      }
    }
    EXPECT_GT(worst_ratio, 1e-3) << type->name;
  }
}

// A lane block's margins are each element's own: margin() (one element) bit for bit, for
// straight and curved elements mixed in blocks and a tail.
TEST(StraightSided, BlockMarginsEqualOneElementMargins) {
  std::mt19937 rng(15);
  for (const ElementType* type : straight_types()) {
    const StraightSidedMargin straight(*type, jacobian_space(*type), true);
    std::vector<double> nodes;
    for (int e = 0; e < 19; ++e) {
      const std::vector<double> x = straight_element(*type, 0.15, e % 5 == 0 ? 1e-6 : 1e-12 * e, rng);
      nodes.insert(nodes.end(), x.begin(), x.end());
    }
    const std::vector<double> m = margins_of(straight, *type, nodes, 19);
    const auto stride = static_cast<std::size_t>(type->num_nodes) * 3;
    for (std::size_t e = 0; e < 19; ++e) {
      std::array<double, 3> beta{};
      EXPECT_EQ(m[e], straight.margin(nodes.data() + e * stride, beta)) << type->name << " element " << e;
      EXPECT_EQ(std::isfinite(m[e]), e % 5 != 0) << type->name << " element " << e;
    }
  }
}

TEST(StraightSided, CurvedOrNonFiniteElementsGetNoMargin) {
  std::mt19937 rng(12);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const ElementType* type : straight_types()) {
    const StraightSidedMargin straight(*type, jacobian_space(*type), true);
    const auto last = static_cast<std::size_t>(type->num_nodes - 1) * 3;
    // Nine elements: a curved one, then non-finite coordinates at a high-order node and at
    // a vertex, among straight ones (a full lane block and a tail).
    std::vector<double> nodes;
    for (int e = 0; e < 9; ++e) {
      const std::vector<double> x = straight_element(*type, 0.15, e == 0 ? 1e-6 : 0.0, rng);
      nodes.insert(nodes.end(), x.begin(), x.end());
    }
    const auto stride = static_cast<std::size_t>(type->num_nodes) * 3;
    nodes[3 * stride + last] = std::nan("");
    nodes[5 * stride + last + 1] = kInf;
    nodes[8 * stride + 1] = std::nan("");
    const std::vector<double> m = margins_of(straight, *type, nodes, 9);
    for (int e : {0, 3, 5, 8}) EXPECT_EQ(m[static_cast<std::size_t>(e)], kInf) << type->name << " element " << e;
    for (int e : {1, 2, 4, 6, 7}) EXPECT_TRUE(std::isfinite(m[static_cast<std::size_t>(e)])) << type->name << " element " << e;
  }
}

// check's validity answers on straight-sided elements, some inverted (two vertices
// swapped), equal the general path's, and its bounds hold at dense samples.
TEST(StraightSided, CheckDecidesStraightElementsAsTheGeneralPath) {
  std::mt19937 rng(13);
  std::size_t answers[3] = {0, 0, 0};
  for (const ElementType* type : straight_types()) {
    std::vector<std::vector<double>> elements;
    for (int e = 0; e < 40; ++e) {
      std::vector<double> x = straight_element(*type, 0.15, e % 2 == 0 ? 0.0 : 1e-10, rng);
      if (e % 5 == 0) {  // mirrored: every node's x negated, J < 0 everywhere
        for (std::size_t i = 0; i < x.size(); i += 3) x[i] = -x[i];
      }
      elements.push_back(x);
    }
    const Mesh mesh = test::mesh_of_elements(*type, elements);
    CheckOptions o;
    o.measure = CheckMeasure::validity;
    const CheckReport r = check_mesh(mesh, o);
    ASSERT_EQ(r.elements.size(), elements.size());
    BoundsOptions bo;
    bo.one_pass_decision = false;
    BoundsWorkspace ws;
    const LagrangeBasis& basis = lagrange_basis(*type);
    const auto points = test::dense_points(type->family, 6, 50, rng);
    for (std::size_t e = 0; e < elements.size(); ++e) {
      const JacobianBounds& b = r.elements[e].bounds;
      const JacobianBounds general = jacobian_bounds(*type, elements[e], bo, ws, true);
      EXPECT_EQ(b.validity, general.validity) << type->name << " element " << e;
      EXPECT_LE(b.jmin_lower, general.jmin_upper) << type->name << " element " << e;
      EXPECT_GE(b.jmin_upper, general.jmin_lower) << type->name << " element " << e;
      for (const RefPoint& p : points) {
        const double j = test::jacobian_at(basis, elements[e], p, true);
        const double slack = 1e-13 * std::abs(j);  // the sample's own rounding
        EXPECT_GE(j + slack, b.jmin_lower) << type->name << " element " << e;
        EXPECT_LE(j - slack, b.jmax_upper) << type->name << " element " << e;
      }
      ++answers[static_cast<int>(b.validity)];
    }
  }
  EXPECT_GT(answers[static_cast<int>(Validity::valid)], 0u);
  EXPECT_GT(answers[static_cast<int>(Validity::invalid)], 0u);
  EXPECT_EQ(answers[static_cast<int>(Validity::undetermined)], 0u);
}

// With mu or the scaled Jacobian measured, check settles validity by the fast paths too
// (first-order chunks, straight-sided margins computed 8 elements at a time and handed to
// the quality bounds): every element's bounds equal, bit for bit, those of mu_bounds and
// scaled_jacobian_bounds called on it alone.
TEST(StraightSided, CheckQualityOnTheFastPathsEqualsTheElementsOwn) {
  std::mt19937 rng(17);
  std::vector<const ElementType*> types;
  for (const ElementType* t : straight_types())
    if (t->order <= 3) types.push_back(t);
  for (ElementFamily f : {ElementFamily::triangle, ElementFamily::quadrangle, ElementFamily::tetrahedron,
                          ElementFamily::hexahedron})
    types.push_back(find_element_type(f, 1, true));
  std::size_t compared = 0;
  for (const ElementType* type : types) {
    std::vector<std::vector<double>> elements;
    for (int e = 0; e < 24; ++e) {
      std::vector<double> x = straight_element(*type, 0.15, e % 2 == 0 ? 0.0 : 1e-10, rng);
      if (e % 5 == 0)  // mirrored: J < 0 everywhere
        for (std::size_t i = 0; i < x.size(); i += 3) x[i] = -x[i];
      if (type->dim == 2)  // in the plane z = 0, as a 2D mesher writes it
        for (std::size_t i = 2; i < x.size(); i += 3) x[i] = 0;
      elements.push_back(x);
    }
    const Mesh mesh = test::mesh_of_elements(*type, elements);
    for (const CheckMeasure measure : {CheckMeasure::mu, CheckMeasure::scaled_jacobian}) {
      CheckOptions o;
      o.measure = measure;
      const CheckReport r = check_mesh(mesh, o);
      ASSERT_EQ(r.elements.size(), elements.size());
      QualityOptions qo;
      qo.abs_tol = o.quality_abs_tol;
      qo.max_subdivisions = o.max_subdivisions;
      for (std::size_t e = 0; e < elements.size(); ++e) {
        const bool mu = measure == CheckMeasure::mu;
        const QualityBounds got = mu ? r.mu_of(e) : r.sj_of(e);
        const QualityBounds want =
            mu ? mu_bounds(*type, elements[e], qo, true) : scaled_jacobian_bounds(*type, elements[e], qo, true);
        EXPECT_EQ(got.lower, want.lower) << type->name << (mu ? " mu" : " sj") << " element " << e;
        EXPECT_EQ(got.upper, want.upper) << type->name << (mu ? " mu" : " sj") << " element " << e;
        EXPECT_EQ(got.tolerance_met, want.tolerance_met) << type->name << " element " << e;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 800u);
}

}  // namespace
}  // namespace quadval
