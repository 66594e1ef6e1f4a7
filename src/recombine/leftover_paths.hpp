#pragma once
// Pairs the triangles a quad-dominant matching leaves (the look-ahead tree's, Paper II §6):
// the matching-level form of the post-process that Paper II names (Bunin's). Each step swaps
// augmenting paths: from a free triangle t0, a path t0 - t1 = t2 - t3 = ... - tk to another
// free triangle tk alternates pairs not in the matching and pairs in it; swapping them
// re-pairs the triangles along it, so both ends are paired and no other triangle is
// unpaired. In turn:
// 1. from each free triangle, the cheapest path that a best-first search finds (the cost of
//    the pairs gained minus that of the pairs given up) within 256 triangles;
// 2. for those still free, an exact re-pairing of their neighbourhoods (within 4, then 16
//    pairs): each connected piece gets the minimum-cost perfect matching of its real pairs
//    (blossom_solver.hpp) where one exists; this also passes odd cycles of pairs, where an
//    alternating search cannot;
// 3. for partners far apart, alternating trees grown from all free triangles at once, a
//    sweep of the graph per round: the shortest paths where the trees meet (fewest pairs,
//    not the cheapest);
// 4. step 2 again within 64 pairs, for the odd cycles step 3 cannot pass.
// Measured (`quadval recombine --algo lookahead`: triangles left before -> after, eta_min,
// the look-ahead stage's time): uniform-100k-a6 408 -> 0, 0.481 -> 0.499, about 0.3 ->
// 0.42 s (Blossom: 5.8 s, eta_min 0.553, cost 16,937 against 17,001 here);
// square-hole-100k 364 -> 0, 0.501 -> 0.502; square-hole-1000k 3,238 -> 0, 0.506 -> 0.475,
// 3.2 -> 3.8 s; disk-20k-a5 52 -> 0; disk-50k-a5 76 -> 0, 0.436 -> 0.490; box-12k-a6
// 132 -> 0, 0.538 -> 0.555.

#include <cstddef>

#include "dual_graph.hpp"
#include "matching.hpp"

namespace quadval::recombine_detail {

/// Pairs free triangles of `m` (a matching of `g`'s real pairs) by steps 1-4 above (step 3:
/// at most 32 rounds, while one pairs). Every triangle paired before stays paired; m.pairs
/// (kept ascending), m.cost and m.perfect are updated. Returns the number of triangles paired.
std::size_t pair_leftovers(const DualGraph& g, Matching& m);

/// Step 1 alone: a search from each free triangle in increasing index, stopping after
/// `max_visits` triangles. It labels each triangle once (an alternating tree), so on a dual
/// graph with odd cycles it can miss a path that exists; on a bipartite one (all interior
/// nodes of even degree) it misses none within its reach.
std::size_t pair_along_paths(const DualGraph& g, Matching& m, std::size_t max_visits);

/// Step 2 alone, with the neighbourhoods within `radius` pairs of the free triangles. A
/// piece that holds a whole connected set of triangles gets that set's optimum.
std::size_t pair_in_neighbourhoods(const DualGraph& g, Matching& m, int radius);

/// Step 3 alone, at most `max_rounds` rounds. A round that pairs nothing leaves a forest
/// with no pair between two outer triangles of different trees: on a bipartite dual graph
/// the matching is then of maximum size.
std::size_t pair_by_trees(const DualGraph& g, Matching& m, int max_rounds);

}  // namespace quadval::recombine_detail
