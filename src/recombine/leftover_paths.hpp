#pragma once
// Pairs the triangles a quad-dominant matching leaves (the look-ahead tree's, Paper II §6):
// the matching-level form of the post-process that Paper II names (Bunin's). Each step swaps
// augmenting paths: from a free triangle t0, a path t0 - t1 = t2 - t3 = ... - tk to another
// free triangle tk alternates pairs not in the matching and pairs in it; swapping them
// re-pairs the triangles along it, so both ends are paired and no other triangle is
// unpaired. In turn:
// 1. from each free triangle, the cheapest path that a best-first search finds (the cost of
//    the pairs gained minus that of the pairs given up) within 256 triangles;
// 2. for those still free, an exact re-pairing of their neighbourhoods within 4 pairs: each
//    connected piece gets the minimum-cost perfect matching of its real pairs
//    (blossom_solver.hpp) where one exists; this also passes odd cycles of pairs, where an
//    alternating search cannot;
// 3. for partners far apart, alternating trees grown from all free triangles at once, a
//    sweep of the graph per round (at most 32): the shortest paths where the trees meet
//    (fewest pairs, not the cheapest);
// 4. step 2 again within 16, then 64 pairs, for the odd cycles step 3 cannot pass.
// Step 2 within 16 pairs before step 3 took 1.2 s on uniform-1000k-a6 for 36 triangles
// (neighbourhoods in regions of equal costs are slow to solve, as Blossom is there); after
// it, 0.02 s.
// Measured (`quadval recombine --algo lookahead`: triangles left before -> after, eta_min,
// end to end): all-quad on 21 of the 22 meshes of /tmp/quadval_recombine_bench and the STL
// and CAD test surfaces; uniform-100k-a6 408 -> 0, 0.481 -> 0.526, 0.53 s (Blossom: about
// 6 s, eta_min 0.553); square-hole-1000k 3,238 -> 0, 0.506 -> 0.513, 5.7 s;
// uniform-1000k-a6 3,488 -> 86, 7.5 s (the post-process 2.2 s of it, 32 rounds of step 3).

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
