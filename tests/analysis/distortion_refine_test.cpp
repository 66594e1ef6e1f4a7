// The distortion J / J_straight of quadrangles, prisms, hexahedra and pyramids, refined
// best-first (ratio_refinement.hpp): against dense sampling of J and J_straight from the
// Lagrange shape-function gradients (jacobian_test_util.hpp, no shared code), the lower bound
// is never above a sampled value, the gap meets the tolerance, and the bounds are never wider
// than the first-level coefficient ratios (which alone were often far below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "analysis/jacobian_test_util.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {
namespace {

TEST(DistortionRefinement, DenseSamplingOfCurvedTensorElements) {
  std::mt19937 rng(31);
  BoundsWorkspace ws;
  BoundsOptions options;
  options.goal = BoundsGoal::measure;
  options.rel_tol = 1e-2;
  int checked = 0, sharper = 0;
  for (const auto& [family, max_order] :
       std::vector<std::pair<ElementFamily, int>>{{ElementFamily::quadrangle, 3},
                                                  {ElementFamily::prism, 2},
                                                  {ElementFamily::hexahedron, 2},
                                                  {ElementFamily::pyramid, 2}}) {
    const ElementType& straight_type = *find_element_type(family, 1, true);
    const LagrangeBasis& straight = lagrange_basis(straight_type);
    const auto nv = static_cast<std::size_t>(straight_type.num_nodes);
    for (int order = 1; order <= max_order; ++order) {
      const ElementType& type = *find_element_type(family, order, true);
      const LagrangeBasis& curved = lagrange_basis(type);
      const bool planar = type.dim == 2;
      for (int trial = 0; trial < 25; ++trial) {
        const std::vector<double> x = test::random_element(type, 0.12, rng);
        const JacobianBounds jb = jacobian_bounds(type, x, options, ws, planar);
        if (jb.validity != Validity::valid) continue;
        const DistortionBounds d = distortion_bounds(type, x, jb, ws, planar, options);
        if (std::isnan(d.lower)) continue;  // straight element not proven positive
        const std::vector<double> vertices(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(3 * nv));
        double sampled = INFINITY;
        for (const RefPoint& p : test::dense_points(family, 10, 200, rng)) {
          const double js = test::jacobian_at(straight, vertices, p, planar);
          ASSERT_GT(js, 0) << type.name;
          sampled = std::min(sampled, test::jacobian_at(curved, x, p, planar) / js);
        }
        SCOPED_TRACE(::testing::Message() << type.name << " trial " << trial);
        EXPECT_LE(d.lower, sampled * (1 + 1e-12) + 1e-12);
        EXPECT_LE(d.lower, d.upper);
        EXPECT_LE(d.upper - d.lower, std::max(options.abs_tol, options.rel_tol * std::abs(d.upper)) * (1 + 1e-9));
        // The first-level bound (no refinement) for comparison: refinement must not lose.
        BoundsOptions first = options;
        first.max_subdivisions = 0;
        const DistortionBounds d0 = distortion_bounds(type, x, jb, ws, planar, first);
        EXPECT_GE(d.lower, d0.lower);
        EXPECT_LE(d.upper, d0.upper);
        if (d.lower > d0.lower + 0.01) ++sharper;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 150);
  EXPECT_GT(sharper, 10);  // refinement matters on curved elements
}

// A straight parallelogram quadrangle with one curved (order 2) edge: J_straight is constant,
// so min J / J_straight = min J / J_straight(0), which the Jacobian bounds bracket.
TEST(DistortionRefinement, ParallelogramWithACurvedEdgeMatchesTheJacobianBounds) {
  const ElementType& q9 = *find_element_type(10);
  // Corners (0,0) (2,0) (2.5,1) (0.5,1), mid-edge and centre nodes on the straight element,
  // then the mid-node of edge 0-1 pushed inward.
  std::vector<double> x = {0, 0, 0, 2, 0, 0, 2.5, 1, 0, 0.5, 1, 0,
                           1, 0, 0, 2.25, 0.5, 0, 1.5, 1, 0, 0.25, 0.5, 0, 1.25, 0.5, 0};
  x[4 * 3 + 1] = 0.3;
  BoundsWorkspace ws;
  BoundsOptions options;
  options.goal = BoundsGoal::measure;
  options.rel_tol = 1e-6;
  const JacobianBounds jb = jacobian_bounds(q9, x, options, ws, true);
  ASSERT_EQ(jb.validity, Validity::valid);
  const double js = 2.0 * 1.0 / 4.0;  // area 2 over the reference square's 4
  const DistortionBounds d = distortion_bounds(q9, x, jb, ws, true, options);
  EXPECT_LE(d.lower, jb.jmin_upper / js * (1 + 1e-12));
  EXPECT_GE(d.upper, jb.jmin_lower / js * (1 - 1e-12));
  // Both bracket min J / js: they agree within the two gaps.
  EXPECT_NEAR(d.lower, jb.jmin_lower / js, (jb.jmin_upper - jb.jmin_lower) / js + (d.upper - d.lower));
  EXPECT_LE(d.upper - d.lower, 1e-6 * std::abs(d.upper) * (1 + 1e-9));
}

}  // namespace
}  // namespace quadval
