// The last polish of the worst elements (polish_worst): a closed form, one interior node
// pulled off the centre of 2 x 2 unit squares goes back to where all four are squares.
#include <algorithm>

#include <gtest/gtest.h>

#include "recombine/smoothing.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

// 2 x 2 unit squares whose centre node is pulled to (1.3, 1.2): the polish must bring it back
// near (1, 1), where all four quads are squares (eta = 1), never lowering the worst score.
TEST(PolishWorst, RestoresTheSquaresAroundAPulledNode) {
  MixedMesh m;
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) m.add_node({double(i), double(j), 0.0}, 3 * j + i + 1);
  m.coords[3 * 4] = 1.3;
  m.coords[3 * 4 + 1] = 1.2;
  auto id = [](int i, int j) { return static_cast<NodeIndex>(3 * j + i); };
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      m.elements.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      m.region.push_back(0);
      m.normal.push_back({0, 0, 1});
      m.alive.push_back(1);
    }
  auto worst = [&] {
    double w = 2;
    for (std::size_t e = 0; e < 4; ++e) w = std::min(w, element_score(m, e));
    return w;
  };
  const double before = worst();
  EXPECT_LT(before, 0.9);
  const std::vector<char> boundary = region_boundary_nodes(m);
  EXPECT_GT(polish_worst(m, boundary, SmoothingOptions{}), 0u);
  EXPECT_NEAR(m.point(4)[0], 1.0, 0.01);
  EXPECT_NEAR(m.point(4)[1], 1.0, 0.01);
  EXPECT_GT(worst(), 0.98);
  for (NodeIndex v : {0u, 1u, 2u, 3u, 5u, 6u, 7u, 8u})  // corners of the square stay
    EXPECT_EQ(m.point(v)[2], 0.0);
  EXPECT_EQ(m.point(0)[0], 0.0);
}

}  // namespace
}  // namespace quadval
