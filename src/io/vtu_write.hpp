#pragma once
// VTU (VTK XML UnstructuredGrid) writer (conventions in io.hpp and vtk_node_order.hpp).
#include <ostream>
#include <span>
#include <string>

#include "quadval/io.hpp"

namespace quadval::io {

/// Writes `mesh` as VTK XML UnstructuredGrid, file version 2.2, raw appended binary data
/// (UInt64 headers): Points (Float64), connectivity and offsets (Int64), types (UInt8),
/// CellData "element_tag" (Int64), "entity_tag" (Int32) and one Float64 array per field.
/// Elements of a type with no exact VTK cell get a warning on stderr naming `file`.
/// @pre each field has mesh.num_elements() values
void write_vtu(const Mesh& mesh, std::ostream& out, std::span<const ElementField> fields, const std::string& file);

}  // namespace quadval::io
