#pragma once
/// Mesh input and output: Gmsh MSH 2.2 and 4.1 (ASCII and binary) read and write, VTU
/// (VTK XML) write, OBJ / OFF surface read and write, STL read.
///
/// How files map onto a Mesh (mesh.hpp), so that read-write-read round trips are exact:
///
/// MSH 4.1
///  - Nodes, node blocks, element blocks, entities and $PhysicalNames are kept as in the
///    file, in file order. Parametric node coordinates (parametric = 1) are read and dropped
///    with a warning.
///  - Writing a mesh whose node_blocks is empty derives one node block holding every node,
///    on the entity of the first element block of the highest dimension (entity (0, 0)
///    when there are no elements), since Gmsh needs every node on an entity. Reading that
///    file back gives the derived node_blocks, so such a mesh round-trips exactly from its
///    second write on. $Entities is written only when mesh.entities is not empty.
///
/// MSH 2.2
///  - node_blocks is empty after a read (2.2 has no node entities); a write ignores it.
///  - Elements are grouped into one block per (type, elementary tag) pair, in order of
///    first appearance, elements in file order; entity_dim = the type's dimension and
///    entity_tag = the elementary tag.
///  - Physical tags go to entities: every nonzero elementary tag gets an Entity (dim = type
///    dimension, box all zero, no boundary) whose physical_tags are the distinct nonzero
///    physical tags of its elements, in order of first appearance. Gmsh writes an element
///    that belongs to two physical groups twice (same type, elementary tag and nodes,
///    another physical tag and element tag): such a copy is merged into the first one.
///  - A write emits each element once per physical tag of its entity (once with physical
///    0 when it has none); the copies get fresh element tags above the largest one.
///
/// Both versions: element types with a variable node count (polygons, polyhedra) are
/// rejected; node and element tags need not be contiguous; $Periodic, $NodeData,
/// $ElementData, $Parametrizations and other sections are skipped with a warning.
///
/// VTU (write only): VTK XML UnstructuredGrid, file version 2.2 (the current Lagrange
/// hexahedron edge order), appended raw binary data. Linear cells use the classical VTK
/// types (1, 3, 5, 9, 10, 12, 13, 14), complete higher-order lines, triangles, quadrangles,
/// tetrahedra, hexahedra and prisms the VTK Lagrange types 68-73 with nodes permuted into
/// VTK's order, the serendipity types Quadrilateral 8, Hexahedron 20, Prism 15 and
/// Pyramid 13 the VTK quadratic types 23, 25, 26, 27. VTK (9.1, installed here) has no
/// Lagrange pyramid (type 74 is not implemented), so Pyramid 14 becomes type 27 without
/// its base centre node and higher-order pyramids their linear pyramid. Other types with
/// no VTK cell (incomplete types of order >= 3, bubble, border and Xfem elements) are
/// written as their corner-only linear cell; one-node order-0 types and the trihedron as a
/// VTK_POLY_VERTEX. Each lossy case prints one warning per block on stderr. Per-element
/// fields become CellData, beside the "element_tag" and "entity_tag" arrays written always.
///
/// Surfaces (read only): STL (ASCII or binary; vertices with identical coordinates are
/// merged), OBJ (v / f lines; indices may be negative or carry /vt/vn parts), OFF. Faces
/// with 3 vertices become Triangle 3, with 4 Quadrilateral 4, each in one block on entity
/// (2, 1); node and element tags are 1..n in file order; entities and node_blocks are empty.
///
/// Surfaces (OBJ, OFF write): the triangles and quadrangles, block after block, as faces
/// over the nodes they use, in node order (coordinates in their shortest round-trip form, so
/// reading the file back gives the same positions and faces). Higher-order faces keep their
/// corners and point and line elements are left out, with one warning for each of the two;
/// a mesh with 3D elements or without faces is refused (InputError). Tags, entities and
/// fields are not written.
/// STL is not written: it holds triangles only.
///
/// Every error in the input raises InputError naming the file and the line (text) or byte
/// offset (binary) and what was expected. Every output goes through write_file_atomically.

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval {

enum class MeshFormat { msh22, msh41, vtu, stl, obj, off };

/// Per-element data for output: one value per element, in block order (block 0's
/// elements, then block 1's...).
struct ElementField {
  std::string name;
  std::vector<double> values;
};

struct WriteOptions {
  MeshFormat format = MeshFormat::msh41;
  bool binary = false;  ///< MSH only: binary instead of ASCII (VTU data is always binary)
};

/// Format from the extension (.msh -> msh41, .vtu, .stl, .obj, .off; case-insensitive).
/// Throws InputError for an unknown one.
MeshFormat format_from_extension(const std::filesystem::path& path);

/// The format to write `path` in (format_from_extension), checked before any work: throws
/// InputError for an unknown extension and for .stl (read only).
MeshFormat output_format_from_extension(const std::filesystem::path& path);

/// Reads any supported input: MSH (version 2.2 or 4.1, ASCII or binary, detected from
/// $MeshFormat), STL, OBJ, OFF (chosen by extension). Warnings (skipped sections...) are
/// appended to *warnings when given, else printed to stderr with the file name.
/// Throws InputError for a missing, empty or malformed file, or a directory.
Mesh read_mesh(const std::filesystem::path& path, std::vector<std::string>* warnings = nullptr);

/// Writes `mesh` to `path` atomically (write_file_atomically) in options.format (msh22,
/// msh41, vtu, obj or off; stl throws InputError). Fields become $ElementData (MSH) or
/// CellData (VTU); OBJ and OFF have no place for them.
/// @pre each field has mesh.num_elements() values (throws std::invalid_argument otherwise)
void write_mesh(const Mesh& mesh, const std::filesystem::path& path,
                const WriteOptions& options = {}, std::span<const ElementField> fields = {});

}  // namespace quadval
