#pragma once
// The look-ahead tree (Paper II) as a step of the recombine() pipeline: it returns the merged
// pairs as a Matching of the dual graph, so that the rest of the pipeline (mixed mesh,
// optimisation, the full-quad refinement of leftover triangles, statistics) is shared with
// Blossom-Quad.

#include "dual_graph.hpp"
#include "matching.hpp"
#include "quadval/recombine.hpp"
#include "triangle_input.hpp"

namespace quadval::recombine_detail {

/// Best of options.lookahead.runs runs on the real pairs of `graph` (built without extra
/// pairs), then its leftover triangles paired (leftover_paths.hpp: lookahead_path_pairs).
/// Fills the lookahead_* statistics (the tree's own: quality, triangles left); with
/// options.compare_with_blossom also the Blossom optimum on the same pairs
/// (blossom_matching) and the percentage.
/// @throws InputError (naming options.source) when a connected set of triangles has an odd
///         count: the criterion needs even polder sets. OddPolicy::split_boundary_edge
///         (make_pieces_even) fixes every odd piece that has a boundary edge; this is left for
///         OddPolicy::leave_triangle and for odd pieces without a boundary edge.
Matching lookahead_matching(const DualGraph& graph, const TriangleSurface& s,
                            const RecombineOptions& options, RecombineStats& stats);

}  // namespace quadval::recombine_detail
