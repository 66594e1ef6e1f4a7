#pragma once
// Post-processing of matched extra edges (Paper I §5.3): each extra pair is two triangles that
// share one boundary node v only. Both repairs make them quads, so that no triangle remains.

#include <cstdint>
#include <vector>

#include "mixed_mesh.hpp"

namespace quadval::recombine_detail {

struct ExtraPair {
  std::uint32_t e0, e1;  ///< the two triangles (element indices in the MixedMesh)
  NodeIndex v;           ///< their shared boundary node
};

struct RepairCounts {
  std::size_t edge_swaps = 0;
  std::size_t vertex_duplications = 0;
  std::size_t failed = 0;  ///< pairs left as two triangles (the fan walk found no path)
};

/// Repairs each extra pair. Around v, counter-clockwise, lie: the first triangle (v, a, p1),
/// the fan elements F between them, the second triangle (v, pk, b).
/// - Edge swap (Fig. 8), when F is one quad (v, p, r, q): its diagonal becomes v-r, giving
///   the quads (v, a, p, r) and (v, r, q, b); used when both are convex.
/// - Vertex duplication (Fig. 9), otherwise: a new node v' is put inside the fan, F's elements
///   take v' instead of v, and the hexagon (v, a, p1, v', pk, b) becomes the quads
///   (v, a, p1, v') and (v, v', pk, b). v' lies on a direction strictly between p1 and pk
///   that keeps both corners at v below pi, at a distance halved until every changed element
///   is valid (at most 30 halvings; if none is valid the swap, then the smallest step, is kept
///   and counted by the caller's validity statistics).
/// New nodes get tags from `next_tag` on.
RepairCounts repair_extra_pairs(MixedMesh& m, const std::vector<ExtraPair>& pairs, Tag& next_tag);

}  // namespace quadval::recombine_detail
