// The topology validate_triangles keeps for the later steps (triangle_input.hpp) is the one
// a fresh build gives on the oriented triangles, reversed triangles included; and a parity
// split drops it.
#include "recombine/triangle_input.hpp"

#include <random>

#include <gtest/gtest.h>

#include "recombine/lookahead_parity.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval::recombine_detail {
namespace {

void expect_same_topology(const TriangleTopology& kept, const TriangleTopology& fresh) {
  EXPECT_EQ(kept.triangles, fresh.triangles);
  EXPECT_EQ(kept.edges, fresh.edges);
  EXPECT_EQ(kept.triangle_edges, fresh.triangle_edges);
  EXPECT_EQ(kept.neighbors, fresh.neighbors);
  EXPECT_EQ(kept.edge_triangle_offsets, fresh.edge_triangle_offsets);
  EXPECT_EQ(kept.edge_triangles, fresh.edge_triangles);
  EXPECT_EQ(kept.boundary_edges, fresh.boundary_edges);
  EXPECT_EQ(kept.num_misoriented_edges, fresh.num_misoriented_edges);
}

TEST(TriangleInput, KeptTopologyMatchesAFreshBuildAfterReversals) {
  std::mt19937 rng(11);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    Mesh m = test::random_grid_mesh(7, 5, seed);
    // Reverse a random third of the triangles: the minority is turned back by orient().
    std::vector<NodeIndex>& nodes = m.blocks[0].nodes;
    std::size_t reversed = 0;
    for (std::size_t t = 0; 3 * t < nodes.size(); ++t)
      if (rng() % 3 == 0) {
        std::swap(nodes[3 * t + 1], nodes[3 * t + 2]);
        ++reversed;
      }
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(m, "grid", warnings);
    ASSERT_GT(reversed, 0u);
    ASSERT_EQ(s.flipped, reversed) << seed;  // each reversed triangle turned back
    ASSERT_TRUE(s.topology.has_value());
    expect_same_topology(*s.topology, build_triangle_topology(s.triangles, s.node_tags.size()));
  }
}

TEST(TriangleInput, ParitySplitDropsTheKeptTopology) {
  std::vector<std::string> warnings;
  TriangleSurface s = prepare_triangles(test::random_grid_mesh(4, 3, 5, /*remove=*/1, /*make_even=*/false), "odd",
                                        warnings);
  ASSERT_EQ(s.triangles.size() % 2, 1u);
  ASSERT_TRUE(s.topology.has_value());
  make_pieces_even(s);
  ASSERT_EQ(s.odd_splits, 1u);
  EXPECT_FALSE(s.topology.has_value());
}

}  // namespace
}  // namespace quadval::recombine_detail
