#pragma once
// How an element of each Gmsh type becomes a VTK cell: the VTK cell type and, for each
// VTK point of the cell, which Gmsh node it is.
#include <string>
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval::io {

struct VtkCell {
  int vtk_type = 0;             ///< VTK cell type id (vtkCellType.h)
  std::vector<int> gmsh_node;   ///< VTK point i of the cell is Gmsh node gmsh_node[i]
  bool exact = true;            ///< false: a lossy stand-in (corner-only, dropped nodes)
  std::string note;             ///< what was lost, for the warning (empty when exact)
};

/// The VTK cell for elements of `type`. Built once per type and cached (thread-safe).
///  - point: VTK_VERTEX (1)
///  - order 1: the classical linear cells (3 line, 5 triangle, 9 quad, 10 tet, 12 hex,
///    13 wedge, 14 pyramid)
///  - complete order >= 2 line, triangle, quadrangle, tetrahedron, hexahedron, prism:
///    VTK Lagrange cells 68-73, nodes in VTK's order (VTK XML file version 2.2 and later)
///  - Quadrilateral 8, Hexahedron 20, Prism 15, Pyramid 13: VTK_QUADRATIC_QUAD (23),
///    _HEXAHEDRON (25), _WEDGE (26), _PYRAMID (27)
///  - Pyramid 14: VTK_QUADRATIC_PYRAMID without the base centre node (VTK 9.1 has no
///    Lagrange pyramid); other types with no VTK cell (complete pyramids of order >= 3,
///    incomplete types of order >= 3, bubble, border and Xfem elements): the corner-only
///    linear cell; one-node and variable types: VTK_POLY_VERTEX (2) of all nodes.
/// The Lagrange orders follow VTK's rules (vertices, then edges, then faces, then the
/// interior, each in VTK's direction) and are matched to Gmsh's nodes through their
/// reference coordinates (reference_nodes), not tabulated.
const VtkCell& vtk_cell(const ElementType& type);

}  // namespace quadval::io
