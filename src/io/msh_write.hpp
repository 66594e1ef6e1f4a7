#pragma once
// MSH writers (conventions in io.hpp).
#include <ostream>
#include <span>
#include <string>

#include "quadval/io.hpp"

namespace quadval::io {

/// Writes `mesh` as MSH 4.1 or 2.2, ASCII or binary; fields become $ElementData.
/// `file` names the output in errors (e.g. a tag that does not fit MSH 2.2's int).
/// @pre the mesh is consistent (node indices < num_nodes, connectivity sizes match types,
///      node_blocks empty or a partition of the nodes in order); QV_ASSERT checks it.
void write_msh(const Mesh& mesh, std::ostream& out, bool version41, bool binary,
               std::span<const ElementField> fields, const std::string& file);

}  // namespace quadval::io
