// Boundary sliding: which nodes may slide (corners and curved sides may not), and a closed
// form: two quads of a 2 x 1 rectangle whose shared side is pulled off-centre recover the two
// unit squares (eta = 1) once the side's end nodes slide along the straight boundary.
#include <cmath>

#include <gtest/gtest.h>

#include "recombine/boundary_slide.hpp"
#include "recombine/smoothing.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

MixedMesh two_quads(double bottom_x, double top_x) {
  MixedMesh m;
  const double pts[6][2] = {{0, 0}, {bottom_x, 0}, {2, 0}, {0, 1}, {top_x, 1}, {2, 1}};
  for (int i = 0; i < 6; ++i) m.add_node({pts[i][0], pts[i][1], 0.0}, i + 1);
  m.elements = {{0, 1, 4, 3}, {1, 2, 5, 4}};
  m.region = {0, 0};
  m.normal = {{0, 0, 1}, {0, 0, 1}};
  m.alive = {1, 1};
  return m;
}

TEST(BoundarySlide, OnlyNodesInsideStraightSidesSlide) {
  const MixedMesh m = two_quads(0.3, 1.4);
  const std::vector<char> boundary = region_boundary_nodes(m);
  const auto slides = straight_boundary_slides(m, boundary);
  // Corners 0, 2, 3, 5 are fixed; 1 slides between 0 and 2, 4 between 3 and 5.
  for (NodeIndex v : {0u, 2u, 3u, 5u}) EXPECT_EQ(slides[v][0], kNoNode) << v;
  EXPECT_EQ(std::min(slides[1][0], slides[1][1]), 0u);
  EXPECT_EQ(std::max(slides[1][0], slides[1][1]), 2u);
  EXPECT_EQ(std::min(slides[4][0], slides[4][1]), 3u);
  EXPECT_EQ(std::max(slides[4][0], slides[4][1]), 5u);

  // Bend the bottom side at node 1: it is a corner now.
  MixedMesh bent = two_quads(0.3, 1.4);
  bent.coords[3 * 1 + 1] = -0.01;
  EXPECT_EQ(straight_boundary_slides(bent, region_boundary_nodes(bent))[1][0], kNoNode);
}

TEST(BoundarySlide, SmoothingRecoversTheTwoSquares) {
  MixedMesh m = two_quads(0.3, 1.4);
  const std::vector<char> boundary = region_boundary_nodes(m);
  const auto slides = straight_boundary_slides(m, boundary);
  SmoothingOptions options;
  options.passes = 50;
  options.slides = &slides;
  smooth(m, boundary, options);
  // The optimum is x = 1 for both (squares, eta = 1); the moves halve the distance at worst.
  EXPECT_NEAR(m.point(1)[0], 1.0, 1e-6);
  EXPECT_NEAR(m.point(4)[0], 1.0, 1e-6);
  for (NodeIndex v : {1u, 4u}) EXPECT_EQ(m.point(v)[1], v == 1 ? 0.0 : 1.0);  // on the sides
  EXPECT_NEAR(element_score(m, 0), 1.0, 1e-6);
  EXPECT_NEAR(element_score(m, 1), 1.0, 1e-6);

  // Without slides nothing can move: every node is on the boundary.
  MixedMesh still = two_quads(0.3, 1.4);
  SmoothingOptions fixed_only;
  fixed_only.passes = 50;
  EXPECT_EQ(smooth(still, boundary, fixed_only), 0u);
}

}  // namespace
}  // namespace quadval
