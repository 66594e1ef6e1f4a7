// The Blossom V-style min-cost perfect matching against two independent oracles: brute-force
// enumeration of every perfect matching (tiny graphs) and LEMON's MaxWeightedPerfectMatching
// (thousands of random graphs, dense and sparse, few and many distinct costs, plus mesh-like
// graphs of degree <= 3 with nearly equal costs, the case the solver exists for).
#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>
#include <omp.h>

#include "quadval/io.hpp"
#include "recombine/blossom_solver.hpp"
#include "recombine/dual_graph.hpp"
#include "recombine/lemon_matching.hpp"
#include "recombine/matching.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

struct Graph {
  std::uint32_t n = 0;
  std::vector<CostEdge> edges;
};

// Checks that `matched` is a perfect matching of g and returns its cost.
std::int64_t perfect_cost(const Graph& g, const std::vector<char>& matched) {
  EXPECT_EQ(matched.size(), g.edges.size());
  std::vector<int> times(g.n, 0);
  std::int64_t total = 0;
  for (std::size_t e = 0; e < g.edges.size(); ++e) {
    if (!matched[e]) continue;
    ++times[g.edges[e].u];
    ++times[g.edges[e].v];
    total += g.edges[e].cost;
  }
  for (std::uint32_t v = 0; v < g.n; ++v) EXPECT_EQ(times[v], 1) << "vertex " << v;
  return total;
}

// Brute force: the lowest vertex is matched by each of its edges in turn.
std::int64_t brute_force_min(const Graph& g, bool& exists) {
  constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();
  std::vector<char> used(g.n, 0);
  std::function<std::int64_t()> best = [&]() -> std::int64_t {
    std::uint32_t v = 0;
    while (v < g.n && used[v]) ++v;
    if (v == g.n) return 0;
    std::int64_t result = kNone;
    used[v] = 1;
    for (const CostEdge& e : g.edges) {
      if (e.u != v && e.v != v) continue;
      const std::uint32_t w = e.u == v ? e.v : e.u;
      if (used[w]) continue;
      used[w] = 1;
      const std::int64_t rest = best();
      if (rest != kNone) result = std::min(result, rest + e.cost);
      used[w] = 0;
    }
    used[v] = 0;
    return result;
  };
  const std::int64_t r = best();
  exists = r != kNone;
  return r;
}

std::int64_t lemon_min(const Graph& g, bool& exists) {
  std::vector<WeightedEdge> w;
  for (const CostEdge& e : g.edges) w.push_back({e.u, e.v, -e.cost});
  std::vector<char> matched;
  exists = lemon_max_weight_perfect_matching(g.n, w, matched);
  if (!exists) return 0;
  std::int64_t total = 0;
  for (std::size_t e = 0; e < g.edges.size(); ++e)
    if (matched[e]) total += g.edges[e].cost;
  return total;
}

Graph random_graph(std::mt19937& rng, std::uint32_t n, double density, std::int64_t max_cost,
                   bool parallel_edges) {
  Graph g;
  g.n = n;
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  std::uniform_int_distribution<std::int64_t> cost(-max_cost, max_cost);
  for (std::uint32_t u = 0; u < n; ++u)
    for (std::uint32_t v = u + 1; v < n; ++v) {
      if (coin(rng) >= density) continue;
      // Random orientation: the solver must not rely on u < v.
      if (rng() & 1)
        g.edges.push_back({u, v, cost(rng)});
      else
        g.edges.push_back({v, u, cost(rng)});
      if (parallel_edges && coin(rng) < 0.2) g.edges.push_back({u, v, cost(rng)});
    }
  std::shuffle(g.edges.begin(), g.edges.end(), rng);
  return g;
}

