#pragma once
// Topological clean-up of Paper I §6: quad-vertex-merge (Fig. 10) and doublet collapse
// (Fig. 11), which delete one quad each and never touch a fixed (boundary) node; and, ours,
// diagonal swaps with a neighbouring quad: for the quads whose shape smoothing cannot mend,
// and (swap_worst) at the worst quads once the mesh is smoothed.

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
/// - Diagonal swap, for a quad that is not valid (score <= 0) or has a frozen corner (it and
///   both its neighbours fixed: no smoothing changes its angle): it and a quad of its region
///   across one of its edges are re-split along one of the two other diagonals of their
///   hexagon (never one that already joins two nodes of another element, never into a quad
///   with a stuck corner, i.e. frozen and not strictly convex). A quad that is not valid takes
///   the split whose worse quad scores higher if both are valid, or, if it has a stuck corner,
///   even if not (smoothing opens the rest). A valid quad with a frozen corner takes the split
///   that, with the free nodes of the hexagon relaxed, most raises the worst score of the
///   elements there, if any does. It mends what smoothing cannot: a corner of (nearly)
///   180 degrees at a boundary node that only that quad holds.
/// Removed nodes stay in the arrays, unreferenced.
CleanupCounts cleanup_quads(MixedMesh& m, const std::vector<char>& fixed, int max_passes);

/// The last step of the optimisation: up to `rounds` rounds, each over the worst `share` of
/// the quads (at least 16), worst first, of the diagonal swap for valid quads (as in
/// cleanup_quads, with the hexagon's free nodes relaxed), kept only where it raises the
/// worst score of the elements around the hexagon. So the mesh's worst quad never gets worse
/// and no element is inverted. Returns the swaps made.
/// @param near  if given, set to 1 (resized to #nodes) at the nodes of the elements around
///              each swapped quad's corners, for a local smoothing after
std::size_t swap_worst(MixedMesh& m, const std::vector<char>& fixed, double share = 0.002, int rounds = 2,
                       std::vector<char>* near = nullptr);

}  // namespace quadval::recombine_detail
