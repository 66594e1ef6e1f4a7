#pragma once
// Topological clean-up of Paper I §6: quad-vertex-merge (Fig. 10) and doublet collapse
// (Fig. 11). Both delete one quad; neither touches a fixed (boundary) node.

#include <cstddef>
#include <vector>

#include "mixed_mesh.hpp"

namespace quadval::recombine_detail {

struct CleanupCounts {
  std::size_t vertex_merges = 0;
  std::size_t doublet_collapses = 0;
};

/// Runs up to `max_passes` rounds (each: doublet collapses, then vertex merges) until nothing
/// changes.
/// - Doublet collapse: a free node v in exactly two quads (v, a, x, b), (v, b, y, a) is removed
///   and they become (a, x, b, y), kept if its score is not below the worse of the two.
/// - Quad-vertex-merge: a quad (a, b, c, d) whose opposite corners a, c are free, each in
///   exactly three quads, and share no other element, loses its diagonal: a and c become one
///   node (at their midpoint, or else at the mean of its edge neighbours) in four quads.
///   Kept only if b and d keep at least 3 quads (2 on the boundary) and the worst score of
///   the four quads is positive or not below the worst of the five before (never inverts).
/// Removed nodes stay in the arrays, unreferenced.
CleanupCounts cleanup_quads(MixedMesh& m, const std::vector<char>& fixed, int max_passes);

}  // namespace quadval::recombine_detail
