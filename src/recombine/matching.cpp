#include "matching.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "blossom_solver.hpp"
#include "lemon_matching.hpp"
#include "quadval/error.hpp"

namespace quadval::recombine_detail {

long long matching_weight(double cost) noexcept { return -std::llround(1e9 * cost); }

namespace {

Matching read_matching(const DualGraph& g, const std::vector<char>& matched) {
  Matching m;
  for (std::uint32_t i = 0; i < g.pairs.size(); ++i)
    if (matched[i]) {
      m.pairs.push_back(i);
      m.cost += g.pairs[i].cost;
    }
  m.perfect = 2 * m.pairs.size() == g.num_triangles;
  return m;
}

}  // namespace

Matching blossom_matching(const DualGraph& g, const MatchingProgress& progress) {
  QV_ASSERT(g.num_triangles < (1u << 30), g.num_triangles << " triangles");
  std::vector<char> matched;
  if (g.num_triangles % 2 == 0) {
    std::vector<CostEdge> costs(g.pairs.size());
    for (std::uint32_t i = 0; i < g.pairs.size(); ++i)
      costs[i] = {g.pairs[i].t0, g.pairs[i].t1, -matching_weight(g.pairs[i].cost)};
    if (min_cost_perfect_matching(g.num_triangles, costs, matched, progress)) {
      Matching m = read_matching(g, matched);
      QV_ASSERT(m.perfect, "a perfect matching with " << m.pairs.size() << " pairs for "
                                                      << g.num_triangles);
      return m;
    }
  }
  std::vector<WeightedEdge> edges(g.pairs.size());
  for (std::uint32_t i = 0; i < g.pairs.size(); ++i)
    edges[i] = {g.pairs[i].t0, g.pairs[i].t1, 0};
  // No perfect matching: every weight positive, so that more pairs weigh more; then quality.
  double max_cost = 0;
  for (const TrianglePair& p : g.pairs) max_cost = std::max(max_cost, p.cost);
  for (std::uint32_t i = 0; i < g.pairs.size(); ++i)
    edges[i].weight = -matching_weight(2 * (1 + max_cost) - g.pairs[i].cost);
  lemon_max_weight_matching(g.num_triangles, edges, matched);
  return read_matching(g, matched);
}

Matching greedy_matching(const DualGraph& g) {
  std::vector<std::uint32_t> order(g.num_real);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return g.pairs[a].cost < g.pairs[b].cost;
  });
  std::vector<char> used(g.num_triangles, 0);
  Matching m;
  for (std::uint32_t i : order) {
    const TrianglePair& p = g.pairs[i];
    if (used[p.t0] || used[p.t1]) continue;
    used[p.t0] = used[p.t1] = 1;
    m.pairs.push_back(i);
    m.cost += p.cost;
  }
  std::sort(m.pairs.begin(), m.pairs.end());
  m.perfect = 2 * m.pairs.size() == g.num_triangles;
  return m;
}

}  // namespace quadval::recombine_detail
