// The diagonal swaps of the clean-up: a quad with a flat (or nearly flat) corner at a
// boundary node, which no smoothing can open, is re-split with its neighbour.
#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "quadval/recombine.hpp"
#include "recombine/mixed_mesh.hpp"
#include "recombine/quad_cleanup.hpp"
#include "recombine/quad_mesh_checks.hpp"
#include "recombine/smoothing.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

using recombine_detail::MixedMesh;

// Nodes a, b, c on the straight side y = 0 (b only in triangles t0 and t1), x, e, f above:
// t0 = (a, b, x) has no other neighbour than t1 = (b, c, x), and t3 = (x, e, f) none other than
// t2 = (x, c, e), so the only perfect matching (without extra edges, whose cost is far above)
// pairs t0-t1 and t2-t3: the quad (a, b, c, x) has a flat corner at b.
const std::vector<std::array<double, 2>> kNodes = {{0, 0}, {1, 0}, {2, 0}, {0.8, 1.2}, {2.5, 0.8}, {2, 1.8}};
enum : NodeIndex { A, B, C, X, E, F };

TEST(QuadCleanup, FlatBoundaryCornerIsMendedByADiagonalSwap) {
  const Mesh in = test::make_triangle_mesh(kNodes, {{A, B, X}, {B, C, X}, {X, C, E}, {X, E, F}});
  RecombineOptions no_cleanup;
  no_cleanup.max_cleanup_passes = 0;
  const RecombineResult before = recombine(in, no_cleanup);
  EXPECT_EQ(before.stats.quads, 2u);
  EXPECT_EQ(before.stats.invalid_quads, 1u) << "the flat corner at b";
  EXPECT_EQ(before.stats.eta_min, 0.0);

  const RecombineResult r = recombine(in, {});
  EXPECT_EQ(r.stats.diagonal_swaps, 1u);
  EXPECT_EQ(r.stats.invalid_quads, 0u);
  EXPECT_GT(r.stats.eta_min, 0.3);
  const test::QuadMeshSummary s = test::expect_valid_recombination(in, r.mesh);
  EXPECT_EQ(s.quads, 2u);
  EXPECT_EQ(s.triangles, 0u);
  // The hexagon's other valid split, by hand: along b-f, (b, c, e, f) and (f, x, a, b).
  std::set<std::set<Tag>> quads;
  for (const ElementBlock& b : r.mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) {
      std::set<Tag> q;
      for (NodeIndex v : b.element(e)) q.insert(r.mesh.node_tags[v]);
      quads.insert(q);
    }
  const auto tag = [](NodeIndex v) { return static_cast<Tag>(v + 1); };  // make_triangle_mesh tags
  EXPECT_EQ(quads, (std::set<std::set<Tag>>{{tag(B), tag(C), tag(E), tag(F)}, {tag(F), tag(X), tag(A), tag(B)}}));
}

MixedMesh two_quads(const std::vector<std::array<double, 2>>& xy, const std::array<NodeIndex, 4>& q0,
                    const std::array<NodeIndex, 4>& q1) {
  MixedMesh m;
  for (std::size_t i = 0; i < xy.size(); ++i) m.add_node({xy[i][0], xy[i][1], 0.0}, static_cast<Tag>(i + 1));
  for (const auto& q : {q0, q1}) {
    m.elements.push_back(q);
    m.region.push_back(0);
    m.normal.push_back({0, 0, 1});
    m.alive.push_back(1);
  }
  return m;
}

