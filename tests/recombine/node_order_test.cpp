// The nodes renumbered along the Z-order curve (node_order.hpp): a permutation that keeps
// every node's tag with its coordinates, in the order of a hand-computed Morton key; and the
// recombined mesh lists its nodes by increasing tag whatever the internal order. The
// triangles then in the order of their smallest node, stable, each carrying its region, tag
// and input index.
#include "recombine/node_order.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "quadval/recombine.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval::recombine_detail {
namespace {

TEST(NodeOrder, FourByFourGridFollowsTheZCurve) {
  // Nodes of a 4 x 4 grid listed row by row from the top, tags 101..116.
  TriangleSurface s;
  for (int i = 0; i < 16; ++i) {
    const int x = i % 4, y = 3 - i / 4;
    s.coords.insert(s.coords.end(), {double(x), double(y), 0.0});
    s.node_tags.push_back(101 + i);
  }
  s.triangles = {{0, 4, 5}, {15, 14, 10}};
  order_nodes_along_curve(s);
  // The Z-curve over cells (x, y) interleaves the bits x0 y0 x1 y1 (x lowest); on the full
  // range of 2^21 cells per axis, x = 0..3 maps to cells 0, 699050, 1398101, 2097151, whose
  // top two bits are those of x: so the order is that of the 2-bit key x0 y0 x1 y1 read from
  // the top bits: (x1 y1 x0 y0) most significant first.
  std::vector<std::pair<int, int>> expected;
  for (int k = 0; k < 16; ++k) {
    const int y1 = (k >> 3) & 1, x1 = (k >> 2) & 1, y0 = (k >> 1) & 1, x0 = k & 1;
    expected.push_back({2 * x1 + x0, 2 * y1 + y0});
  }
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(s.coords[3 * i], expected[i].first) << i;
    EXPECT_EQ(s.coords[3 * i + 1], expected[i].second) << i;
    const int x = expected[i].first, y = expected[i].second;
    EXPECT_EQ(s.node_tags[i], 101 + (3 - y) * 4 + x) << i;  // the tag moved with its node
  }
  // The triangles still join the same tagged nodes.
  const auto tags_of = [&](const std::array<NodeIndex, 3>& t) {
    return std::array<Tag, 3>{s.node_tags[t[0]], s.node_tags[t[1]], s.node_tags[t[2]]};
  };
  EXPECT_EQ(tags_of(s.triangles[0]), (std::array<Tag, 3>{101, 105, 106}));
  EXPECT_EQ(tags_of(s.triangles[1]), (std::array<Tag, 3>{116, 115, 111}));
}

TEST(NodeOrder, RandomSurfaceIsAPermutationKeepingTagsWithCoordinates) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3, 7);
  TriangleSurface s;
  const int n = 500;
  for (int i = 0; i < n; ++i) {
    s.coords.insert(s.coords.end(), {u(rng), u(rng), u(rng)});
    s.node_tags.push_back(1000 + 7 * i);
  }
  s.coords[3 * 17 + 1] = NAN;  // a node no triangle uses may hold anything
  for (int t = 0; t + 2 < n; t += 3) s.triangles.push_back({NodeIndex(t), NodeIndex(t + 1), NodeIndex(t + 2)});
  std::map<Tag, std::array<double, 3>> before;
  for (int i = 0; i < n; ++i) before[s.node_tags[i]] = {s.coords[3 * i], s.coords[3 * i + 1], s.coords[3 * i + 2]};
  const auto triangle_tags = [&] {
    std::vector<std::array<Tag, 3>> out;
    for (const auto& t : s.triangles) out.push_back({s.node_tags[t[0]], s.node_tags[t[1]], s.node_tags[t[2]]});
    return out;
  };
  const auto tri_before = triangle_tags();
  order_nodes_along_curve(s);
  ASSERT_EQ(s.node_tags.size(), std::size_t(n));
  ASSERT_EQ(s.coords.size(), std::size_t(3 * n));
  std::map<Tag, int> seen;
  for (int i = 0; i < n; ++i) {
    ++seen[s.node_tags[i]];
    const auto& c = before.at(s.node_tags[i]);
    for (int d = 0; d < 3; ++d) {
      if (std::isnan(c[d])) {
        EXPECT_TRUE(std::isnan(s.coords[3 * i + d]));
      } else {
        EXPECT_EQ(s.coords[3 * i + d], c[d]);
      }
    }
  }
  EXPECT_EQ(seen.size(), std::size_t(n));
  EXPECT_EQ(triangle_tags(), tri_before);
  // Z-order: the key's top three bits (the half of the bounding box on each axis, z highest)
  // never decrease along the order.
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    lo[d] = INFINITY;
    hi[d] = -INFINITY;
    for (int i = 0; i < n; ++i)
      if (std::isfinite(s.coords[3 * i + d])) {
        lo[d] = std::min(lo[d], s.coords[3 * i + d]);
        hi[d] = std::max(hi[d], s.coords[3 * i + d]);
      }
  }
  const auto octant = [&](int i) {
    int o = 0;
    for (int d = 0; d < 3; ++d) {
      const double x = s.coords[3 * i + d];
      const bool upper = std::isfinite(x) && (x - lo[d]) / (hi[d] - lo[d]) * ((1 << 21) - 1) >= (1 << 20);
      o |= (upper ? 1 : 0) << d;
    }
    return o;
  };
  for (int i = 0; i + 1 < n; ++i) {
    EXPECT_LE(octant(i), octant(i + 1)) << i;
  }
}

TEST(NodeOrder, RecombinedMeshListsNodesByIncreasingTag) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Mesh in = test::random_grid_mesh(9, 7, seed);
    const RecombineResult r = recombine(in, {});
    ASSERT_FALSE(r.mesh.node_tags.empty());
    EXPECT_TRUE(std::is_sorted(r.mesh.node_tags.begin(), r.mesh.node_tags.end())) << seed;
  }
}

TEST(NodeOrder, TrianglesFollowTheirSmallestNodeStably) {
  // Six triangles over 8 nodes; smallest nodes 5, 0, 2, 0, 5, 1 (by hand).
  TriangleSurface s;
  for (int i = 0; i < 8; ++i) {
    s.coords.insert(s.coords.end(), {double(i), 0.0, 0.0});
    s.node_tags.push_back(i + 1);
  }
  s.triangles = {{5, 6, 7}, {3, 0, 4}, {2, 7, 3}, {6, 4, 0}, {7, 5, 6}, {1, 2, 3}};
  s.region = {10, 11, 12, 13, 14, 15};
  s.triangle_tags = {20, 21, 22, 23, 24, 25};
  s.input_index = {0, 1, 2, 3, 4, 5};
  order_triangles_along_curve(s);
  // Keys 0 (inputs 1, 3 in that order), 1 (5), 2 (2), 5 (0, 4 in that order).
  const std::vector<std::uint32_t> expected = {1, 3, 5, 2, 0, 4};
  const std::vector<std::array<NodeIndex, 3>> input = {{5, 6, 7}, {3, 0, 4}, {2, 7, 3},
                                                       {6, 4, 0}, {7, 5, 6}, {1, 2, 3}};
  ASSERT_EQ(s.triangles.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(s.input_index[i], expected[i]) << i;
    EXPECT_EQ(s.triangles[i], input[expected[i]]) << i;  // corners and orientation kept
    EXPECT_EQ(s.region[i], static_cast<std::int32_t>(10 + expected[i])) << i;
    EXPECT_EQ(s.triangle_tags[i], static_cast<Tag>(20 + expected[i])) << i;
  }
}

}  // namespace
}  // namespace quadval::recombine_detail
