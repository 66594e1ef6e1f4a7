#pragma once
// Boundary nodes that may slide: a node of the region boundary whose only two boundary
// neighbours a, b lie on one straight line through it (a straight side of the domain or of an
// interface). Moving such a node along a-b, strictly between a and b, keeps the boundary's
// shape exactly, which lets smoothing (Paper I §6) improve the quads along straight sides.

#include <array>
#include <vector>

#include "mixed_mesh.hpp"

namespace quadval::recombine_detail {

/// Per node: {a, b}, its two boundary neighbours, when it can slide between them; else
/// {kNoNode, kNoNode} (interior nodes, corners, nodes on curved sides, junctions).
/// @param boundary  region_boundary_nodes(m)
/// Collinear: |(v - a) × (b - v)| <= 1e-12 |v - a| |b - v| and (v - a)·(b - v) > 0.
std::vector<std::array<NodeIndex, 2>> straight_boundary_slides(const MixedMesh& m,
                                                                const std::vector<char>& boundary);

}  // namespace quadval::recombine_detail
