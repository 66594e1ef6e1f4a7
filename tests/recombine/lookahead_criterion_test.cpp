// Definition 2 (the recombination criterion of Paper II §3), maintained incrementally by
// LookaheadState, against hand-made meshes and a brute-force oracle (plain component search).
#include <random>

#include <gtest/gtest.h>

#include "recombine/lookahead_state.hpp"
#include "recombine/lookahead_test_support.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

using recombine_detail::LookaheadState;

// The pair of g joining triangles a and b (any order).
std::uint32_t pair_of(const recombine_detail::LookaheadGraph& g, std::uint32_t a, std::uint32_t b) {
  for (std::uint32_t p = 0; p < g.pairs.size(); ++p)
    if ((g.pairs[p].t0 == a && g.pairs[p].t1 == b) || (g.pairs[p].t0 == b && g.pairs[p].t1 == a))
      return p;
  ADD_FAILURE() << "no pair " << a << "-" << b;
  return 0;
}

TEST(LookaheadCriterion, MergeThatIsolatesTrianglesIsRefused) {
  // Two unit cells, dual graph the path T1 - T0 - T3 - T2.
  const Mesh m = test::make_triangle_mesh({{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}},
                                          {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}});
  const auto f = test::make_lookahead_fixture(m);
  LookaheadState s(f.graph);
  EXPECT_FALSE(s.allowed(pair_of(f.graph, 0, 3)));  // leaves {T1} and {T2}
  EXPECT_TRUE(s.allowed(pair_of(f.graph, 0, 1)));   // leaves {T3, T2}
  EXPECT_TRUE(s.allowed(pair_of(f.graph, 3, 2)));
  s.apply(pair_of(f.graph, 0, 1));
  EXPECT_TRUE(s.allowed(pair_of(f.graph, 3, 2)));
  EXPECT_FALSE(s.allowed(pair_of(f.graph, 0, 3)));  // T0 is taken
  s.undo();
  EXPECT_FALSE(s.allowed(pair_of(f.graph, 0, 3)));
}

TEST(LookaheadCriterion, MergeThatLeavesAnOddCavityIsRefused) {
  // A 3 x 3 grid of unit cells, every cell cut by its (i,j)-(i+1,j+1) diagonal: 18 triangles.
  // Cell (i, j) holds lower triangle L = 2(3j + i) and upper triangle U = L + 1.
  std::vector<std::array<double, 2>> xy;
  for (int j = 0; j <= 3; ++j)
    for (int i = 0; i <= 3; ++i) xy.push_back({double(i), double(j)});
  std::vector<std::array<NodeIndex, 3>> tris;
  auto id = [](int i, int j) { return static_cast<NodeIndex>(4 * j + i); };
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  const auto f = test::make_lookahead_fixture(test::make_triangle_mesh(xy, tris));
  LookaheadState s(f.graph);
  auto L = [](int i, int j) { return static_cast<std::uint32_t>(2 * (3 * j + i)); };
  // Quads in the cells (0,0), (1,0) and (0,1), (0,2): the free part is the L-shape of
  // cells (2,0), (1,1), (2,1), (1,2), (2,2) (10 triangles, even).
  for (auto [i, j] : {std::pair{0, 0}, {1, 0}, {0, 1}, {0, 2}}) {
    const std::uint32_t p = pair_of(f.graph, L(i, j), L(i, j) + 1);
    ASSERT_TRUE(s.allowed(p));
    s.apply(p);
  }
  // Merging U(1,1) with L(1,2) above it cuts off U(1,2) (alone: odd) from the rest.
  EXPECT_FALSE(s.allowed(pair_of(f.graph, L(1, 1) + 1, L(1, 2))));
  // Merging U(2,1) with L(2,2) leaves the cavities {L(2,0), U(2,0), L(2,1)} (3: odd) and
  // {L(1,1), U(1,1), L(1,2), U(1,2), U(2,2)} (5: odd): refused.
  EXPECT_FALSE(s.allowed(pair_of(f.graph, L(2, 1) + 1, L(2, 2))));
  // Merging cell (1,1) keeps parity: allowed.
  EXPECT_TRUE(s.allowed(pair_of(f.graph, L(1, 1), L(1, 1) + 1)));
  // All three verdicts agree with the brute force.
  std::vector<char> free(f.graph.num_triangles);
  for (std::uint32_t t = 0; t < free.size(); ++t) free[t] = s.is_free(t);
  EXPECT_FALSE(test::oracle_allowed(f, free, L(1, 1) + 1, L(1, 2)));
  EXPECT_FALSE(test::oracle_allowed(f, free, L(2, 1) + 1, L(2, 2)));
  EXPECT_TRUE(test::oracle_allowed(f, free, L(1, 1), L(1, 1) + 1));
}

