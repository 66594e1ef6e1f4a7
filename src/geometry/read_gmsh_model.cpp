#include "geometry/read_gmsh_model.hpp"

#include <unordered_map>

#include <gmsh.h>

#include "quadval/error.hpp"

namespace quadval::geometry {

Mesh read_gmsh_model_mesh(int max_dim) {
  Mesh mesh;
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities);

  // Physical groups and their names.
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    if (dim > max_dim) continue;
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    mesh.physical_names.push_back({dim, tag, name});
  }

  // Entities and their nodes.
  std::unordered_map<std::size_t, NodeIndex> index_of_tag;
  for (const auto& [dim, tag] : entities) {
    if (dim > max_dim) continue;
    Entity e;
    e.dim = dim;
    e.tag = tag;
    gmsh::model::getBoundingBox(dim, tag, e.box[0], e.box[1], e.box[2], e.box[3], e.box[4],
                                e.box[5]);
    gmsh::model::getPhysicalGroupsForEntity(dim, tag, e.physical_tags);
    if (dim > 0) {
      gmsh::vectorpair boundary;
      gmsh::model::getBoundary({{dim, tag}}, boundary, /*combined=*/false, /*oriented=*/true,
                               /*recursive=*/false);
      for (const auto& b : boundary) e.boundary_tags.push_back(b.second);
    }
    mesh.entities.push_back(std::move(e));

    std::vector<std::size_t> tags;
    std::vector<double> coords, parametric;
    gmsh::model::mesh::getNodes(tags, coords, parametric, dim, tag, /*includeBoundary=*/false,
                                /*returnParametricCoord=*/false);
    if (tags.empty()) continue;
    QV_ASSERT(coords.size() == 3 * tags.size(), "Gmsh gave " << coords.size() << " coordinates for "
                                                             << tags.size() << " nodes");
    mesh.node_blocks.push_back({dim, tag, mesh.node_tags.size(), tags.size()});
    for (std::size_t i = 0; i < tags.size(); ++i) {
      const auto [it, inserted] =
          index_of_tag.emplace(tags[i], static_cast<NodeIndex>(mesh.node_tags.size()));
      QV_ASSERT(inserted, "Gmsh node " << tags[i] << " on two entities");
      mesh.node_tags.push_back(tags[i]);
    }
    mesh.coords.insert(mesh.coords.end(), coords.begin(), coords.end());
  }

  // Elements, one block per (entity, type).
  for (const auto& [dim, tag] : entities) {
    if (dim > max_dim) continue;
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, node_tags;
    gmsh::model::mesh::getElements(types, element_tags, node_tags, dim, tag);
    for (std::size_t t = 0; t < types.size(); ++t) {
      ElementBlock block;
      block.type = find_element_type(types[t]);
      QV_ASSERT(block.type && block.type->num_nodes > 0, "Gmsh element type " << types[t]);
      block.entity_dim = dim;
      block.entity_tag = tag;
      block.tags.assign(element_tags[t].begin(), element_tags[t].end());
      block.nodes.reserve(node_tags[t].size());
      for (std::size_t n : node_tags[t]) {
        const auto it = index_of_tag.find(n);
        QV_ASSERT(it != index_of_tag.end(), "Gmsh element node " << n << " has no coordinates");
        block.nodes.push_back(it->second);
      }
      QV_ASSERT(block.nodes.size() == block.tags.size() * block.type->num_nodes,
                "connectivity size " << block.nodes.size());
      mesh.blocks.push_back(std::move(block));
    }
  }
  return mesh;
}

}  // namespace quadval::geometry
