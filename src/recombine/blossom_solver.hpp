#pragma once
// Minimum-cost perfect matching by Edmonds' blossom algorithm, organised as in Blossom V
// (Kolmogorov 2009, "Blossom V: a new implementation of a minimum cost perfect matching
// algorithm"): a greedy initialisation of the duals and the matching, then alternating trees
// from all free vertices growing together, the dual change applied lazily (one running offset)
// and the events (grow, shrink, augment, expand) taken from priority queues. Exact: integer
// costs, doubled inside so that every dual stays an integer.
//
// Measured against LEMON's MaxWeightedPerfectMatching (kept as the test oracle, and for the
// non-perfect fallback): equal optimum everywhere tested; about as fast (102k uniform
// Frontal-Delaunay triangles: 8.8 s vs 8.1 s CPU; 35k graded: 0.17 vs 0.27 s end to end).
// Both grow faster than linearly on large meshes (graded square with a hole: 35k triangles
// 0.17 s, 100k 1.5 s, 300k 7 s, 1M 86 s), worst on uniform Frontal-Delaunay meshes, whose
// triangles are nearly all equilateral (141,430 of 152,742 pairs of uniform-100k cost exactly
// 1/3). Measured cause (event counts): the dual graph there is a honeycomb, bipartite, so the
// free vertices a region has in excess can only pair through its defects; one tree then
// covers whole regions of tight edges, and every augmentation dissolves it and has its
// neighbours absorb it again (uniform-100k: 2,119 augmentations, 9.4M grow events, trees of
// ~100k nodes). Breaking the ties by perturbing the costs does not change that (measured), nor
// growing one tree at a time (3x slower). An algorithm that augments along many paths per
// dual adjustment (cost scaling, or phases as in Hopcroft-Karp) would be the remedy.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace quadval::recombine_detail {

struct CostEdge {
  std::uint32_t u, v;  ///< u != v, both < num_nodes; parallel edges are allowed
  std::int64_t cost;   ///< |cost| <= kMaxMatchingCost
};

/// Bound on |cost|: leaves int64 headroom (2^16) over the doubled costs for the duals, their
/// per-tree offsets and the event keys, which are sums of a few such values.
inline constexpr std::int64_t kMaxMatchingCost = std::int64_t{1} << 46;

/// Called after the greedy start and after each augmentation with (vertices paired since the
/// start, vertices the start left free): the second stays fixed, the first rises by 2 to it.
using MatchingProgress = std::function<void(std::uint32_t paired, std::uint32_t free_at_start)>;

/// Minimum-cost perfect matching of the graph (num_nodes, edges).
/// @param[out] matched  #edges flags, 1 for the edges of the matching (resized here)
/// @param progress      optional (see MatchingProgress)
/// @return false when the graph has no perfect matching (`matched` is then unspecified)
/// @pre every edge has u != v, u, v < num_nodes, |cost| <= kMaxMatchingCost (QV_ASSERT)
bool min_cost_perfect_matching(std::uint32_t num_nodes, std::span<const CostEdge> edges,
                               std::vector<char>& matched,
                               const MatchingProgress& progress = {});

}  // namespace quadval::recombine_detail
