#include "quadval/element_type.hpp"

#include <algorithm>
#include <array>

namespace quadval {

std::string_view family_name(ElementFamily f) noexcept {
  switch (f) {
    case ElementFamily::point: return "point";
    case ElementFamily::line: return "line";
    case ElementFamily::triangle: return "triangle";
    case ElementFamily::quadrangle: return "quadrangle";
    case ElementFamily::tetrahedron: return "tetrahedron";
    case ElementFamily::hexahedron: return "hexahedron";
    case ElementFamily::prism: return "prism";
    case ElementFamily::pyramid: return "pyramid";
    case ElementFamily::polygon: return "polygon";
    case ElementFamily::polyhedron: return "polyhedron";
    case ElementFamily::trihedron: return "trihedron";
  }
  return "?";
}

int family_dimension(ElementFamily f) noexcept {
  switch (f) {
    case ElementFamily::point: return 0;
    case ElementFamily::line: return 1;
    case ElementFamily::triangle:
    case ElementFamily::quadrangle:
    case ElementFamily::polygon: return 2;
    default: return 3;
  }
}

int family_num_vertices(ElementFamily f) noexcept {
  switch (f) {
    case ElementFamily::point: return 1;
    case ElementFamily::line: return 2;
    case ElementFamily::triangle: return 3;
    case ElementFamily::quadrangle: return 4;
    case ElementFamily::tetrahedron: return 4;
    case ElementFamily::hexahedron: return 8;
    case ElementFamily::prism: return 6;
    case ElementFamily::pyramid: return 5;
    case ElementFamily::trihedron: return 4;
    default: return 0;
  }
}

namespace {

using F = ElementFamily;
constexpr bool C = true;   // complete
constexpr bool I = false;  // incomplete (vertex and edge nodes only)

// Ids, names, orders and node counts are Gmsh's (GmshDefines.h, and
// gmsh.model.mesh.getElementProperties for the ones it can build).
constexpr ElementType kTypes[] = {
    {1, "Line 2", F::line, 1, 1, 2, C, true},
    {2, "Triangle 3", F::triangle, 2, 1, 3, C, true},
    {3, "Quadrilateral 4", F::quadrangle, 2, 1, 4, C, true},
    {4, "Tetrahedron 4", F::tetrahedron, 3, 1, 4, C, true},
    {5, "Hexahedron 8", F::hexahedron, 3, 1, 8, C, true},
    {6, "Prism 6", F::prism, 3, 1, 6, C, true},
    {7, "Pyramid 5", F::pyramid, 3, 1, 5, C, true},
    {8, "Line 3", F::line, 1, 2, 3, C, true},
    {9, "Triangle 6", F::triangle, 2, 2, 6, C, true},
    {10, "Quadrilateral 9", F::quadrangle, 2, 2, 9, C, true},
    {11, "Tetrahedron 10", F::tetrahedron, 3, 2, 10, C, true},
    {12, "Hexahedron 27", F::hexahedron, 3, 2, 27, C, true},
    {13, "Prism 18", F::prism, 3, 2, 18, C, true},
    {14, "Pyramid 14", F::pyramid, 3, 2, 14, C, true},
    {15, "Point", F::point, 0, 0, 1, C, true},
    {16, "Quadrilateral 8", F::quadrangle, 2, 2, 8, I, true},
    {17, "Hexahedron 20", F::hexahedron, 3, 2, 20, I, true},
    {18, "Prism 15", F::prism, 3, 2, 15, I, true},
    {19, "Pyramid 13", F::pyramid, 3, 2, 13, I, true},
    {20, "Triangle 9", F::triangle, 2, 3, 9, I, true},
    {21, "Triangle 10", F::triangle, 2, 3, 10, C, true},
    {22, "Triangle 12", F::triangle, 2, 4, 12, I, true},
    {23, "Triangle 15", F::triangle, 2, 4, 15, C, true},
    {24, "Triangle 15I", F::triangle, 2, 5, 15, I, true},
    {25, "Triangle 21", F::triangle, 2, 5, 21, C, true},
    {26, "Line 4", F::line, 1, 3, 4, C, true},
    {27, "Line 5", F::line, 1, 4, 5, C, true},
    {28, "Line 6", F::line, 1, 5, 6, C, true},
    {29, "Tetrahedron 20", F::tetrahedron, 3, 3, 20, C, true},
    {30, "Tetrahedron 35", F::tetrahedron, 3, 4, 35, C, true},
    {31, "Tetrahedron 56", F::tetrahedron, 3, 5, 56, C, true},
    {32, "Tetrahedron 22", F::tetrahedron, 3, 4, 22, I, true},
    {33, "Tetrahedron 28", F::tetrahedron, 3, 5, 28, I, true},
    {34, "Polygon", F::polygon, 2, 1, 0, C, false},
    {35, "Polyhedron", F::polyhedron, 3, 1, 0, C, false},
    {36, "Quadrilateral 16", F::quadrangle, 2, 3, 16, C, true},
    {37, "Quadrilateral 25", F::quadrangle, 2, 4, 25, C, true},
    {38, "Quadrilateral 36", F::quadrangle, 2, 5, 36, C, true},
    {39, "Quadrilateral 12", F::quadrangle, 2, 3, 12, I, true},
    {40, "Quadrilateral 16I", F::quadrangle, 2, 4, 16, I, true},
    {41, "Quadrilateral 20", F::quadrangle, 2, 5, 20, I, true},
    {42, "Triangle 28", F::triangle, 2, 6, 28, C, true},
    {43, "Triangle 36", F::triangle, 2, 7, 36, C, true},
    {44, "Triangle 45", F::triangle, 2, 8, 45, C, true},
    {45, "Triangle 55", F::triangle, 2, 9, 55, C, true},
    {46, "Triangle 66", F::triangle, 2, 10, 66, C, true},
    {47, "Quadrilateral 49", F::quadrangle, 2, 6, 49, C, true},
    {48, "Quadrilateral 64", F::quadrangle, 2, 7, 64, C, true},
    {49, "Quadrilateral 81", F::quadrangle, 2, 8, 81, C, true},
    {50, "Quadrilateral 100", F::quadrangle, 2, 9, 100, C, true},
    {51, "Quadrilateral 121", F::quadrangle, 2, 10, 121, C, true},
    {52, "Triangle 18", F::triangle, 2, 6, 18, I, true},
    {53, "Triangle 21I", F::triangle, 2, 7, 21, I, true},
    {54, "Triangle 24", F::triangle, 2, 8, 24, I, true},
    {55, "Triangle 27", F::triangle, 2, 9, 27, I, true},
    {56, "Triangle 30", F::triangle, 2, 10, 30, I, true},
    {57, "Quadrilateral 24", F::quadrangle, 2, 6, 24, I, true},
    {58, "Quadrilateral 28", F::quadrangle, 2, 7, 28, I, true},
    {59, "Quadrilateral 32", F::quadrangle, 2, 8, 32, I, true},
    {60, "Quadrilateral 36I", F::quadrangle, 2, 9, 36, I, true},
    {61, "Quadrilateral 40", F::quadrangle, 2, 10, 40, I, true},
    {62, "Line 7", F::line, 1, 6, 7, C, true},
    {63, "Line 8", F::line, 1, 7, 8, C, true},
    {64, "Line 9", F::line, 1, 8, 9, C, true},
    {65, "Line 10", F::line, 1, 9, 10, C, true},
    {66, "Line 11", F::line, 1, 10, 11, C, true},
    {67, "Line Border", F::line, 1, 1, 2, C, false},
    {68, "Triangle Border", F::triangle, 2, 1, 3, C, false},
    {69, "Polygon Border", F::polygon, 2, 1, 0, C, false},
    {70, "Line Child", F::line, 1, 1, 2, C, false},
    {71, "Tetrahedron 84", F::tetrahedron, 3, 6, 84, C, true},
    {72, "Tetrahedron 120", F::tetrahedron, 3, 7, 120, C, true},
    {73, "Tetrahedron 165", F::tetrahedron, 3, 8, 165, C, true},
    {74, "Tetrahedron 220", F::tetrahedron, 3, 9, 220, C, true},
    {75, "Tetrahedron 286", F::tetrahedron, 3, 10, 286, C, true},
    {79, "Tetrahedron 34", F::tetrahedron, 3, 6, 34, I, true},
    {80, "Tetrahedron 40", F::tetrahedron, 3, 7, 40, I, true},
    {81, "Tetrahedron 46", F::tetrahedron, 3, 8, 46, I, true},
    {82, "Tetrahedron 52", F::tetrahedron, 3, 9, 52, I, true},
    {83, "Tetrahedron 58", F::tetrahedron, 3, 10, 58, I, true},
    {84, "Line 1", F::line, 1, 0, 1, C, false},
    {85, "Triangle 1", F::triangle, 2, 0, 1, C, false},
    {86, "Quadrilateral 1", F::quadrangle, 2, 0, 1, C, false},
    {87, "Tetrahedron 1", F::tetrahedron, 3, 0, 1, C, false},
    {88, "Hexahedron 1", F::hexahedron, 3, 0, 1, C, false},
    {89, "Prism 1", F::prism, 3, 0, 1, C, false},
    {90, "Prism 40", F::prism, 3, 3, 40, C, true},
    {91, "Prism 75", F::prism, 3, 4, 75, C, true},
    {92, "Hexahedron 64", F::hexahedron, 3, 3, 64, C, true},
    {93, "Hexahedron 125", F::hexahedron, 3, 4, 125, C, true},
    {94, "Hexahedron 216", F::hexahedron, 3, 5, 216, C, true},
    {95, "Hexahedron 343", F::hexahedron, 3, 6, 343, C, true},
    {96, "Hexahedron 512", F::hexahedron, 3, 7, 512, C, true},
    {97, "Hexahedron 729", F::hexahedron, 3, 8, 729, C, true},
    {98, "Hexahedron 1000", F::hexahedron, 3, 9, 1000, C, true},
    {99, "Hexahedron 32", F::hexahedron, 3, 3, 32, I, true},
    {100, "Hexahedron 44", F::hexahedron, 3, 4, 44, I, true},
    {101, "Hexahedron 56", F::hexahedron, 3, 5, 56, I, true},
    {102, "Hexahedron 68", F::hexahedron, 3, 6, 68, I, true},
    {103, "Hexahedron 80", F::hexahedron, 3, 7, 80, I, true},
    {104, "Hexahedron 92", F::hexahedron, 3, 8, 92, I, true},
    {105, "Hexahedron 104", F::hexahedron, 3, 9, 104, I, true},
    {106, "Prism 126", F::prism, 3, 5, 126, C, true},
    {107, "Prism 196", F::prism, 3, 6, 196, C, true},
    {108, "Prism 288", F::prism, 3, 7, 288, C, true},
    {109, "Prism 405", F::prism, 3, 8, 405, C, true},
    {110, "Prism 550", F::prism, 3, 9, 550, C, true},
    {111, "Prism 24", F::prism, 3, 3, 24, I, true},
    {112, "Prism 33", F::prism, 3, 4, 33, I, true},
    {113, "Prism 42", F::prism, 3, 5, 42, I, true},
    {114, "Prism 51", F::prism, 3, 6, 51, I, true},
    {115, "Prism 60", F::prism, 3, 7, 60, I, true},
    {116, "Prism 69", F::prism, 3, 8, 69, I, true},
    {117, "Prism 78", F::prism, 3, 9, 78, I, true},
    {118, "Pyramid 30", F::pyramid, 3, 3, 30, C, true},
    {119, "Pyramid 55", F::pyramid, 3, 4, 55, C, true},
    {120, "Pyramid 91", F::pyramid, 3, 5, 91, C, true},
    {121, "Pyramid 140", F::pyramid, 3, 6, 140, C, true},
    {122, "Pyramid 204", F::pyramid, 3, 7, 204, C, true},
    {123, "Pyramid 285", F::pyramid, 3, 8, 285, C, true},
    {124, "Pyramid 385", F::pyramid, 3, 9, 385, C, true},
    {125, "Pyramid 21", F::pyramid, 3, 3, 21, I, true},
    {126, "Pyramid 29", F::pyramid, 3, 4, 29, I, true},
    {127, "Pyramid 37", F::pyramid, 3, 5, 37, I, true},
    {128, "Pyramid 45", F::pyramid, 3, 6, 45, I, true},
    {129, "Pyramid 53", F::pyramid, 3, 7, 53, I, true},
    {130, "Pyramid 61", F::pyramid, 3, 8, 61, I, true},
    {131, "Pyramid 69", F::pyramid, 3, 9, 69, I, true},
    {132, "Pyramid 1", F::pyramid, 3, 0, 1, C, false},
    {133, "Point Xfem", F::point, 0, 1, 1, C, false},
    {134, "Line Xfem", F::line, 1, 1, 2, C, false},
    {135, "Triangle Xfem", F::triangle, 2, 1, 3, C, false},
    {136, "Tetrahedron Xfem", F::tetrahedron, 3, 1, 4, C, false},
    {137, "Tetrahedron 16", F::tetrahedron, 3, 3, 16, I, true},
    {138, "Triangle Mini", F::triangle, 2, 1, 4, C, false},
    {139, "Tetrahedron Mini", F::tetrahedron, 3, 1, 5, C, false},
    {140, "Trihedron 4", F::trihedron, 3, 1, 4, C, false},
};

}  // namespace

std::span<const ElementType> element_types() noexcept { return kTypes; }

const ElementType* find_element_type(int gmsh_id) noexcept {
  auto it = std::lower_bound(std::begin(kTypes), std::end(kTypes), gmsh_id,
                             [](const ElementType& t, int id) { return t.gmsh_id < id; });
  return (it != std::end(kTypes) && it->gmsh_id == gmsh_id) ? &*it : nullptr;
}

namespace {

int family_num_edges(ElementFamily f) noexcept {
  switch (f) {
    case ElementFamily::line: return 1;
    case ElementFamily::triangle: return 3;
    case ElementFamily::quadrangle: return 4;
    case ElementFamily::tetrahedron: return 6;
    case ElementFamily::hexahedron: return 12;
    case ElementFamily::prism: return 9;
    case ElementFamily::pyramid: return 8;
    default: return 0;
  }
}

// True when every node is a vertex or an edge node (no face or interior node).
bool only_vertex_and_edge_nodes(const ElementType& t) noexcept {
  return t.num_nodes ==
         family_num_vertices(t.family) + family_num_edges(t.family) * std::max(t.order - 1, 0);
}

}  // namespace

const ElementType* find_element_type(ElementFamily family, int order, bool complete) noexcept {
  const ElementType* complete_type = nullptr;
  for (const ElementType& t : kTypes) {
    if (!t.has_lagrange_basis || t.family != family || t.order != order) continue;
    if (t.complete == complete) return &t;
    if (t.complete) complete_type = &t;
  }
  // A complete type without face or interior nodes (points, lines, order 1, order-2
  // triangles and tetrahedra) is also the incomplete one: Gmsh's
  // getElementType(family, order, serendip=True) answers the same id.
  if (!complete && complete_type && only_vertex_and_edge_nodes(*complete_type))
    return complete_type;
  return nullptr;
}

}  // namespace quadval