TEST(QuadCleanup, SwapNeedsASplitWithoutStuckCorners) {
  // Here c's other neighbour d is on the side too: both other splits of the hexagon
  // (a, b, c, d, y, x) keep a flat corner at a fixed node (b or c), so nothing changes.
  const std::vector<std::array<double, 2>> xy = {{0, 0}, {1, 0}, {2, 0}, {1, 1}, {3, 0}, {2.5, 1}};
  enum : NodeIndex { a, b, c, x, d, y };
  MixedMesh m = two_quads(xy, {a, b, c, x}, {x, c, d, y});
  const std::vector<char> fixed = {1, 1, 1, 0, 1, 0};
  const auto elements = m.elements;
  EXPECT_EQ(recombine_detail::element_score(m, 0), 0.0);
  EXPECT_GT(recombine_detail::element_score(m, 1), 0.0);
  EXPECT_EQ(recombine_detail::cleanup_quads(m, fixed, 5).diagonal_swaps, 0u);
  EXPECT_EQ(m.elements, elements);

  // The same two quads with f above the side: swapped, nodes unmoved, outline kept.
  MixedMesh m2 = two_quads(kNodes, {A, B, C, X}, {X, C, E, F});
  const auto coords = m2.coords;
  EXPECT_EQ(recombine_detail::cleanup_quads(m2, {1, 1, 1, 0, 0, 0}, 5).diagonal_swaps, 1u);
  EXPECT_EQ(m2.coords, coords);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_GT(recombine_detail::element_score(m2, e), 0.0) << e;
  std::multiset<std::pair<NodeIndex, NodeIndex>> edges;  // directed, counter-clockwise
  for (const auto& q : m2.elements)
    for (int k = 0; k < 4; ++k) edges.insert({q[k], q[(k + 1) % 4]});
  for (const auto& [from, to] : std::vector<std::pair<NodeIndex, NodeIndex>>{{A, B}, {B, C}, {C, E}, {E, F}, {F, X}, {X, A}})
    EXPECT_EQ(edges.count({from, to}), 1u) << "outline edge " << from << "-" << to;

  // With x lower, the split along b-f is the one without a stuck corner, but (f, x, a, b) is
  // reflex at x: swapped all the same (b's corner cannot open, x's can), and the pipeline's
  // smoothing and polish then open it (x, in one quad only, is smoothed onto the line f-a:
  // the polish's search takes it off).
  std::vector<std::array<double, 2>> low = kNodes;
  low[X] = {1.2, 0.7};
  MixedMesh m4 = two_quads(low, {A, B, C, X}, {X, C, E, F});
  const std::vector<char> fixed4 = {1, 1, 1, 0, 1, 1};
  EXPECT_GT(recombine_detail::element_score(m4, 1), 0.0);
  EXPECT_EQ(recombine_detail::cleanup_quads(m4, fixed4, 5).diagonal_swaps, 1u);
  double worst = 1;
  for (std::size_t e = 0; e < 2; ++e) worst = std::min(worst, recombine_detail::element_score(m4, e));
  EXPECT_LT(worst, 0.0);
  recombine_detail::smooth(m4, fixed4, {});
  recombine_detail::polish_worst(m4, fixed4, {});
  for (std::size_t e = 0; e < 2; ++e) EXPECT_GT(recombine_detail::element_score(m4, e), 0.0) << e;

  // b a little below the line a-c: the quad (a, b, c, x) is valid, but its corner at b, of
  // about 174 degrees, is frozen (a, b, c fixed). The split along a-e keeps that corner;
  // along b-f (by hand, as above) it is cut in two, so that split is taken, and the worst
  // score of the two quads rises. Fixed nodes stay, the outline too.
  std::vector<std::array<double, 2>> bent = kNodes;
  bent[B] = {1, -0.05};
  MixedMesh m5 = two_quads(bent, {A, B, C, X}, {X, C, E, F});
  const std::vector<char> fixed5 = {1, 1, 1, 0, 0, 0};
  const double before5 = std::min(recombine_detail::element_score(m5, 0), recombine_detail::element_score(m5, 1));
  EXPECT_GT(before5, 0.0);
  EXPECT_LT(before5, 0.1);
  const auto coords5 = m5.coords;
  EXPECT_EQ(recombine_detail::cleanup_quads(m5, fixed5, 5).diagonal_swaps, 1u);
  EXPECT_GT(std::min(recombine_detail::element_score(m5, 0), recombine_detail::element_score(m5, 1)), before5);
  for (NodeIndex v : {A, B, C})
    for (int d = 0; d < 3; ++d) EXPECT_EQ(m5.coords[3 * v + d], coords5[3 * v + d]);
  std::set<std::set<NodeIndex>> split5;
  for (const auto& q : m5.elements) split5.insert(std::set<NodeIndex>(q.begin(), q.end()));
  EXPECT_EQ(split5, (std::set<std::set<NodeIndex>>{{B, C, E, F}, {F, X, A, B}}));

  // Valid quads without a frozen corner are never swapped.
  MixedMesh m3 = two_quads(kNodes, {B, C, E, F}, {F, X, A, B});
  const auto valid = m3.elements;
  EXPECT_EQ(recombine_detail::cleanup_quads(m3, {1, 1, 1, 0, 0, 0}, 5).diagonal_swaps, 0u);
  EXPECT_EQ(m3.elements, valid);
}

