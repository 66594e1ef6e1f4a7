#pragma once
// The uniform (Paper II §4) and selective (§5) look-ahead trees over a LookaheadState.

#include <cstdint>
#include <vector>

#include "lookahead_state.hpp"
#include "quadval/lookahead.hpp"

namespace quadval::recombine_detail {

struct LookaheadOutcome {
  std::vector<std::uint32_t> pairs;  ///< merged pairs (into LookaheadGraph::pairs), in order
  LookaheadRun run;
};

/// One run with the random stream std::mt19937_64(seed). At each step a tree of depth
/// options.horizon is expanded from the current state and the first action of its best
/// sequence (largest sum of rewards; a branch that ends early is a leaf) is applied, until no
/// allowed action is left.
/// - uniform, horizon 1: best allowed pair first (a priority queue, exact by the lemma of
///   lookahead_state.hpp), ties in a random order fixed per run.
/// - uniform, horizon > 1: every allowed pair at every node (small meshes only).
/// - selective: the root branches on the options of a triangle with the fewest allowed options
///   (found through buckets of cached counts, which are upper bounds, re-checked when drawn);
///   a child branches on a most constrained free triangle next to the quads made along its
///   branch, or, when there is none, on the root's kind of triangle. A triangle with a single
///   option is merged without a tree.
/// @pre every dual component of g has an even number of triangles.
LookaheadOutcome lookahead_run(const LookaheadGraph& g, const LookaheadOptions& options,
                               std::uint64_t seed);

/// The uniform tree (§4) by plain enumeration, at any horizon, with the same random stream
/// as lookahead_run: lookahead_run uses it for horizons >= 2 and a priority queue for
/// horizon 1; at horizon 1 both must give the same sequence for the same seed (ties
/// included), which the tests check through this entry point.
LookaheadOutcome uniform_enumeration_run(const LookaheadGraph& g, int horizon, std::uint64_t seed);

struct LookaheadBest {
  LookaheadOutcome best;
  std::size_t best_run = 0;
  std::vector<LookaheadRun> runs;  ///< all runs, in run order (for box plots)
};

/// options.runs runs in parallel (OpenMP), run i with seed options.seed + i; the best is the
/// largest quality, ties to the lowest run index: the same for any thread count.
LookaheadBest lookahead_best_of(const LookaheadGraph& g, const LookaheadOptions& options);

}  // namespace quadval::recombine_detail
