#pragma once
// Uniform refinement to an all-quad mesh (Paper I §3, Fig. 2): each quad becomes 4 quads, each
// triangle 3, through the edge midpoints and the element centroid. Sizes halve.

#include "mixed_mesh.hpp"

namespace quadval::recombine_detail {

/// Returns the refined mesh (new nodes: edge midpoints shared between neighbours, then
/// centroids; tags from next_tag on). Orientation, regions and normals are inherited.
MixedMesh refine_to_quads(const MixedMesh& m, Tag& next_tag);

}  // namespace quadval::recombine_detail
