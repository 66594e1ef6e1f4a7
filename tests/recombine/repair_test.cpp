// Meshes whose only perfect matchings use an extra edge (Paper I §5.3), in the configurations
// of Fig. 8 (edge swap) and Fig. 9 (vertex duplication).
#include <cmath>
#include <numbers>
#include <set>

#include <gtest/gtest.h>

#include "quadval/recombine.hpp"
#include "recombine/quad_mesh_checks.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

// Fig. 8: t2 = (v, p, q) has three neighbours t1 = (v, a, p), t3 = (v, q, b) and
// t4 = (p, r, q), which have no other neighbour. t2 can take only one of them: without extra
// edges there is no perfect matching (Tutte: removing t2 leaves three odd components).
Mesh fig8_star() {
  return test::make_triangle_mesh(
      {{0, 0}, {1, 0}, {-1, 0}, {0.5, 0.8}, {-0.5, 0.8}, {0, 1.2}},  // v a b p q r
      {{0, 1, 3}, {0, 3, 4}, {0, 4, 2}, {3, 5, 4}});
}

TEST(RecombineRepair, Fig8EdgeSwapGivesTwoConvexQuads) {
  const Mesh in = fig8_star();
  RecombineOptions no_extra;
  no_extra.extra_edges = false;
  no_extra.optimize = false;
  const RecombineResult without = recombine(in, no_extra);
  EXPECT_FALSE(without.stats.perfect_matching);
  EXPECT_GT(without.stats.triangles, 0u);

  RecombineOptions o;
  o.optimize = false;
  const RecombineResult r = recombine(in, o);
  EXPECT_TRUE(r.stats.perfect_matching);
  EXPECT_EQ(r.stats.matched_extra_pairs, 1u);
  EXPECT_EQ(r.stats.edge_swaps, 1u);
  EXPECT_EQ(r.stats.vertex_duplications, 0u);
  // The extra pair, plus the kite (v, p, r, q) whose worst corner is v, at 2 atan(0.5 / 0.8):
  // cost (2/pi)(pi/2 - 2 atan(0.625)) = 1 - (4/pi) atan(0.625).
  EXPECT_NEAR(r.stats.matching_cost, 1000.0 + 1.0 - 4.0 / std::numbers::pi * std::atan(0.625), 1e-9);
  const auto s = test::expect_valid_recombination(in, r.mesh);
  EXPECT_EQ(s.quads, 2u);
  EXPECT_EQ(s.triangles, 0u);
  EXPECT_EQ(r.mesh.num_nodes(), 6u);  // no node added
  EXPECT_EQ(r.stats.invalid_quads, 0u);
  // The swapped diagonal is v-r: quads (v, a, p, r) and (v, r, q, b) by node tags.
  std::set<std::set<Tag>> quads;
  for (const auto& b : r.mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) {
      std::set<Tag> q;
      for (NodeIndex n : b.element(e)) q.insert(r.mesh.node_tags[n]);
      quads.insert(q);
    }
  EXPECT_EQ(quads, (std::set<std::set<Tag>>{{1, 2, 4, 6}, {1, 6, 5, 3}}));
}

// Fig. 9: boundary node v at the origin with the fan a (0 deg), p1 (20), p2 (90), p3 (160),
// b (180): t1 = (v, a, p1), m1 = (v, p1, p2), m2 = (v, p2, p3), t3 = (v, p3, b), and the
// parallelogram caps x1 = (p2, p1, s1), x2 = (p3, p2, s2). No perfect matching of the real
// pairs exists (m1 and m2 each have two leaves). The two cheapest perfect matchings with one
// extra edge are {t1-t3 at v, m1-x1, m2-x2} (quads with angles 70/110: cost 2 * 2/9) and
// {x1-x2 at p2, t1-m1, m2-t3} (quads with a 135-degree corner: cost 2 * 1/2). The first wins,
// and between t1 and t3 lie two quads: vertex duplication.
Mesh fig9_fan() {
  auto polar = [](double degrees) {
    const double a = degrees * std::numbers::pi / 180;
    return std::array<double, 2>{std::cos(a), std::sin(a)};
  };
  const auto p1 = polar(20), p2 = polar(90), p3 = polar(160);
  const std::array<double, 2> s1{p1[0] + p2[0], p1[1] + p2[1]}, s2{p2[0] + p3[0], p2[1] + p3[1]};
  return test::make_triangle_mesh(
      {{0, 0}, {1, 0}, p1, p2, p3, {-1, 0}, s1, s2},  // v a p1 p2 p3 b s1 s2
      {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {3, 2, 6}, {4, 3, 7}});
}

TEST(RecombineRepair, Fig9VertexDuplicationGivesFourValidQuads) {
  const Mesh in = fig9_fan();
  RecombineOptions o;
  o.optimize = false;
  const RecombineResult r = recombine(in, o);
  EXPECT_TRUE(r.stats.perfect_matching);
  EXPECT_EQ(r.stats.matched_extra_pairs, 1u);
  EXPECT_EQ(r.stats.vertex_duplications, 1u);
  EXPECT_EQ(r.stats.edge_swaps, 0u);
  // 1000 for the extra pair + two parallelograms of angle 70 degrees: 2 * (20/90).
  EXPECT_NEAR(r.stats.matching_cost, 1000.0 + 2.0 * 20.0 / 90.0, 1e-9);
  const auto s = test::expect_valid_recombination(in, r.mesh);
  EXPECT_EQ(s.quads, 4u);  // 6 triangles -> 3 pairs -> 3 quads + 1 from the duplication
  EXPECT_EQ(s.triangles, 0u);
  EXPECT_EQ(r.mesh.num_nodes(), 9u);  // one new node
  EXPECT_EQ(r.stats.invalid_quads, 0u);
  // The new node is inside the fan: above the x axis, below the arc through p1..p3.
  bool found = false;
  for (std::size_t i = 0; i < r.mesh.num_nodes(); ++i)
    if (r.mesh.node_tags[i] == 9) {
      const auto p = r.mesh.node(static_cast<NodeIndex>(i));
      EXPECT_GT(p[1], 0.0);
      EXPECT_LT(std::hypot(p[0], p[1]), 1.0);
      found = true;
    }
  EXPECT_TRUE(found);
  // Optimisation keeps it all-quad and valid.
  const RecombineResult opt = recombine(in, {});
  test::expect_valid_recombination(in, opt.mesh);
  EXPECT_EQ(opt.stats.triangles, 0u);
  EXPECT_EQ(opt.stats.invalid_quads, 0u);
}

}  // namespace
}  // namespace quadval
