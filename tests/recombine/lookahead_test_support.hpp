#pragma once
// Shared by the look-ahead tests: the graph of a test mesh, and oracles that do not use the
// code under test (components of the free triangles by a plain search over shared edges).

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "quadval/mesh.hpp"
#include "recombine/dual_graph.hpp"
#include "recombine/lookahead_state.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval::test {

struct LookaheadFixture {
  recombine_detail::TriangleSurface surface;
  recombine_detail::LookaheadGraph graph;
  /// Triangles sharing an edge (by node pairs, computed here): the oracle's adjacency.
  std::vector<std::vector<std::uint32_t>> adjacent;
};

inline LookaheadFixture make_lookahead_fixture(const Mesh& mesh) {
  using namespace recombine_detail;
  LookaheadFixture f;
  std::vector<std::string> warnings;
  f.surface = prepare_triangles(mesh, "test", warnings);
  const auto& s = f.surface;
  DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size(),
                    PairCostKind::angle, nullptr, 0.0, false, 1000.0};
  f.graph = build_lookahead_graph(build_dual_graph(in), s.triangles, s.node_tags.size());
  std::map<std::pair<NodeIndex, NodeIndex>, std::vector<std::uint32_t>> by_edge;
  for (std::uint32_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      NodeIndex a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      by_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  f.adjacent.resize(s.triangles.size());
  for (const auto& [edge, ts] : by_edge)
    if (ts.size() == 2) {
      f.adjacent[ts[0]].push_back(ts[1]);
      f.adjacent[ts[1]].push_back(ts[0]);
    }
  return f;
}

/// Sizes of the connected components of the triangles with free[t] set.
inline std::vector<std::size_t> component_sizes(const LookaheadFixture& f,
                                                const std::vector<char>& free) {
  std::vector<char> seen(free.size(), 0);
  std::vector<std::size_t> sizes;
  for (std::uint32_t s = 0; s < free.size(); ++s) {
    if (!free[s] || seen[s]) continue;
    std::vector<std::uint32_t> stack{s};
    seen[s] = 1;
    std::size_t n = 0;
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      ++n;
      for (std::uint32_t u : f.adjacent[t])
        if (free[u] && !seen[u]) {
          seen[u] = 1;
          stack.push_back(u);
        }
    }
    sizes.push_back(n);
  }
  return sizes;
}

/// Definition 2 by brute force: t0 and t1 free and adjacent, and no component of the free
/// triangles without them is odd (all components are even before, by the invariant).
inline bool oracle_allowed(const LookaheadFixture& f, std::vector<char> free, std::uint32_t t0,
                           std::uint32_t t1) {
  if (!free[t0] || !free[t1]) return false;
  if (std::find(f.adjacent[t0].begin(), f.adjacent[t0].end(), t1) == f.adjacent[t0].end())
    return false;
  free[t0] = free[t1] = 0;
  for (std::size_t n : component_sizes(f, free))
    if (n % 2 == 1) return false;
  return true;
}

}  // namespace quadval::test