TEST(BlossomSolver, EqualsBruteForceOnTinyGraphs) {
  std::mt19937 rng(7);
  int with_matching = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    const std::uint32_t n = 2 * (1 + trial % 5);  // 2 .. 10 vertices
    const double density = 0.3 + 0.7 * (trial % 7) / 6.0;
    const std::int64_t max_cost = trial % 3 == 0 ? 2 : 1000;  // many ties, or few
    const Graph g = random_graph(rng, n, density, max_cost, trial % 4 == 0);
    bool exists = false;
    const std::int64_t want = brute_force_min(g, exists);
    std::vector<char> matched;
    const bool got = min_cost_perfect_matching(g.n, g.edges, matched);
    ASSERT_EQ(got, exists) << "trial " << trial;
    if (!exists) continue;
    ++with_matching;
    EXPECT_EQ(perfect_cost(g, matched), want) << "trial " << trial;
  }
  EXPECT_GT(with_matching, 800);
}

TEST(BlossomSolver, EqualsLemonOnRandomGraphs) {
  std::mt19937 rng(11);
  int with_matching = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::uint32_t n = 2 * (6 + trial % 30);  // 12 .. 70 vertices
    const double density = trial % 2 ? 0.5 : 3.5 / n;  // dense or sparse
    const std::int64_t max_cost = trial % 3 == 0 ? 3 : trial % 3 == 1 ? 1000 : 1'000'000'000'000;
    const Graph g = random_graph(rng, n, density, max_cost, trial % 5 == 0);
    bool exists = false;
    const std::int64_t want = lemon_min(g, exists);
    std::vector<char> matched;
    ASSERT_EQ(min_cost_perfect_matching(g.n, g.edges, matched), exists) << "trial " << trial;
    if (!exists) continue;
    ++with_matching;
    EXPECT_EQ(perfect_cost(g, matched), want) << "trial " << trial;
  }
  EXPECT_GT(with_matching, 1500);
}

// A triangulated strip folded into a lattice: the dual graph of a k x k grid of squares cut
// along random diagonals (degree <= 3), with costs near one value (Frontal-Delaunay-like)
// plus a few "extra edges" of cost 1e12 between boundary triangles.
Graph mesh_like_graph(std::mt19937& rng, int k, std::int64_t spread) {
  Graph g;
  g.n = 2 * k * k;
  std::uniform_int_distribution<std::int64_t> cost(500'000'000 - spread, 500'000'000 + spread);
  // Triangle 2c is below/left of the diagonal of cell c, 2c+1 above/right; cells share sides.
  std::vector<char> diag(k * k);
  for (auto& d : diag) d = rng() & 1;
  auto tri = [&](int i, int j, int side) {
    // side: 0 bottom, 1 right, 2 top, 3 left -> which triangle of cell (i, j) holds it.
    const int c = j * k + i;
    const bool d = diag[c];  // d: diagonal from bottom-left to top-right
    const int lower = d ? (side == 0 || side == 1) : (side == 0 || side == 3);
    return static_cast<std::uint32_t>(2 * c + (lower ? 0 : 1));
  };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const int c = j * k + i;
      g.edges.push_back({static_cast<std::uint32_t>(2 * c), static_cast<std::uint32_t>(2 * c + 1),
                         cost(rng)});
      if (i + 1 < k) g.edges.push_back({tri(i, j, 1), tri(i + 1, j, 3), cost(rng)});
      if (j + 1 < k) g.edges.push_back({tri(i, j, 2), tri(i, j + 1, 0), cost(rng)});
    }
  for (int i = 0; i + 1 < k; ++i)
    if (rng() % 4 == 0) g.edges.push_back({tri(i, 0, 0), tri(i + 1, 0, 0), 1'000'000'000'000});
  return g;
}

