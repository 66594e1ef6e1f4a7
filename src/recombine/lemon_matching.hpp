#pragma once
// Thin wrapper over LEMON's weighted matchings. This header and lemon_matching.cpp are plain
// C++17: LEMON 1.3's ArrayMap calls std::allocator::construct/destroy, which C++20 removed,
// so lemon_matching.cpp is compiled with -std=c++17 (src/recombine/sources.cmake).

#include <cstdint>
#include <vector>

namespace quadval::recombine_detail {

struct WeightedEdge {
  std::uint32_t u, v;
  long long weight;  ///< 64-bit: LEMON's default int overflows silently at large weights
};

/// Maximum-weight perfect matching (LEMON MaxWeightedPerfectMatching, default fractional warm
/// start). Returns false when the graph has no perfect matching; else sets matched[i] for
/// each edge in the matching.
bool lemon_max_weight_perfect_matching(std::uint32_t num_nodes,
                                       const std::vector<WeightedEdge>& edges,
                                       std::vector<char>& matched);

/// Maximum-weight matching, not necessarily perfect (LEMON MaxWeightedMatching).
void lemon_max_weight_matching(std::uint32_t num_nodes, const std::vector<WeightedEdge>& edges,
                               std::vector<char>& matched);

}  // namespace quadval::recombine_detail
