#pragma once
// Minimum-cost perfect matching by Edmonds' blossom algorithm, organised as in Blossom V
// (Kolmogorov 2009, "Blossom V: a new implementation of a minimum cost perfect matching
// algorithm"): a greedy initialisation of the duals and the matching, then alternating trees
// from all free vertices growing together, the dual change applied lazily (one running offset)
// and the events (grow, shrink, augment, expand) taken from priority queues. Exact: integer
// costs, doubled inside so that every dual stays an integer.
//
// Measured against LEMON's MaxWeightedPerfectMatching (kept as the test oracle, and for the
// non-perfect fallback): equal optimum everywhere tested, and about as fast (graded square
// with a hole, 100k triangles: 0.76 s vs 0.71 s; 300k: 3.8 s vs 4.3 s). The solver waits on
// memory, so the vertex order matters: a breadth-first renumbering gained (CPU time, medians of
// 3) square-hole-100k 0.77 -> 0.55 s, square-hole-300k 3.43 -> 2.60 s, uniform-100k 7.95 ->
// 4.15 s over Gmsh's numbering; recombine's Z-order (node_order.hpp), now kept as given in
// memory (component_order in the .cpp) while the start still visits the vertices breadth
// first (breadth_first_visit), does better still: the solver alone, alternating runs,
// square-hole-1M 9.5-11.6 -> 8.3-10.8 s (medians 11.1 -> 9.2 s), uniform-1000k-a5 4.0-4.8 ->
// 3.4-4.2 s, box-130k-a6 0.53-0.62 -> 0.45-0.50 s.
//
// Both solvers grow faster than linearly on large meshes, and the time goes to the last
// augmentations. Measured (event counts per augmentation): on square-hole-100k the first 7,000
// of 7,489 augmentations take a third of the time; the last one grows a tree over 91,519 of the
// 99,778 vertices; on square-hole-1M the last 90 of 69,544 take about half the time, the last
// one a tree of 703,909 vertices. These are shortest augmenting paths between the last free
// vertices, far apart, at a large dual value (1.5 in cost units), where nearly every edge is
// tight: any method that augments one shortest path at a time (Edmonds' primal-dual, LEMON,
// Blossom V) must visit every vertex nearer than that path, i.e. the whole mesh, for each of
// them. On uniform Frontal-Delaunay meshes the same happens earlier: their triangles are nearly
// all equilateral (141,430 of 152,742 pairs of uniform-100k cost exactly 1/3), the dual graph
// is a honeycomb, bipartite, so the free vertices a region has in excess can only pair through
// its defects; one tree then covers whole regions of tight edges, and every augmentation
// dissolves it and has its neighbours absorb it again (uniform-100k: ~620 augmentations at
// distinct dual values after the first ~700, each regrowing ~12,000 vertices). Breaking the
// ties by perturbing the costs does not change that (measured; also a geometric tie-break,
// costs times 64 plus 0-63 by the shared edge's angle to a fixed axis, which makes one
// lozenge tiling of a lattice region strictly best: uniform-100k 3.6 s, with it 3.5-3.9 s),
// nor growing one tree at a time (3x slower), nor packing the per-vertex fields into one
// struct. An algorithm that augments
// along many paths per dual adjustment (cost scaling) would be the remedy.
//
// Where the work goes on uniform-100k (event counts of one run): 692 augmentations, 7.39M
// grows, 13.6M tree nodes dissolved, 280k shrinks, 262k expands. (Counted again later
// through `quadval recombine`, whose start leaves 1,504 vertices free: 752 augmentations,
// 12.5M grows, 850k shrinks, 828k expands; a shrink's cycle holds 5.4 nodes and its walk to
// the base takes 5.5 steps on average, so shrink's 14% of the time (perf) is spent waiting
// on memory (the walk's outer() lookups, the groups' boundary lists), not on long walks.
// The vertex order matters (one run each): without recombine's ordering of the triangles
// the matching took 10.0 s instead of 6.0 s; starting the breadth-first visit at 0, 25, 37,
// 50, 75 or 90% of the vertex range, 5.7-6.6 s: no start is much better.)
// - Augmentations 100-300: a few trees of 5k-30k vertices beside about 1,000 of 1-15; when
//   a big one augments, its region is regrown at the same dual value, 99.9% with the same
//   labels, about 85% of it by one neighbouring tree.
// - Augmentations 300-650 (5M of the grows): one tree covers 90k-96k vertices; each time it
//   augments (with a tree of 3-5), the region stays free until, at a higher dual value,
//   another tree reaches it and takes all of it again: about 50 such cycles.
// - The last 12 augmentations (30% of the time): about 20k shrinks and 20k expands each, of
//   blossoms of 10k-100k vertices nested thousands deep (each level adds 2-12 vertices to
//   the one inside). In a tree as "-", such a blossom is peeled one level per expand, each
//   level at its own dual value (a dual step each), and built again level by level later;
//   about 2 us per event. Expanding free blossoms whose dual is zero (the classic end-of-
//   stage rule) changes nothing here: none are left when trees dissolve.
// In a bipartite tight region the labels come back the same, only tree ids and parents
// change: a structure that let a tree take over such a region without regrowing it (parents
// repaired or found lazily) would remove most of the grows. But only where the regrowth
// comes at the dual value of the dissolution, which is rare on graded meshes. Counted over
// the nodes that dissolving trees free (labelled again with the same label at the same
// eps / later): uniform-100k-a6 1.35M / 16.5M of 21.3M freed, square-hole-100k 2 / 464k of
// 554k, square-hole-1M 1,933 / 6.35M of 7.71M. On graded meshes a freed region waits
// until some tree's dual has risen enough to reach it; a takeover at the same dual value
// would spare next to nothing there.
// A dissolving tree no longer walks its nodes' edges to find the other trees' "+" nodes (the
// edges are parked with the tree instead, see park() in the .cpp); solver alone, run
// alternately with the walk, medians of 7: uniform-100k 3.79 -> 3.28 s, square-hole-100k
// 0.87 -> 0.80 s; uniform-1000k, both at once on the two cores: 469 -> 386 s. The events
// are the same (uniform-100k: 7.38M grows, 281k shrinks, 692 augmentations); the time on
// uniform meshes still grows about as the square of their size.
//
// Warm starts, measured on uniform-100k (all give the same optimum; none adopted):
// - From the exact optimal duals of the fractional relaxation (the assignment problem of the
//   bipartite double cover, solved by LEMON's NetworkSimplex), this solver needs 0.3-0.6 s
//   instead of 3.7 s. But that solve took 12 s (LEMON's CostScaling: 1.7 s on uniform-10k,
//   where this solver takes 0.05 s), and near-optimal duals do not do: lowering each exact
//   dual by a random amount below 1e-4 cost units made the solver take 19 s, as it breaks
//   the tight structure everywhere. The cover solved by this solver itself (bipartite: no
//   blossoms; started from this graph's greedy start on both copies) took 5.2 s, 15.4M grows
//   for 1,384 augmentations: the relaxation has the same regrowth of tight regions (few odd
//   cycles survive in its optimum, so its free vertices pair up across the mesh as well);
//   from its duals and half-integral matching (odd cycles matched around, one vertex left
//   free) this solver then needed 0.15 s and 4 augmentations. An auction with epsilon-scaling (Bertsekas) for those
//   duals fell into price wars: over 100 bids per vertex per phase on uniform-10k. With
//   global price updates (every n bids, prices raised by a bucketed shortest-path pass from
//   the unassigned vertices), assignments kept across phases while still epsilon-optimal,
//   and the exact integer duals recovered from the optimal assignment by label correcting,
//   it gave the exact duals (dual objective = primal) but took 0.12 s on uniform-10k (this
//   solver: 0.07 s) and 3.8-5 s on uniform-100k: 10-28 bids per vertex per phase, and at
//   each phase start about 90% of the assignment breaks the new epsilon. Re-tried plainly
//   (forward auction, alpha = 10, every person unassigned at each phase start, global
//   price updates every n or n/5 bids): 15 phases, 20-35 bids per vertex per phase (7
//   with updates every n/5 bids, 542 updates), 8-15 s on uniform-100k; LEMON's CostScaling
//   on the same cover (the extra edges at their cost 1000) had not finished after 10 min.
// - Exact solves over cost scales (the costs' top bits first, 4 or 8 more bits per level,
//   each level started from the last one's duals in cut form, scaled up, plus its matching):
//   every level still left 600-1,000 free vertices and took 0.3-1 s; 3.5-6 s in all.
// - Blocks: the graph cut into breadth-first balls of B vertices, each solved alone (its
//   trees kept to its own edges; blossoms and duals kept), then joined: each edge between
//   blocks with negative slack had one end's top-level node lowered by the deficit (a
//   blossom through its z, opened where z ran out) and unmatched, and the whole graph
//   finished from there. The blocks take little (uniform-100k, B = 4,096: 33 blocks in
//   0.07 s, 580 vertices left free), but joining frees 1,000-9,000 vertices and the final
//   phase costs about what a whole solve did: uniform-100k 3.2 s whole against 5.2, 3.3, 1.2
//   and 3.1 s for B = 1,000, 4,096, 16,000 and 30,000; square-hole-100k 0.45 s against
//   2.0-2.6 s. The blocks' duals agree inside each block but not across: in the regions of
//   tight edges the duals of the two sides of a bipartite region can shift against each
//   other at no cost, each block settles that shift its own way, and reconciling them
//   needs the same region-wide trees.
// - Coarser integer costs (fewer distinct dual values): round(q cost) for q = 1e6, 1e4,
//   1e3, 1e2 instead of 1e9 gave uniform-100k 3.3, 3.0, 1.9, 1.5 s: the trees stay large
//   even with a hundred cost levels.
// - A primal warm start: the optimal matching itself, computed by a first solve, offered to
//   the greedy start (its edges matched first wherever they are tight at y = min c / 2):
//   uniform-100k 1,364 instead of 1,384 vertices free at the start, 2.8 s instead of 2.6 s.
//   Most optimal pairs are not tight at those duals; what the solver spends its time on is
//   finding the duals, not the pairs.
// - A larger start on the tight edges: the greedy start already leaves as few vertices free
//   as a maximum matching of the edges tight at its duals would (LEMON's MaxMatching on
//   them: uniform-100k-a6 1,504 free either way, square-hole-100k 14,948).
// Nor did prefetching the records of queued grow events and of dissolving nodes gain beyond
// the noise (memory-bound, but the loads of one step depend on each other; re-tried on the
// FIFO lane and the heap's next entries: square-hole-100k 10% faster, square-hole-1M and
// uniform-100k not); nor, on square-hole-1M (solver alone, medians
// of 6-8 alternating runs), transparent huge pages for the per-vertex arrays (madvise; the
// kernel's zeroing of 2 MiB pages took back what the TLB gained) or reserving room for the
// blossoms in the per-node arrays up front. Where its grow queue's 8.9M pops go there: 5.0M
// events fire, 2.5M are stale because their "+" end's tree dissolved, 1.1M because their free
// end joined a tree by another edge, 0.3M are queued again; queues per tree, dropped whole
// when the tree dissolves, would spare at most the first kind (about a tenth of the time).
// What did gain was removing loads from those dependent chains: each vertex's far ends
// beside its edge ids, its partner beside its mate endpoint, the edge's two ends in the
// queued events (square-hole-1M's matching 7.8 -> 6.8 s), and no malloc/free of the lists
// of reused blossom and group ids; the .cpp and event_queue.hpp give the figures.
// Where the time goes since (perf annotate of grow_trees): on square-hole-1M a fifth in the
// grow heap's sift-down (its lower levels, megabytes of 24-byte entries, miss the caches);
// on uniform-100k-a6 a fifth in the walk over a dissolving tree's nodes (a miss per node),
// which trees that end in place now spare (their nodes leave when next met; dissolve() in
// the .cpp: uniform-100k-a6's L1 data misses -14% by cachegrind). There, since, push_edges_
// of_plus_vertex takes 36% of the time (perf annotate: its samples 32% at the incidence
// load, 25% at the far end's record, 15% at the edge's cost, 12% at the group's top); the
// cost stored in the incidence (16-byte records) made the matching slower (5.39 -> 5.76 s,
// medians of 15 alternating runs).

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

/// Minimum-cost perfect matching of the graph (num_nodes, edges). Connected components are
/// solved by solvers of their own (runs of small components grouped, at least 4,096 vertices
/// each), largest first, on the OpenMP threads there are; the matching does not depend on
/// the thread count. A box of 6 faces, Gmsh's Frontal-Delaunay mesh of 128,340 triangles:
/// 1.20 s in one solver, 0.90 s one solver per face on one thread, 0.43 s on two.
/// @param[out] matched  #edges flags, 1 for the edges of the matching (resized here)
/// @param progress      optional (see MatchingProgress)
/// @return false when the graph has no perfect matching (`matched` is then unspecified)
/// @pre every edge has u != v, u, v < num_nodes, |cost| <= kMaxMatchingCost (QV_ASSERT)
bool min_cost_perfect_matching(std::uint32_t num_nodes, std::span<const CostEdge> edges,
                               std::vector<char>& matched,
                               const MatchingProgress& progress = {});

}  // namespace quadval::recombine_detail
