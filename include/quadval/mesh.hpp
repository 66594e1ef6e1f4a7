#pragma once
/// The one mesh type that flows through quadval (DESIGN.md "Data flow").
///
/// Nodes are a contiguous x,y,z array; elements come in blocks of one type on one model
/// entity, with contiguous connectivity given as node *indices* (0-based positions in the
/// node arrays, not MSH tags). Entities and physical groups are kept so that a MSH file
/// survives a read-write-read round trip.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval {

using NodeIndex = std::uint32_t;  ///< position of a node in Mesh::coords / Mesh::node_tags
using Tag = std::uint64_t;        ///< MSH node or element tag (>= 1)

/// A physical group: name of a ($PhysicalNames) or group without a name (name empty).
struct PhysicalGroup {
  int dim = 0;
  int tag = 0;
  std::string name;
  bool operator==(const PhysicalGroup&) const = default;
};

/// A model entity (point, curve, surface, volume) as in MSH 4.1 $Entities.
struct Entity {
  int dim = 0;
  int tag = 0;
  /// minX minY minZ maxX maxY maxZ; for points, x y z x y z.
  std::array<double, 6> box{};
  std::vector<int> physical_tags;
  /// Signed tags of the bounding entities of dimension dim-1 (empty for points).
  std::vector<int> boundary_tags;
  bool operator==(const Entity&) const = default;
};

/// A run of consecutive nodes that belong to one entity (MSH 4.1 node block).
struct NodeBlock {
  int entity_dim = 0;
  int entity_tag = 0;
  std::size_t first = 0;  ///< index of the first node of the run
  std::size_t count = 0;
  bool operator==(const NodeBlock&) const = default;
};

/// Elements of one type on one entity. entity_tag 0 means "no entity known".
struct ElementBlock {
  const ElementType* type = nullptr;  ///< never null in a valid mesh; points into the registry
  int entity_dim = 0;
  int entity_tag = 0;
  std::vector<Tag> tags;          ///< #elements
  std::vector<NodeIndex> nodes;   ///< #elements × type->num_nodes, Gmsh node order

  std::size_t size() const noexcept { return tags.size(); }
  std::span<const NodeIndex> element(std::size_t e) const noexcept {
    const std::size_t n = static_cast<std::size_t>(type->num_nodes);
    return {nodes.data() + e * n, n};
  }
  bool operator==(const ElementBlock&) const = default;
};

struct Mesh {
  std::vector<Tag> node_tags;              ///< #nodes
  std::vector<double> coords;              ///< #nodes × 3
  std::vector<NodeBlock> node_blocks;      ///< optional: which entity each node run is on
  std::vector<ElementBlock> blocks;
  std::vector<Entity> entities;            ///< optional ($Entities of MSH 4.1)
  std::vector<PhysicalGroup> physical_names;

  std::size_t num_nodes() const noexcept { return node_tags.size(); }
  std::size_t num_elements() const noexcept;
  std::array<double, 3> node(NodeIndex i) const noexcept {
    return {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
  }
  /// Highest dimension among the element blocks (-1 if there are none).
  int dimension() const noexcept;

  bool operator==(const Mesh&) const = default;
};

}  // namespace quadval
