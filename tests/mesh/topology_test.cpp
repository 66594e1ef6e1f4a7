// Triangle-mesh topology against hand counts and Euler's formula.
#include "quadval/topology.hpp"

#include <algorithm>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

using Tri = std::array<NodeIndex, 3>;

TEST(TriangleTopology, TwoTrianglesOfASquare) {
  const std::vector<Tri> tris{{0, 1, 2}, {0, 2, 3}};
  const TriangleTopology t = build_triangle_topology(tris, 4);
  EXPECT_EQ(t.num_edges(), 5u);
  EXPECT_EQ(t.boundary_edges.size(), 4u);
  EXPECT_TRUE(t.nonmanifold_edges.empty());
  EXPECT_TRUE(t.even());
  // The diagonal 0-2 is edge 2 of triangle 0 and edge 0 of triangle 1.
  EXPECT_EQ(t.neighbors[0][2], 1u);
  EXPECT_EQ(t.neighbors[1][0], 0u);
  EXPECT_EQ(t.neighbors[0][0], kNoTriangle);
  EXPECT_EQ(t.triangle_edges[0][2], t.triangle_edges[1][0]);
  EXPECT_EQ(t.edges[t.triangle_edges[0][2]], (std::array<NodeIndex, 2>{0, 2}));
  ASSERT_EQ(t.boundary_loops.size(), 1u);
  EXPECT_EQ(std::set<NodeIndex>(t.boundary_loops[0].begin(), t.boundary_loops[0].end()),
            (std::set<NodeIndex>{0, 1, 2, 3}));
  EXPECT_EQ(t.vertex_valence, (std::vector<std::uint32_t>{3, 2, 3, 2}));
  EXPECT_EQ(t.vertex_triangles, (std::vector<std::uint32_t>{2, 1, 2, 1}));
  EXPECT_EQ(t.num_misoriented_edges, 0u);
}

TEST(TriangleTopology, SquareWithSquareHoleHasTwoLoops) {
  // Outer square 0..3, inner square 4..7, 8 triangles in the ring.
  const std::vector<Tri> tris{{0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
                              {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  const TriangleTopology t = build_triangle_topology(tris, 8);
  ASSERT_EQ(t.boundary_loops.size(), 2u);
  EXPECT_EQ(t.boundary_loops[0].size(), 4u);
  EXPECT_EQ(t.boundary_loops[1].size(), 4u);
  EXPECT_TRUE(t.open_boundary_chains.empty());
  // Euler for an annulus: V - E + F = 0.
  EXPECT_EQ(8 - static_cast<long>(t.num_edges()) + 8, 0);
}

TEST(TriangleTopology, NonManifoldEdgeMisorientationAndCollapsed) {
  // Three triangles on edge 0-1; the third one repeats the first's direction; one collapsed.
  const std::vector<Tri> tris{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {2, 2, 3}};
  const TriangleTopology t = build_triangle_topology(tris, 5);
  ASSERT_EQ(t.nonmanifold_edges.size(), 1u);
  EXPECT_EQ(t.edges[t.nonmanifold_edges[0]], (std::array<NodeIndex, 2>{0, 1}));
  EXPECT_EQ(t.edge_degree(t.nonmanifold_edges[0]), 3u);
  EXPECT_EQ(t.neighbors[0][0], kNoTriangle);  // no dual edge across a non-manifold edge
  EXPECT_EQ(t.collapsed_triangles, (std::vector<std::uint32_t>{3}));
  EXPECT_FALSE(t.even() == false);  // 4 triangles
  // Misoriented: a two-triangle edge run the same way by both.
  const std::vector<Tri> flipped{{0, 1, 2}, {0, 1, 3}};
  EXPECT_EQ(build_triangle_topology(flipped, 4).num_misoriented_edges, 1u);
}

TEST(TriangleTopology, RandomGridsSatisfyCountingIdentities) {
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const Mesh m = test::random_grid_mesh(2 + seed % 5, 2 + seed % 3, seed, 0, false);
    const TriangleTopology t = build_triangle_topology(m);
    SCOPED_TRACE(seed);
    const long nv = static_cast<long>(m.num_nodes()), ne = static_cast<long>(t.num_edges()),
               nf = static_cast<long>(t.num_triangles());
    EXPECT_EQ(nv - ne + nf, 1);  // a disk
    // Each triangle has 3 edge slots; interior edges fill two, boundary edges one.
    EXPECT_EQ(3 * nf, 2 * (ne - static_cast<long>(t.boundary_edges.size())) +
                          static_cast<long>(t.boundary_edges.size()));
    ASSERT_EQ(t.boundary_loops.size(), 1u);
    EXPECT_EQ(t.boundary_loops[0].size(), t.boundary_edges.size());
    // Neighbour relation is symmetric and agrees with shared edges.
    for (std::size_t a = 0; a < t.num_triangles(); ++a)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t b = t.neighbors[a][k];
        if (b == kNoTriangle) continue;
        const auto& nb = t.neighbors[b];
        EXPECT_TRUE(std::find(nb.begin(), nb.end(), a) != nb.end());
      }
    // Valence sums to twice the edge count.
    long valence = 0;
    for (auto v : t.vertex_valence) valence += v;
    EXPECT_EQ(valence, 2 * ne);
  }
}

TEST(TriangleTopology, FromMeshUsesCornerNodesOfAllTriangleBlocks) {
  Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 1, 2}});
  ElementBlock second = m.blocks[0];
  second.entity_tag = 2;
  second.tags = {2};
  second.nodes = {0, 2, 3};
  m.blocks.push_back(second);
  const TriangleTopology t = build_triangle_topology(m);
  EXPECT_EQ(t.num_triangles(), 2u);
  EXPECT_EQ(t.num_edges(), 5u);
}

}  // namespace
}  // namespace quadval
