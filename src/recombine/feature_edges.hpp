#pragma once
// Feature edges of a triangulated surface in 3D (an STL of a part, say): the edges where the
// surface bends by more than a given angle. Recombination treats them as region boundaries,
// as it treats the curves between the faces of a CAD model: no quad is folded across one, and
// the smoothing neither moves the nodes off them nor rounds the corners they make.

#include <cstddef>

#include "triangle_input.hpp"

namespace quadval::recombine_detail {

/// Splits each region of a non-planar surface along its feature edges: the edges shared by
/// two triangles of the region whose normals (consistently oriented, validate_triangles) make
/// an angle above `angle_degrees`. Each connected piece left between features becomes a
/// region of its own, with its parent's entity tag, and the two triangles of every feature
/// edge are a forbidden pair (TriangleSurface::forbidden_pairs); a piece of a single triangle
/// joins the neighbour across its least sharp edge instead (its edges are then no features).
/// Nothing changes for a planar surface or
/// for angle_degrees >= 180. Returns the number of feature edges found.
/// @pre validate_triangles has run (oriented triangles; the topology, if kept, stays valid)
std::size_t split_regions_at_features(TriangleSurface& s, double angle_degrees);

}  // namespace quadval::recombine_detail
