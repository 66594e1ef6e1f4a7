#pragma once
/// The registry of Gmsh element types (GmshDefines.h ids 1..140).
///
/// Every id Gmsh defines has an entry, so that a reader can name what it found. Only the
/// Lagrange types (points, lines, triangles, quadrangles, tetrahedra, hexahedra, prisms,
/// pyramids; complete and incomplete, every order) have reference nodes and shape
/// functions; the others (polygons, Xfem sub-elements, bubble "mini" elements, border
/// elements, the trihedron, order-0 one-node elements) are listed with has_lagrange_basis
/// false.

#include <cstdint>
#include <span>
#include <string_view>

namespace quadval {

enum class ElementFamily : std::uint8_t {
  point, line, triangle, quadrangle, tetrahedron, hexahedron, prism, pyramid,
  polygon, polyhedron, trihedron
};

/// "point", "line", "triangle", ...
std::string_view family_name(ElementFamily f) noexcept;
/// Topological dimension of the reference element of a family (0..3).
int family_dimension(ElementFamily f) noexcept;
/// Number of corner vertices of a family (polygons: 0, variable).
int family_num_vertices(ElementFamily f) noexcept;

struct ElementType {
  int gmsh_id;              ///< Gmsh's id (MSH file type number)
  std::string_view name;    ///< Gmsh's own name, e.g. "Triangle 6", "Quadrilateral 16I"
  ElementFamily family;
  int dim;                  ///< 0..3
  int order;                ///< polynomial order (0 for one-node constant elements)
  int num_nodes;            ///< nodes per element in MSH files; 0 = variable (polygons)
  bool complete;            ///< false for incomplete (serendipity) types
  bool has_lagrange_basis;  ///< reference nodes and shape functions are available
};

/// All 140 entries, ordered by gmsh_id; unused ids (76-78) have no entry.
std::span<const ElementType> element_types() noexcept;

/// The type with this Gmsh id, or nullptr if Gmsh defines no such id.
const ElementType* find_element_type(int gmsh_id) noexcept;

/// The Lagrange type of a family and order, or nullptr (e.g. any line of order 11).
/// Incomplete types have vertex and edge nodes only; asking for the incomplete type of a
/// family and order whose complete type has no face or interior node (lines, order 1,
/// order-2 triangles and tetrahedra) gives that complete type, as Gmsh's
/// getElementType(family, order, serendip=True) does.
const ElementType* find_element_type(ElementFamily family, int order, bool complete) noexcept;

}  // namespace quadval