// Random walks through the state space of meshes with holes (triangles removed): at every
// state, the incremental verdict equals the brute force for every pair, and undo restores
// the verdicts. Also checks that the walks met refusals that cut off more than one triangle.
TEST(LookaheadCriterion, MatchesBruteForceOnRandomStates) {
  std::size_t refused_isolated = 0, refused_cavity = 0, allowed_cuts = 0, checks = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    const Mesh m = test::random_grid_mesh(3 + seed % 5, 3 + seed % 4, seed, seed % 3 == 0 ? 0 : 3);
    const auto f = test::make_lookahead_fixture(m);
    // The brute force's invariant: start from even components only.
    std::vector<char> all(f.graph.num_triangles, 1);
    bool even = true;
    for (std::size_t n : test::component_sizes(f, all)) even &= n % 2 == 0;
    if (!even) continue;
    LookaheadState s(f.graph);
    std::mt19937 rng(seed);
    for (int step = 0;; ++step) {
      std::vector<char> free(f.graph.num_triangles);
      for (std::uint32_t t = 0; t < free.size(); ++t) free[t] = s.is_free(t);
      std::vector<std::uint32_t> allowed;
      for (std::uint32_t p = 0; p < f.graph.pairs.size(); ++p) {
        const auto& q = f.graph.pairs[p];
        const bool want = test::oracle_allowed(f, free, q.t0, q.t1);
        ASSERT_EQ(s.allowed(p), want) << "seed " << seed << " step " << step << " pair " << p;
        ++checks;
        if (want) allowed.push_back(p);
        if (!free[q.t0] || !free[q.t1]) continue;
        auto rest = free;
        rest[q.t0] = rest[q.t1] = 0;
        const auto sizes = test::component_sizes(f, rest);
        std::size_t odd_max = 0;
        for (std::size_t n : sizes)
          if (n % 2 == 1) odd_max = std::max(odd_max, n);
        if (!want && odd_max == 1) ++refused_isolated;
        if (!want && odd_max >= 3) ++refused_cavity;
        if (want && sizes.size() > test::component_sizes(f, free).size()) ++allowed_cuts;
      }
      if (allowed.empty()) break;
      const std::uint32_t p = allowed[rng() % allowed.size()];
      // apply + undo leaves every verdict as it was (spot check on a few pairs).
      s.apply(p);
      s.undo();
      for (std::uint32_t k = 0; k < 5 && k < f.graph.pairs.size(); ++k) {
        const std::uint32_t q = rng() % f.graph.pairs.size();
        EXPECT_EQ(s.allowed(q), std::find(allowed.begin(), allowed.end(), q) != allowed.end());
      }
      s.apply(p);
    }
  }
  EXPECT_GT(checks, 10000u);
  EXPECT_GT(refused_isolated, 50u);
  EXPECT_GT(refused_cavity, 20u);
  EXPECT_GT(allowed_cuts, 20u);  // merges that split a polder set into even parts
}

}  // namespace
}  // namespace quadval
