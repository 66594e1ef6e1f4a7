#pragma once
// The triangles to recombine, checked and prepared: validated (InputError for bad input),
// oriented consistently per connected region, and made even per region (OddPolicy).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "quadval/mesh.hpp"
#include "quadval/recombine.hpp"
#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

struct TriangleSurface {
  std::vector<double> coords;                       ///< #nodes × 3 (input nodes, then new ones)
  std::vector<Tag> node_tags;                       ///< #nodes (new nodes: after the input max)
  std::vector<std::array<NodeIndex, 3>> triangles;  ///< oriented consistently per component
  std::vector<std::int32_t> region;                 ///< #triangles: index into region_entity
  std::vector<Tag> triangle_tags;                   ///< #triangles (split halves share the tag)
  std::vector<std::uint32_t> input_index;           ///< #triangles: position in triangle_corners()
  std::vector<int> region_entity;                   ///< entity tag of each region
  std::size_t flipped = 0;                          ///< triangles reversed to orient consistently
  std::size_t odd_splits = 0;
  /// The two halves of each split triangle: merged they would give back the triangle, a quad
  /// with a flat corner at the new node, so they must not be paired.
  std::vector<std::array<std::uint32_t, 2>> forbidden_pairs;
  std::vector<std::int32_t> odd_regions_left;       ///< odd regions that could not be split
  bool planar = true;                               ///< all nodes at one z
  /// The topology of `triangles` as they are, kept from validate_triangles for the steps
  /// after it (parity, dual graph) so that they need not build it again (uniform-1000k-a5:
  /// about 0.1 s each); reset by whatever changes the triangles. Callers may drop it once
  /// the dual graph is built (its memory, about 75 bytes per triangle).
  std::optional<TriangleTopology> topology;
};

/// Reads the triangles of `mesh`, validates them and orients them (see recombine()'s
/// @throws). Does not fix parity; see make_regions_even.
TriangleSurface prepare_triangles(const Mesh& mesh, const std::string& source,
                                  std::vector<std::string>& warnings);

/// prepare_triangles in two steps, so that the triangles can be reordered in between
/// (node_order.hpp), and the checks then read memory in order (uniform-1000k-a5, Gmsh's
/// numbering: checks and ordering 0.60 -> 0.29 s, medians of 5): collect_triangles only reads
/// them (InputError for elements other than triangles, or none), validate_triangles does the
/// rest and keeps the topology (TriangleSurface::topology).
TriangleSurface collect_triangles(const Mesh& mesh, const std::string& source,
                                  std::vector<std::string>& warnings);
void validate_triangles(TriangleSurface& surface, const std::string& source,
                        std::vector<std::string>& warnings);

/// The kept topology of `surface`, or one built into `built` when there is none.
const TriangleTopology& topology_of(const TriangleSurface& surface, std::optional<TriangleTopology>& built);

/// Splits, in each region with an odd triangle count, its longest boundary edge (an edge with
/// one triangle in the whole mesh) at the midpoint. Odd regions without such an edge (the
/// pieces of a closed surface cut at its feature edges) are first made even by splitting
/// edges between two regions (split_interfaces in the .cpp); those that remain odd are
/// listed in odd_regions_left. s.odd_splits counts the edges split.
void make_regions_even(TriangleSurface& surface);

/// Signed-area normal (b - a) × (c - a) of a triangle (length = twice its area).
std::array<double, 3> triangle_normal(const std::vector<double>& coords,
                                      const std::array<NodeIndex, 3>& t) noexcept;

}  // namespace quadval::recombine_detail
