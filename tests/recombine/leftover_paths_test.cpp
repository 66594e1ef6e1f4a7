// Pairing the triangles a quad-dominant matching leaves (leftover_paths.hpp): the result is a
// matching that keeps every earlier pair's triangles paired; on a bipartite dual graph the
// path search pairs all of them; neighbourhoods that cover a mesh give its optimum, checked
// against brute-force enumeration of every perfect matching.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "recombine/dual_graph.hpp"
#include "recombine/leftover_paths.hpp"
#include "recombine/matching.hpp"
#include "recombine/test_meshes.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

DualGraph graph_of(const TriangleSurface& s) {
  DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size()};
  in.extra_edges = false;
  return build_dual_graph(in);
}

// Per triangle: how many pairs of m hold it.
std::vector<int> cover(const DualGraph& g, const Matching& m) {
  std::vector<int> c(g.num_triangles, 0);
  for (std::uint32_t p : m.pairs) {
    ++c[g.pairs[p].t0];
    ++c[g.pairs[p].t1];
  }
  return c;
}

// A maximal matching taken in a random order of the pairs: it leaves triangles free.
Matching random_maximal(const DualGraph& g, unsigned seed) {
  std::vector<std::uint32_t> order(g.num_real);
  for (std::uint32_t p = 0; p < order.size(); ++p) order[p] = p;
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  std::vector<char> used(g.num_triangles, 0);
  Matching m;
  for (std::uint32_t p : order)
    if (!used[g.pairs[p].t0] && !used[g.pairs[p].t1]) {
      used[g.pairs[p].t0] = used[g.pairs[p].t1] = 1;
      m.pairs.push_back(p);
    }
  std::sort(m.pairs.begin(), m.pairs.end());
  for (std::uint32_t p : m.pairs) m.cost += g.pairs[p].cost;
  m.perfect = 2 * m.pairs.size() == g.num_triangles;
  return m;
}

// What every step must keep: a matching (no triangle twice), each earlier pair's triangles
// still paired, `paired` more triangles paired, and the cost and the flag in step.
void expect_consistent(const DualGraph& g, const Matching& before, const Matching& after, std::size_t paired) {
  const std::vector<int> was = cover(g, before), now = cover(g, after);
  std::size_t more = 0;
  for (std::uint32_t t = 0; t < g.num_triangles; ++t) {
    ASSERT_LE(now[t], 1) << "triangle " << t;
    if (was[t] == 1) {
      EXPECT_EQ(now[t], 1) << "triangle " << t << " lost its pair";
    }
    more += static_cast<std::size_t>(now[t] - was[t]);
  }
  EXPECT_EQ(more, paired);
  EXPECT_TRUE(std::is_sorted(after.pairs.begin(), after.pairs.end()));
  double cost = 0;
  for (std::uint32_t p : after.pairs) cost += g.pairs[p].cost;
  EXPECT_DOUBLE_EQ(after.cost, cost);
  EXPECT_EQ(after.perfect, 2 * after.pairs.size() == g.num_triangles);
}

// A jittered grid whose cells are all cut along the same diagonal: every interior node has
// 6 triangles, so the dual graph is bipartite; pairing each cell's two triangles is a
// perfect matching. From random maximal matchings, the path search alone pairs everything,
// and so do the trees grown together.
TEST(LeftoverPaths, PathsPairEveryTriangleOfABipartiteGraph) {
  const int nx = 14, ny = 9;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  std::vector<std::array<double, 2>> xy;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      xy.push_back({i + (i > 0 && i < nx ? jitter(rng) : 0.0), j + (j > 0 && j < ny ? jitter(rng) : 0.0)});
  std::vector<std::array<NodeIndex, 3>> tris;
  const auto id = [&](int i, int j) { return static_cast<NodeIndex>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  std::vector<std::string> warnings;
  const TriangleSurface s = prepare_triangles(test::make_triangle_mesh(xy, tris), "grid", warnings);
  const DualGraph g = graph_of(s);
  int with_leftovers = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const Matching start = random_maximal(g, seed);
    with_leftovers += !start.perfect;
    Matching m = start;
    const std::size_t paired = pair_along_paths(g, m, std::numeric_limits<std::size_t>::max());
    expect_consistent(g, start, m, paired);
    EXPECT_TRUE(m.perfect);
    // The trees grown together reach a maximum matching too: here, a perfect one.
    Matching t = start;
    expect_consistent(g, start, t, pair_by_trees(g, t, 1000));
    EXPECT_TRUE(t.perfect);
  }
  EXPECT_GT(with_leftovers, 20);  // the starts must leave triangles to pair
}

// Minimum total cost over all perfect matchings, by enumeration (infinity if none).
double brute_force_min_cost(const DualGraph& g) {
  const std::uint32_t n = g.num_triangles;
  std::vector<char> used(n, 0);
  double best = std::numeric_limits<double>::infinity();
  std::function<void(double)> search = [&](double so_far) {
    std::uint32_t first = 0;
    while (first < n && used[first]) ++first;
    if (first == n) {
      best = std::min(best, so_far);
      return;
    }
    used[first] = 1;
    for (std::uint32_t i = g.offsets[first]; i < g.offsets[first + 1]; ++i) {
      const TrianglePair& p = g.pairs[g.incident[i]];
      const std::uint32_t other = p.t0 == first ? p.t1 : p.t0;
      if (p.kind == PairKind::real && !used[other]) {
        used[other] = 1;
        search(so_far + p.cost);
        used[other] = 0;
      }
    }
    used[first] = 0;
  };
  search(0.0);
  return best;
}

// Small connected meshes: a neighbourhood larger than the mesh is the whole mesh, so from
// any start that leaves a triangle free the result is the optimum (or, where no perfect
// matching exists, nothing changes).
TEST(LeftoverPaths, NeighbourhoodsCoveringTheMeshGiveTheOptimum) {
  int optimal = 0, impossible = 0;
  for (unsigned seed = 1; seed <= 150; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const Mesh mesh = test::random_grid_mesh(3, 2 + static_cast<int>(seed % 2), seed, 0);
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(mesh, "random", warnings);
    const DualGraph g = graph_of(s);
    const Matching start = random_maximal(g, seed);
    if (start.perfect) continue;
    Matching m = start;
    const std::size_t paired = pair_in_neighbourhoods(g, m, 1000);
    expect_consistent(g, start, m, paired);
    const double best = brute_force_min_cost(g);
    if (std::isinf(best)) {
      EXPECT_EQ(paired, 0u);
      ++impossible;
      continue;
    }
    ASSERT_TRUE(m.perfect);
    EXPECT_NEAR(m.cost, best, 1e-8 * g.num_triangles);
    ++optimal;
  }
  EXPECT_GT(optimal, 50);
}

// Meshes with holes and odd pieces: whatever stays free, the steps keep a consistent
// matching, and the whole post-process pairs at least what the path search alone does.
TEST(LeftoverPaths, KeepAMatchingOnMeshesWithHoles) {
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const Mesh mesh = test::random_grid_mesh(16, 12, seed, 10 + static_cast<int>(seed % 7), false);
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(mesh, "random", warnings);
    const DualGraph g = graph_of(s);
    const Matching start = random_maximal(g, seed);
    Matching paths = start, trees = start, all = start;
    expect_consistent(g, start, paths, pair_along_paths(g, paths, 256));
    expect_consistent(g, start, trees, pair_by_trees(g, trees, 32));
    expect_consistent(g, start, all, pair_leftovers(g, all));
    EXPECT_GE(all.pairs.size(), paths.pairs.size());
  }
}

}  // namespace
}  // namespace quadval
