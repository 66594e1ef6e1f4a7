#include "lookahead_matching.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "leftover_paths.hpp"
#include "lookahead_tree.hpp"
#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

// Number of connected sets of triangles (dual components) with an odd count.
std::size_t odd_components(const LookaheadGraph& g) {
  std::vector<char> seen(g.num_triangles, 0);
  std::vector<std::uint32_t> stack;
  std::size_t odd = 0;
  for (std::uint32_t s = 0; s < g.num_triangles; ++s) {
    if (seen[s]) continue;
    std::size_t n = 0;
    stack.assign(1, s);
    seen[s] = 1;
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      ++n;
      for (std::uint32_t u : g.neighbor[t])
        if (u != kNone && !seen[u]) seen[u] = 1, stack.push_back(u);
    }
    odd += n % 2;
  }
  return odd;
}

}  // namespace

Matching lookahead_matching(const DualGraph& graph, const TriangleSurface& s,
                            const RecombineOptions& options, RecombineStats& stats) {
  const LookaheadOptions& o = options.lookahead;
  if (o.horizon < 1 || o.runs < 1)
    throw InputError::in_file(options.source,
                              fmt::format("look-ahead horizon ({}) and runs ({}) must be >= 1",
                                          o.horizon, o.runs));
  const LookaheadGraph g = build_lookahead_graph(graph, s.triangles, s.node_tags.size());
  if (const std::size_t odd = odd_components(g); odd > 0)
    throw InputError::in_file(
        options.source,
        fmt::format("{} connected set(s) of triangles have an odd count; the look-ahead "
                    "criterion (Paper II, Definition 2) needs even ones (use the odd policy "
                    "that splits a boundary edge; a closed odd piece cannot be fixed)",
                    odd));
  const LookaheadBest best = lookahead_best_of(g, o);
  Matching m;
  m.pairs = best.best.pairs;
  std::sort(m.pairs.begin(), m.pairs.end());
  for (std::uint32_t p : m.pairs) m.cost += graph.pairs[p].cost;
  m.perfect = 2 * m.pairs.size() == graph.num_triangles;
  // The post-process of Paper II §6: the leftover triangles paired (leftover_paths.hpp).
  stats.lookahead_path_pairs = pair_leftovers(graph, m);
  stats.lookahead_runs = best.runs;
  stats.lookahead_best_run = best.best_run;
  stats.lookahead_quality = best.best.run.quality;
  stats.lookahead_triangles_left = best.best.run.triangles_left;
  stats.recombined_share =
      g.num_triangles == 0 ? 1.0 : 2.0 * static_cast<double>(m.pairs.size()) / g.num_triangles;
  if (options.compare_with_blossom) {
    const Matching opt = blossom_matching(graph);
    stats.blossom_quality = 0.0;
    for (std::uint32_t p : opt.pairs) stats.blossom_quality += 1.0 - graph.pairs[p].cost;
    stats.quality_percent_of_blossom =
        stats.blossom_quality > 0 ? 100.0 * stats.lookahead_quality / stats.blossom_quality : 0.0;
  }
  return m;
}

}  // namespace quadval::recombine_detail
