// Optimality of the Blossom matching: against brute-force enumeration of every perfect
// matching with independently computed pair costs (small meshes), and against NetworkX on the
// same graph (mid-size meshes).
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "recombine/dual_graph.hpp"
#include "recombine/matching.hpp"
#include "recombine/test_meshes.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

// --- The oracle: its own adjacency and its own eta (2D polygon angles). ---

struct OraclePair {
  int t0, t1;
  double cost;
};

double oracle_eta_2d(const std::array<std::array<double, 2>, 4>& p) {
  double area = 0;
  for (int k = 0; k < 4; ++k) area += p[k][0] * p[(k + 1) % 4][1] - p[(k + 1) % 4][0] * p[k][1];
  std::array<std::array<double, 2>, 4> q = p;
  if (area < 0) std::swap(q[1], q[3]);  // make it counter-clockwise
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    const double fx = q[(k + 1) % 4][0] - q[k][0], fy = q[(k + 1) % 4][1] - q[k][1];
    const double bx = q[(k + 3) % 4][0] - q[k][0], by = q[(k + 3) % 4][1] - q[k][1];
    // Interior angle of a CCW polygon: from the forward edge to the backward edge, CCW.
    double alpha = std::atan2(fx * by - fy * bx, fx * bx + fy * by);
    if (alpha <= 0) return 0.0;  // reflex (> pi) or flat
    worst = std::max(worst, std::abs(std::numbers::pi / 2 - alpha));
  }
  return std::max(0.0, 1.0 - worst / (std::numbers::pi / 2));
}

std::vector<OraclePair> oracle_pairs(const Mesh& m) {
  const ElementBlock& b = m.blocks[0];
  std::vector<OraclePair> pairs;
  for (std::size_t i = 0; i < b.size(); ++i)
    for (std::size_t j = i + 1; j < b.size(); ++j) {
      const auto ti = b.element(i), tj = b.element(j);
      std::vector<NodeIndex> shared, own_i, own_j;
      for (NodeIndex v : ti)
        (std::find(tj.begin(), tj.end(), v) != tj.end() ? shared : own_i).push_back(v);
      for (NodeIndex v : tj)
        if (std::find(ti.begin(), ti.end(), v) == ti.end()) own_j.push_back(v);
      if (shared.size() != 2) continue;
      // The quad alternates: own_i, shared0, own_j, shared1.
      std::array<std::array<double, 2>, 4> p;
      const NodeIndex order[4] = {own_i[0], shared[0], own_j[0], shared[1]};
      for (int k = 0; k < 4; ++k) p[k] = {m.coords[3 * order[k]], m.coords[3 * order[k] + 1]};
      pairs.push_back({static_cast<int>(i), static_cast<int>(j), 1.0 - oracle_eta_2d(p)});
    }
  return pairs;
}

// Minimum total cost over all perfect matchings (infinity if there is none).
double brute_force_min_cost(int n, const std::vector<OraclePair>& pairs) {
  std::vector<std::vector<std::pair<int, double>>> adj(n);
  for (const auto& p : pairs) {
    adj[p.t0].push_back({p.t1, p.cost});
    adj[p.t1].push_back({p.t0, p.cost});
  }
  std::vector<char> used(n, 0);
  double best = std::numeric_limits<double>::infinity();
  std::function<void(double)> search = [&](double so_far) {
    int first = 0;
    while (first < n && used[first]) ++first;
    if (first == n) {
      best = std::min(best, so_far);
      return;
    }
    used[first] = 1;
    for (const auto& [other, c] : adj[first])
      if (!used[other]) {
        used[other] = 1;
        search(so_far + c);
        used[other] = 0;
      }
    used[first] = 0;
  };
  search(0.0);
  return best;
}

DualGraph graph_of(const TriangleSurface& s, bool extra_edges) {
  DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size()};
  in.extra_edges = extra_edges;
  return build_dual_graph(in);
}

