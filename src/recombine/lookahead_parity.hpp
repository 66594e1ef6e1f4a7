#pragma once
// Even polder sets for the look-ahead criterion (Paper II, Definition 2): every connected set
// of triangles must start with an even count, not only every region (surface entity).

#include "triangle_input.hpp"

namespace quadval::recombine_detail {

/// Like make_regions_even (OddPolicy::split_boundary_edge), but per connected piece of a
/// region (triangles of one region joined through shared edges): in each piece with an odd
/// count the longest boundary edge is split at its midpoint, by make_regions_even itself run
/// on the pieces. A region made of several odd pieces (even in total, so left alone by
/// make_regions_even) thus gets one split per odd piece. Pieces without a boundary edge are
/// reported in odd_regions_left by their region index (once per region).
/// @post s.region and s.region_entity keep their meaning; s.odd_splits counts the splits.
void make_pieces_even(TriangleSurface& s);

}  // namespace quadval::recombine_detail
