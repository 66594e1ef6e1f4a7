#pragma once
// Matchings of the dual graph: optimal (our Blossom V-style solver, blossom_solver.hpp) and
// greedy.

#include <cstdint>
#include <vector>

#include "blossom_solver.hpp"
#include "dual_graph.hpp"

namespace quadval::recombine_detail {

inline constexpr std::uint32_t kUnmatched = 0xffffffffu;

struct Matching {
  std::vector<std::uint32_t> pairs;  ///< indices into DualGraph::pairs, ascending
  bool perfect = false;              ///< every triangle is in a pair
  double cost = 0.0;                 ///< sum of the pair costs
};

/// Cost -> integer weight: w = -round(1e9 * cost), in 64-bit integers (LEMON's default int
/// weights overflow silently at the extra-edge cost and give a wrong "perfect" matching).
long long matching_weight(double cost) noexcept;

/// Minimum-cost perfect matching (Paper I §4, eq. 4) of the integer costs -matching_weight
/// by min_cost_perfect_matching (exact on those integers). If no perfect matching exists,
/// falls back to LEMON's MaxWeightedMatching with weights 2 (1 + max cost) - cost, which
/// leaves some triangles unmatched (perfect = false; the number left is small but not proven
/// minimal). Costs are optimal to within 1e-9 per pair (the weight rounding).
/// `progress` is passed to min_cost_perfect_matching.
Matching blossom_matching(const DualGraph& g, const MatchingProgress& progress = {});

/// Greedy matching of Paper I §3: pairs by increasing cost (ties: lower pair index), taken
/// when both triangles are still free. Extra pairs are never used.
Matching greedy_matching(const DualGraph& g);

}  // namespace quadval::recombine_detail
