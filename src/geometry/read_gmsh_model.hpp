#pragma once
// Reads the current Gmsh model's mesh into a quadval::Mesh through the API (getNodes /
// getElements per entity), not through a file. Internal to src/geometry.

#include "quadval/mesh.hpp"

namespace quadval::geometry {

/// Entities of dimension 0..max_dim with their boxes, boundaries and physical tags; their
/// nodes in one node block per entity; their elements in one block per (entity, type), in
/// Gmsh's order. Node indices refer to positions in the returned node arrays.
/// @pre a Gmsh session is open and the model is meshed up to max_dim.
Mesh read_gmsh_model_mesh(int max_dim);

}  // namespace quadval::geometry