TEST(BlossomSolver, EqualsLemonOnMeshLikeGraphs) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 60; ++trial) {
    const int k = 4 + trial % 37;  // up to 3,200 vertices
    const std::int64_t spread = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 1000 : 300'000'000;
    const Graph g = mesh_like_graph(rng, k, spread);
    bool exists = false;
    const std::int64_t want = lemon_min(g, exists);
    ASSERT_TRUE(exists);
    std::vector<char> matched;
    ASSERT_TRUE(min_cost_perfect_matching(g.n, g.edges, matched)) << "trial " << trial;
    EXPECT_EQ(perfect_cost(g, matched), want) << "trial " << trial;
  }
}

// The dual graphs of Gmsh's Frontal-Delaunay meshes (uniform and graded), with the integer
// costs blossom_matching uses: giant nested blossoms form here, which small graphs never make.
TEST(BlossomSolver, EqualsLemonOnGmshMeshDualGraphs) {
  for (const char* name : {"uniform-10k-a6.msh", "rect-sin-a8.msh", "rect-sin-a6.msh"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_mesh(std::string(QUADVAL_SHARED_DIR) + "/data/tri/" + name);
    std::vector<std::string> warnings;
    const auto s = prepare_triangles(mesh, name, warnings);
    const DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size()};
    const DualGraph dual = build_dual_graph(in);
    Graph g;
    g.n = dual.num_triangles;
    for (const TrianglePair& p : dual.pairs)
      g.edges.push_back({p.t0, p.t1, -matching_weight(p.cost)});
    bool exists = false;
    const std::int64_t want = lemon_min(g, exists);
    ASSERT_TRUE(exists);
    std::vector<char> matched;
    ASSERT_TRUE(min_cost_perfect_matching(g.n, g.edges, matched));
    EXPECT_EQ(perfect_cost(g, matched), want);
  }
}

// Big lattices with nearly equal costs: blossom ids and vertex groups get recycled many times.
TEST(BlossomSolver, EqualsLemonOnLargeMeshLikeGraphs) {
  std::mt19937 rng(3);
  for (const std::int64_t spread : {1'000'000, 30'000'000}) {
    const Graph g = mesh_like_graph(rng, 130, spread);
    bool exists = false;
    const std::int64_t want = lemon_min(g, exists);
    ASSERT_TRUE(exists);
    std::vector<char> matched;
    ASSERT_TRUE(min_cost_perfect_matching(g.n, g.edges, matched));
    EXPECT_EQ(perfect_cost(g, matched), want) << "spread " << spread;
  }
}

// Progress: (0, F) after the greedy start, then +2 per augmentation, ending at (F, F).
TEST(BlossomSolver, ProgressCountsThePairsUpToTheStartsFreeVertices) {
  std::mt19937 rng(5);
  const Graph g = mesh_like_graph(rng, 60, 1'000'000);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> calls;
  std::vector<char> matched;
  ASSERT_TRUE(min_cost_perfect_matching(
      g.n, g.edges, matched,
      [&](std::uint32_t paired, std::uint32_t free) { calls.emplace_back(paired, free); }));
  ASSERT_GE(calls.size(), 2u);
  const std::uint32_t free = calls.front().second;
  EXPECT_EQ(calls.front().first, 0u);
  EXPECT_GT(free, 0u);
  EXPECT_LE(free, g.n);
  EXPECT_EQ(free % 2, 0u);
  EXPECT_EQ(calls.size(), free / 2 + 1);
  for (std::size_t i = 1; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].first, calls[i - 1].first + 2) << "call " << i;
    EXPECT_EQ(calls[i].second, free);
  }
  EXPECT_EQ(calls.back().first, free);
}