TEST(BlossomOptimality, EqualsBruteForceOnHundredsOfSmallMeshes) {
  int perfect = 0, without = 0;
  for (unsigned seed = 1; seed <= 200; ++seed) {
    const int nx = 2 + static_cast<int>(seed % 2), ny = 2 + static_cast<int>((seed / 2) % 2);
    const Mesh m = test::random_grid_mesh(nx, ny, seed, static_cast<int>(seed % 4));
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(m, "random", warnings);
    ASSERT_LE(s.triangles.size(), 20u);
    const double want = brute_force_min_cost(static_cast<int>(s.triangles.size()), oracle_pairs(m));
    const DualGraph g = graph_of(s, false);
    const Matching got = blossom_matching(g);
    if (std::isinf(want)) {
      EXPECT_FALSE(got.perfect);
      ++without;
      continue;
    }
    ++perfect;
    ASSERT_TRUE(got.perfect);
    EXPECT_NEAR(got.cost, want, 1e-8 * static_cast<double>(s.triangles.size()));
    // With the extra edges (cost 1000) the optimum is the same: they are never needed here.
    const Matching with_extra = blossom_matching(graph_of(s, true));
    ASSERT_TRUE(with_extra.perfect);
    EXPECT_NEAR(with_extra.cost, want, 1e-8 * static_cast<double>(s.triangles.size()));
  }
  // The generator must exercise both cases.
  EXPECT_GT(perfect, 100);
  EXPECT_GT(without, 0);
}

TEST(BlossomOptimality, GreedyNeverBeatsBlossomAndIsMaximal) {
  for (unsigned seed = 1; seed <= 100; ++seed) {
    const Mesh m = test::random_grid_mesh(3, 3, seed);
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(m, "random", warnings);
    const DualGraph g = graph_of(s, false);
    const Matching greedy = greedy_matching(g);
    const Matching best = blossom_matching(g);
    // Maximal: no pair has both triangles free.
    std::vector<char> used(s.triangles.size(), 0);
    for (auto i : greedy.pairs) used[g.pairs[i].t0] = used[g.pairs[i].t1] = 1;
    for (std::size_t i = 0; i < g.num_real; ++i)
      EXPECT_FALSE(!used[g.pairs[i].t0] && !used[g.pairs[i].t1]);
    if (greedy.perfect && best.perfect) {
      EXPECT_LE(best.cost, greedy.cost + 1e-9);
    }
  }
}

TEST(BlossomOptimality, Int64WeightsKeepExtraEdgeCostsExact) {
  // 1000 * 1e9 does not fit in 32 bits: the weight must be 64-bit.
  EXPECT_EQ(matching_weight(1000.0), -1000000000000LL);
  EXPECT_EQ(matching_weight(0.25), -250000000LL);
}

int run_networkx(const DualGraph& g, std::size_t& pairs, long long& cost_nanos) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto in = dir / ("qv_nx_" + std::to_string(::getpid()) + ".txt");
  const auto out = dir / ("qv_nx_" + std::to_string(::getpid()) + ".out");
  {
    std::ofstream f(in);
    f << g.num_triangles << " " << g.pairs.size() << "\n";
    for (const auto& p : g.pairs) f << p.t0 << " " << p.t1 << " " << -matching_weight(p.cost) << "\n";
  }
  const std::string cmd = std::string(QUADVAL_PYTHON) + " " + QUADVAL_SOURCE_DIR +
                          "/tests/recombine/networkx_matching.py " + in.string() + " > " +
                          out.string();
  const int rc = std::system(cmd.c_str());
  std::ifstream r(out);
  r >> pairs >> cost_nanos;
  std::filesystem::remove(in);
  std::filesystem::remove(out);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(BlossomOptimality, EqualsNetworkXOnMidSizeMeshes) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Mesh m = test::random_grid_mesh(10 + static_cast<int>(seed), 9, 1000 + seed,
                                          static_cast<int>(seed) * 3);
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    std::vector<std::string> warnings;
    const TriangleSurface s = prepare_triangles(m, "random", warnings);
    const DualGraph g = graph_of(s, true);
    std::size_t nx_pairs = 0;
    long long nx_cost = -1;
    const int rc = run_networkx(g, nx_pairs, nx_cost);
    if (rc == 3) GTEST_SKIP() << "python3 has no networkx module";
    ASSERT_EQ(rc, 0);
    const Matching got = blossom_matching(g);
    long long got_nanos = 0;
    for (auto i : got.pairs) got_nanos += -matching_weight(g.pairs[i].cost);
    // NetworkX gives a maximum-cardinality matching: perfect exactly when one exists.
    EXPECT_EQ(got.perfect, 2 * nx_pairs == g.num_triangles);
    if (got.perfect) {
      EXPECT_EQ(got_nanos, nx_cost);  // integer weights: exact
    }
  }
}

}  // namespace
}  // namespace quadval
