#pragma once
// Surface writers: Wavefront OBJ and OFF (conventions in io.hpp). Both hold polygons and
// nothing else, so what reaches them is the triangles and quadrangles of a mesh.
#include <ostream>
#include <string>

#include "quadval/mesh.hpp"

namespace quadval::io {

/// The triangles and quadrangles of `mesh`, block after block, as faces ("f i j k [l]",
/// 1-based) over the nodes they use ("v x y z", in node order, coordinates in their shortest
/// round-trip form). Higher-order faces keep their corners only, and point and line
/// elements are left out, each with a warning on stderr naming `file`.
/// Throws InputError naming `file` when the mesh has a 3D element or no face at all.
void write_obj(const Mesh& mesh, std::ostream& out, const std::string& file);

/// The same as OFF: "OFF", the counts "nv nf 0", the vertices, then "k i_0 ... i_{k-1}"
/// (0-based) per face.
void write_off(const Mesh& mesh, std::ostream& out, const std::string& file);

}  // namespace quadval::io
