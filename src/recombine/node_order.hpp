#pragma once
// Nodes renumbered along a space-filling curve, so that nodes near in space are near in
// memory: the smoothing sweeps visit the nodes in index order and read their neighbours'
// coordinates, which on meshes numbered by a Delaunay refinement's insertion order (Gmsh's
// Frontal-Delaunay: spatially scattered) miss the cache at every step. Measured on
// square-hole-300k: smoothing 1.53 -> 0.71 s.

#include "triangle_input.hpp"

namespace quadval::recombine_detail {

/// Renumbers the nodes of `s` in Z-order (Morton order, 21 bits per axis over the bounding
/// box of the finite coordinates; ties and non-finite coordinates keep their input order):
/// permutes coords and node_tags and remaps the triangles (and drops s.topology). Triangles, their order and
/// everything indexed by triangle are unchanged, and so is the dual graph.
void order_nodes_along_curve(TriangleSurface& s);

/// Then the triangles in the order of their smallest node (stable): after
/// order_nodes_along_curve, neighbours in space are neighbours in memory for every pass over
/// the triangles too (the dual graph's costs, parity, repair; input files list them in a
/// Delaunay refinement's order). Permutes triangles, region, triangle_tags and input_index
/// (and drops s.topology).
/// Measured on square-hole-1M: graph 0.71 -> 0.40 s, clean-up 0.66 -> 0.16 s, polish 0.99 ->
/// 0.49 s, smoothing 1.7 + 1.5 -> 1.0 + 1.0 s (one run each; the sort costs about 0.1 s).
/// @pre s.forbidden_pairs is empty (called before parity splits)
void order_triangles_along_curve(TriangleSurface& s);

}  // namespace quadval::recombine_detail