// A jittered nx x ny grid of quads (boundary nodes fixed, not moved): swap_worst never lowers
// the worst score, keeps every quad valid, the outline and the conformity, and does swap.
TEST(QuadCleanup, SwapWorstRaisesTheWorstQuadAndKeepsTheMeshSound) {
  std::size_t swapped = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    const int n = 12;
    std::vector<std::array<double, 2>> xy;
    std::vector<char> fixed;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const bool boundary = i == 0 || j == 0 || i == n || j == n;
        xy.push_back({i + (boundary ? 0 : u(rng)), j + (boundary ? 0 : u(rng))});
        fixed.push_back(boundary ? 1 : 0);
      }
    MixedMesh m;
    for (std::size_t i = 0; i < xy.size(); ++i) m.add_node({xy[i][0], xy[i][1], 0.0}, static_cast<Tag>(i + 1));
    const auto id = [n](int i, int j) { return static_cast<NodeIndex>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        m.elements.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
        m.region.push_back(0);
        m.normal.push_back({0, 0, 1});
        m.alive.push_back(1);
      }
    const auto worst = [&m] {
      double w = 2;
      for (std::size_t e = 0; e < m.elements.size(); ++e) w = std::min(w, recombine_detail::element_score(m, e));
      return w;
    };
    const auto edges = [&m](bool boundary_only) {
      std::map<std::pair<NodeIndex, NodeIndex>, int> count;  // undirected
      for (const auto& q : m.elements)
        for (int k = 0; k < 4; ++k) ++count[std::minmax(q[k], q[(k + 1) % 4])];
      std::set<std::pair<NodeIndex, NodeIndex>> out;
      for (const auto& [e, c] : count) {
        EXPECT_LE(c, 2) << "edge " << e.first << "-" << e.second;
        if (!boundary_only || c == 1) out.insert(e);
      }
      return out;
    };
    const double before = worst();
    ASSERT_GT(before, 0.0) << seed;
    const auto outline = edges(true);
    const std::size_t swaps = recombine_detail::swap_worst(m, fixed, 0.05, 3);
    swapped += swaps;
    EXPECT_GE(worst(), before) << seed;
    EXPECT_EQ(edges(true), outline) << seed;
    std::set<std::pair<NodeIndex, NodeIndex>> directed;
    for (const auto& q : m.elements)
      for (int k = 0; k < 4; ++k) EXPECT_TRUE(directed.insert({q[k], q[(k + 1) % 4]}).second) << seed;
    for (std::size_t v = 0; v < fixed.size(); ++v) {
      if (!fixed[v]) continue;
      for (int d = 0; d < 2; ++d) EXPECT_EQ(m.coords[3 * v + d], xy[v][d]);
    }
  }
  EXPECT_GT(swapped, 0u);
}

}  // namespace
}  // namespace quadval
