#pragma once
// Topological clean-up of Paper I §6: quad-vertex-merge (Fig. 10) and doublet collapse
// (Fig. 11), which delete one quad each and never touch a fixed (boundary) node; and, for
// the quads that are still not valid, a diagonal swap with a neighbouring quad.

#include <cstddef>
#include <vector>

#include "mixed_mesh.hpp"

namespace quadval::recombine_detail {

struct CleanupCounts {
  std::size_t vertex_merges = 0;
  std::size_t doublet_collapses = 0;
  std::size_t diagonal_swaps = 0;
};

/// Runs up to `max_passes` rounds (each: doublet collapses, diagonal swaps, then vertex
/// merges) until nothing changes.
/// - Doublet collapse: a free node v in exactly two quads (v, a, x, b), (v, b, y, a) is removed
///   and they become (a, x, b, y), kept if its score is not below the worse of the two.
/// - Quad-vertex-merge: a quad (a, b, c, d) whose opposite corners a, c are free, each in
///   exactly three quads, and share no other element, loses its diagonal: a and c become one
///   node (at their midpoint, or else at the mean of its edge neighbours) in four quads.
///   Kept only if b and d keep at least 3 quads (2 on the boundary) and the worst score of
///   the four quads is positive or not below the worst of the five before (never inverts).
/// - Diagonal swap: a quad that is not valid (score <= 0) and a quad of its region across one
///   of its edges are re-split along one of the two other diagonals of their hexagon, the
///   one whose worse quad scores higher, if both its quads are valid (and no element outside
///   the two already joins that diagonal's ends). No node moves: it mends what smoothing
///   cannot, such as a flat corner at a boundary node that the matching left in one quad.
/// Removed nodes stay in the arrays, unreferenced.
CleanupCounts cleanup_quads(MixedMesh& m, const std::vector<char>& fixed, int max_passes);

}  // namespace quadval::recombine_detail
