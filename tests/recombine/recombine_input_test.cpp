// Bad or unusual input: clear InputError messages, or the documented result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <vector>

#include "quadval/error.hpp"
#include "quadval/recombine.hpp"
#include "recombine/quad_mesh_checks.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

std::string error_of(const Mesh& m) {
  RecombineOptions o;
  o.source = "in.msh";
  try {
    recombine(m, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RecombineInput, NonManifoldEdgeIsRejected) {
  const Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {0, 1}, {0, -1}, {1, 1}},
                                          {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {2, 1, 4}});
  const std::string e = error_of(m);
  EXPECT_NE(e.find("in.msh"), std::string::npos) << e;
  EXPECT_NE(e.find("non-manifold edge"), std::string::npos) << e;
  EXPECT_NE(e.find("3 triangles"), std::string::npos) << e;
}

TEST(RecombineInput, DuplicateTriangleIsRejected) {
  const Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {0, 1}, {1, 1}},
                                          {{0, 1, 2}, {1, 3, 2}, {2, 0, 1}, {0, 2, 3}});
  const std::string e = error_of(m);
  EXPECT_NE(e.find("element 3"), std::string::npos) << e;
  EXPECT_NE(e.find("duplicate triangle"), std::string::npos) << e;
}

// Reversed, and with no third triangle on any edge: no edge is non-manifold.
TEST(RecombineInput, DuplicateTriangleWithOnlyTwoPerEdgeIsRejected) {
  const Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {0, 1}, {5, 5}, {6, 5}, {5, 6}},
                                          {{3, 4, 5}, {0, 1, 2}, {2, 1, 0}});
  const std::string e = error_of(m);
  EXPECT_NE(e.find("element 3"), std::string::npos) << e;
  EXPECT_NE(e.find("same three nodes as element 2"), std::string::npos) << e;
}

TEST(RecombineInput, ZeroAreaTriangleIsRejected) {
  const Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {2, 0}, {1, 1}},
                                          {{0, 1, 3}, {0, 1, 2}});
  const std::string e = error_of(m);
  EXPECT_NE(e.find("element 2"), std::string::npos) << e;
  EXPECT_NE(e.find("zero area"), std::string::npos) << e;
}

TEST(RecombineInput, QuadMeshIsRejected) {
  Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {});
  m.blocks[0].type = find_element_type(3);
  m.blocks[0].tags = {7};
  m.blocks[0].nodes = {0, 1, 2, 3};
  const std::string e = error_of(m);
  EXPECT_NE(e.find("element 7"), std::string::npos) << e;
  EXPECT_NE(e.find("quadrangle"), std::string::npos) << e;
  EXPECT_NE(e.find("triangles only"), std::string::npos) << e;
}

TEST(RecombineInput, NoTrianglesIsRejected) {
  Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}}, {});
  m.blocks.clear();
  EXPECT_NE(error_of(m).find("no triangles"), std::string::npos);
}

TEST(RecombineInput, InconsistentOrientationIsFixedToTheMajority) {
  // Three counter-clockwise triangles and one clockwise: the output faces +z.
  Mesh m = test::random_grid_mesh(2, 1, 4, 0, true, 0.0);
  auto& nodes = m.blocks[0].nodes;
  std::swap(nodes[1], nodes[2]);  // reverse the first triangle
  RecombineOptions o;
  const RecombineResult r = recombine(m, o);
  EXPECT_FALSE(r.warnings.empty());
  for (const auto& b : r.mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) EXPECT_GT(test::shoelace_area(r.mesh, b.element(e)), 0);
}

TEST(RecombineInput, OddCountSplitsTheLongestBoundaryEdge) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    // A grid without its first triangle (a corner): 29 triangles, a simple notched domain.
    Mesh in = test::random_grid_mesh(5, 3, seed, 0, /*make_even=*/false);
    in.blocks[0].tags.erase(in.blocks[0].tags.begin());
    in.blocks[0].nodes.erase(in.blocks[0].nodes.begin(), in.blocks[0].nodes.begin() + 3);
    ASSERT_EQ(in.num_elements() % 2, 1u);
    const RecombineResult r = recombine(in, {});
    SCOPED_TRACE(seed);
    EXPECT_EQ(r.stats.odd_splits, 1u);
    EXPECT_EQ(r.stats.triangles, 0u);
    // Not asserted: invalid_quads. On meshes this small the split can force a non-convex
    // quad (measured: up to 5 of 15 seeds); the leave policy below does not.
    EXPECT_FALSE(r.warnings.empty());
    // One boundary edge is now two: the boundary has one more edge, same total length.
    const auto before = test::boundary_edges(in), after = test::boundary_edges(r.mesh);
    EXPECT_EQ(after.size(), before.size() + 1);
    // The split edge, the one the output lacks, is the longest of those whose two nodes are
    // in 3 or more triangles (make_regions_even's preference).
    std::vector<test::TagEdge> gone;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(gone));
    ASSERT_EQ(gone.size(), 1u);
    std::map<Tag, std::size_t> index, triangles_at;
    for (std::size_t v = 0; v < in.num_nodes(); ++v) index[in.node_tags[v]] = v;
    for (NodeIndex v : in.blocks[0].nodes) ++triangles_at[in.node_tags[v]];
    const auto length = [&](const test::TagEdge& e) {
      const auto a = in.node(static_cast<NodeIndex>(index[e.first])), b = in.node(static_cast<NodeIndex>(index[e.second]));
      return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    };
    double longest = 0;
    for (const test::TagEdge& e : before)
      if (triangles_at[e.first] >= 3 && triangles_at[e.second] >= 3) longest = std::max(longest, length(e));
    EXPECT_EQ(length(gone[0]), longest);
  }
}

TEST(RecombineInput, OddCountLeavePolicyLeavesOneTriangle) {
  Mesh in = test::random_grid_mesh(5, 3, 11, 0, false);
  in.blocks[0].tags.erase(in.blocks[0].tags.begin());
  in.blocks[0].nodes.erase(in.blocks[0].nodes.begin(), in.blocks[0].nodes.begin() + 3);
  RecombineOptions o;
  o.odd_policy = OddPolicy::leave_triangle;
  const RecombineResult r = recombine(in, o);
  EXPECT_FALSE(r.stats.perfect_matching);
  EXPECT_GE(r.stats.triangles, 1u);
  test::expect_valid_recombination(in, r.mesh);
}

}  // namespace
}  // namespace quadval
