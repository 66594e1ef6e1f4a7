#pragma once
// The working mesh of the recombination: triangles and quads in one array, with a reference
// normal per element (the side it must face, from the input triangles) so that validity can
// be checked on surfaces in 3D. The repair, smoothing, clean-up and refinement stages all
// take and return this type, so that the look-ahead tree (Paper II) can reuse them.

#include <array>
#include <cstdint>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval::recombine_detail {

inline constexpr NodeIndex kNoNode = 0xffffffffu;

struct MixedMesh {
  std::vector<double> coords;   ///< #nodes × 3
  std::vector<Tag> node_tags;   ///< #nodes
  /// #elements: corners in order around the element, counter-clockwise seen from `normal`;
  /// [3] == kNoNode for a triangle.
  std::vector<std::array<NodeIndex, 4>> elements;
  std::vector<std::int32_t> region;                ///< #elements
  std::vector<std::array<double, 3>> normal;       ///< #elements, any length > 0
  std::vector<char> alive;                         ///< #elements: false once removed

  std::size_t num_nodes() const noexcept { return node_tags.size(); }
  static int size(const std::array<NodeIndex, 4>& e) noexcept { return e[3] == kNoNode ? 3 : 4; }
  bool is_quad(std::size_t e) const noexcept { return elements[e][3] != kNoNode; }
  std::array<double, 3> point(NodeIndex i) const noexcept {
    return {coords[3 * std::size_t{i}], coords[3 * std::size_t{i} + 1],
            coords[3 * std::size_t{i} + 2]};
  }
  NodeIndex add_node(const std::array<double, 3>& x, Tag tag) {
    coords.insert(coords.end(), x.begin(), x.end());
    node_tags.push_back(tag);
    return static_cast<NodeIndex>(node_tags.size() - 1);
  }
};

/// Shape score used to accept or refuse a change: for a convex quad its eta (eq. 3, > 0);
/// for a non-convex, inverted or degenerate quad the smallest signed corner sine (<= 0).
/// For a triangle: its smallest corner sine scaled so that the equilateral scores 1, negative
/// when it faces against its normal. Valid element <=> score > 0.
double element_score(const MixedMesh& m, const std::array<NodeIndex, 4>& element,
                     const std::array<double, 3>& normal) noexcept;
inline double element_score(const MixedMesh& m, std::size_t e) noexcept {
  return element_score(m, m.elements[e], m.normal[e]);
}

/// Nodes on the boundary of their region (an edge that no other alive element of the same
/// region shares), and so on interfaces between regions: these never move. O(#elements).
std::vector<char> region_boundary_nodes(const MixedMesh& m);

/// The alive elements at each node (dynamic lists: the clean-up edits them).
std::vector<std::vector<std::uint32_t>> node_elements(const MixedMesh& m);

/// Position of node v in element e (QV_ASSERT that it is there).
int corner_of(const std::array<NodeIndex, 4>& e, NodeIndex v);
inline NodeIndex next_corner(const std::array<NodeIndex, 4>& e, int i) {
  return e[(i + 1) % MixedMesh::size(e)];
}
inline NodeIndex prev_corner(const std::array<NodeIndex, 4>& e, int i) {
  const int n = MixedMesh::size(e);
  return e[(i + n - 1) % n];
}

}  // namespace quadval::recombine_detail
