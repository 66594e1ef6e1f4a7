#pragma once
// Pairs the triangles a quad-dominant matching leaves (the look-ahead tree's, Paper II §6):
// the matching-level form of the post-process that Paper II names (Bunin's). First by
// augmenting paths: from a free triangle t0, a path t0 - t1 = t2 - t3 = ... - tk to another
// free triangle tk alternates pairs not in the matching and pairs in it; swapping them
// re-pairs the triangles along it, so both ends are paired and no other triangle is
// unpaired. Each is the cheapest found by a best-first search (the cost of the pairs gained
// minus that of the pairs given up).
// Then, for those still free, by exact re-pairing of their neighbourhoods (within 4, then
// 16 pairs): each connected piece gets the minimum-cost perfect matching of its real pairs
// (blossom_solver.hpp) where one exists, which also goes through odd cycles of pairs, where
// the alternating search cannot.
// Measured (`quadval recombine --algo lookahead`, triangles left before -> after, eta_min
// before -> after): square-hole-100k 364 -> 6, 0.501 -> 0.502; square-hole-1000k 3,238 -> 14,
// 0.506 -> 0.513 (look-ahead stage 3.2 -> 3.7 s); disk-20k-a5 52 -> 0; square-hole-35k 76 ->
// 0; box-12k-a6 132 -> 4; uniform-100k-a6 408 -> 176, 0.481 -> 0.473 (there the free
// triangles' partners lie far away, as for Blossom: blossom_solver.hpp).

#include <cstddef>

#include "dual_graph.hpp"
#include "matching.hpp"

namespace quadval::recombine_detail {

/// Pairs free triangles of `m` (a matching of `g`'s real pairs) as above: the path searches
/// from 256 triangles each, then the neighbourhoods within 4 and 16 pairs. Every triangle
/// paired before stays paired; m.pairs (kept ascending), m.cost and m.perfect are updated.
/// Returns the number of triangles paired.
std::size_t pair_leftovers(const DualGraph& g, Matching& m);

/// The first step alone: a search from each free triangle in increasing index, stopping
/// after `max_visits` triangles. It labels each triangle once (an alternating tree), so on a
/// dual graph with odd cycles it can miss a path that exists; on a bipartite one (all
/// interior nodes of even degree) it misses none within its reach.
std::size_t pair_along_paths(const DualGraph& g, Matching& m, std::size_t max_visits);

/// The second step alone, with the neighbourhoods within `radius` pairs of the free
/// triangles. A piece that holds a whole connected set of triangles gets that set's optimum.
std::size_t pair_in_neighbourhoods(const DualGraph& g, Matching& m, int radius);

}  // namespace quadval::recombine_detail
