#pragma once
/// Topology of a triangle mesh: unique edges, triangle adjacency (the dual graph), boundary
/// edges and loops, non-manifold edges, vertex degrees.
///
/// Used by `quadval info` (even/odd triangle count, non-manifold edges, boundary loops) and
/// by the recombination (the dual graph of Paper I §4.2, the boundary walk of §5.3).
/// Only corner nodes matter: a high-order triangle contributes its first three nodes.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval {

/// Marks "no triangle" in TriangleTopology::neighbors.
inline constexpr std::uint32_t kNoTriangle = 0xffffffffu;

struct TriangleTopology {
  std::size_t num_nodes = 0;  ///< size of the node arrays the indices refer to
  /// #triangles: corner nodes in input order (all triangle blocks, concatenated in block order).
  std::vector<std::array<NodeIndex, 3>> triangles;
  /// #edges: the two end nodes of each unique edge, smaller index first; ordered by
  /// (first, second).
  std::vector<std::array<NodeIndex, 2>> edges;
  /// Triangles that repeat a node (no area, no edges): they are skipped everywhere else.
  std::vector<std::uint32_t> collapsed_triangles;
  /// #triangles × 3: edge k of a triangle joins its corners k and (k+1) mod 3
  /// (kNoTriangle for collapsed triangles).
  std::vector<std::array<std::uint32_t, 3>> triangle_edges;
  /// #edges + 1 offsets into edge_triangles (CSR): the triangles that hold each edge.
  std::vector<std::uint32_t> edge_triangle_offsets;
  std::vector<std::uint32_t> edge_triangles;
  /// #triangles × 3: the triangle across edge k, or kNoTriangle when edge k is on the
  /// boundary or non-manifold. Symmetric: this is the adjacency of the dual graph.
  std::vector<std::array<std::uint32_t, 3>> neighbors;
  /// Edges held by exactly one triangle, ascending.
  std::vector<std::uint32_t> boundary_edges;
  /// Edges held by three or more triangles, ascending.
  std::vector<std::uint32_t> nonmanifold_edges;
  /// Boundary edges chained into loops: each loop lists its nodes in walking order, the
  /// closing edge (last -> first) implied. Where more than two boundary edges meet at a node
  /// (a pinch), the walk takes the first unused one; a chain that cannot close (possible only
  /// next to non-manifold edges) is listed in open_boundary_chains instead.
  std::vector<std::vector<NodeIndex>> boundary_loops;
  std::vector<std::vector<NodeIndex>> open_boundary_chains;
  /// #nodes: number of edges at each node (0 for nodes no triangle uses).
  std::vector<std::uint32_t> vertex_valence;
  /// #nodes: number of triangles at each node.
  std::vector<std::uint32_t> vertex_triangles;
  /// Interior (two-triangle) edges that both triangles run in the same direction, i.e. the
  /// two triangles have opposite orientations.
  std::size_t num_misoriented_edges = 0;

  std::size_t num_triangles() const noexcept { return triangles.size(); }
  std::size_t num_edges() const noexcept { return edges.size(); }
  bool even() const noexcept { return triangles.size() % 2 == 0; }
  /// Number of triangles holding edge e.
  std::uint32_t edge_degree(std::uint32_t e) const noexcept {
    return edge_triangle_offsets[e + 1] - edge_triangle_offsets[e];
  }
};

/// Topology of the given triangles.
/// @param triangles  #triangles corner triples (node indices)
/// @param num_nodes  size of the node arrays; every index must be < num_nodes
/// @pre every node index < num_nodes (QV_ASSERT). A triangle that repeats a node is listed in
///      collapsed_triangles and takes no part in edges or adjacency.
/// O(#triangles) time and memory.
TriangleTopology build_triangle_topology(std::span<const std::array<NodeIndex, 3>> triangles,
                                         std::size_t num_nodes);

/// Topology of all triangle blocks of a mesh (any order: corner nodes only), in block order.
/// Elements of other families are ignored.
TriangleTopology build_triangle_topology(const Mesh& mesh);

/// The corner triples of all triangle blocks of a mesh, in block order.
std::vector<std::array<NodeIndex, 3>> triangle_corners(const Mesh& mesh);

}  // namespace quadval