// Disjoint copies of mesh-like graphs of different sizes, their vertex ids interleaved at
// random, so that the solver splits the graph into components (chunks of >= 4,096 vertices,
// solved on their own and on the threads there are; small ones grouped).
Graph disjoint_union(std::mt19937& rng, const std::vector<int>& sizes, std::int64_t spread) {
  Graph g;
  std::vector<Graph> parts;
  for (int k : sizes) {
    parts.push_back(mesh_like_graph(rng, k, spread));
    g.n += parts.back().n;
  }
  std::vector<std::uint32_t> id(g.n);
  for (std::uint32_t i = 0; i < g.n; ++i) id[i] = i;
  std::shuffle(id.begin(), id.end(), rng);
  std::uint32_t base = 0;
  for (const Graph& p : parts) {
    for (const CostEdge& e : p.edges) g.edges.push_back({id[base + e.u], id[base + e.v], e.cost});
    base += p.n;
  }
  std::shuffle(g.edges.begin(), g.edges.end(), rng);
  return g;
}

TEST(BlossomSolver, SolvesDisjointComponentsOnTheirOwnOnAnyThreads) {
  std::mt19937 rng(13);
  // 2 * 48^2 = 4,608 and 2 * 60^2 = 7,200 vertices: chunks of their own; the small ones are
  // grouped with their neighbours in the order of their lowest vertex.
  const Graph g = disjoint_union(rng, {48, 60, 5, 3, 48, 7}, 1'000'000);
  bool exists = false;
  const std::int64_t want = lemon_min(g, exists);
  ASSERT_TRUE(exists);
  std::vector<char> one, two;
  omp_set_num_threads(1);
  ASSERT_TRUE(min_cost_perfect_matching(g.n, g.edges, one));
  omp_set_num_threads(2);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> calls;
  ASSERT_TRUE(min_cost_perfect_matching(
      g.n, g.edges, two, [&](std::uint32_t paired, std::uint32_t free) { calls.emplace_back(paired, free); }));
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_EQ(perfect_cost(g, one), want);
  EXPECT_EQ(one, two);  // the same matching whatever the threads
  // The progress contract over all chunks: (0, F) first, then +2 per augmentation up to F.
  ASSERT_GE(calls.size(), 2u);
  const std::uint32_t free = calls.front().second;
  EXPECT_EQ(calls.front().first, 0u);
  EXPECT_EQ(calls.size(), free / 2 + 1);
  for (std::size_t i = 1; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].first, calls[i - 1].first + 2) << "call " << i;
    EXPECT_EQ(calls[i].second, free);
  }
  // An odd component among even ones: no perfect matching.
  Graph odd = g;
  const std::uint32_t extra = odd.n++;
  odd.edges.push_back({extra, extra + 1, 5});
  ++odd.n;
  const std::uint32_t lone = odd.n++;  // joined to nothing but one vertex of the pair above
  odd.edges.push_back({extra, lone, 5});
  EXPECT_FALSE(min_cost_perfect_matching(odd.n, odd.edges, one));
}

TEST(BlossomSolver, ReportsGraphsWithoutPerfectMatching) {
  std::vector<char> matched;
  // Odd vertex count; an isolated vertex; a star K(1,3) plus an edge.
  EXPECT_FALSE(min_cost_perfect_matching(3, std::vector<CostEdge>{{0, 1, 1}, {1, 2, 1}}, matched));
  EXPECT_FALSE(min_cost_perfect_matching(4, std::vector<CostEdge>{{0, 1, 1}, {1, 2, 1}}, matched));
  EXPECT_FALSE(min_cost_perfect_matching(
      6, std::vector<CostEdge>{{0, 1, 1}, {0, 2, 1}, {0, 3, 1}, {4, 5, 1}}, matched));
  // Two triangles joined by one edge: perfect only through that edge.
  const std::vector<CostEdge> bowtie{{0, 1, 5}, {1, 2, 5}, {2, 0, 5}, {3, 4, 1}, {4, 5, 1},
                                     {5, 3, 1}, {2, 3, 100}};
  ASSERT_TRUE(min_cost_perfect_matching(6, bowtie, matched));
  EXPECT_EQ(matched[6], 1);
  EXPECT_TRUE(min_cost_perfect_matching(0, std::vector<CostEdge>{}, matched));
}

}  // namespace
}  // namespace quadval
