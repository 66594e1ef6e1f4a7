// VTK node orders, derived from VTK's rules for its Lagrange cells (the ordering of
// vtkHigherOrder{Curve,Triangle,Quadrilateral,Tetra,Hexahedron,Wedge}, VTK >= 9.1, XML
// file version 2.2) and the edge lists of its quadratic cells, then matched to Gmsh's node
// order by reference coordinates.
#include "io/vtk_node_order.hpp"

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include <fmt/core.h>

#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval::io {

namespace {

using Lattice = std::array<int, 3>;  // VTK parametric coordinates times the order

Lattice add(Lattice a, Lattice b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

/// The points of edge a -> b strictly inside, from a to b.
void edge(std::vector<Lattice>& out, Lattice a, Lattice b, int p) {
  for (int i = 1; i < p; ++i)
    out.push_back({a[0] + i * (b[0] - a[0]) / p, a[1] + i * (b[1] - a[1]) / p, a[2] + i * (b[2] - a[2]) / p});
}

/// VTK Lagrange triangle of order p (p = 0: one point): vertices (0,0) (p,0) (0,p), edges
/// 0-1, 1-2, 2-0, then the interior as a triangle of order p - 3 shifted by (1,1).
std::vector<Lattice> triangle(int p) {
  if (p == 0) return {{0, 0, 0}};
  std::vector<Lattice> out = {{0, 0, 0}, {p, 0, 0}, {0, p, 0}};
  edge(out, out[0], out[1], p);
  edge(out, {p, 0, 0}, {0, p, 0}, p);
  edge(out, {0, p, 0}, {0, 0, 0}, p);
  if (p >= 3)
    for (const Lattice& q : triangle(p - 3)) out.push_back(add(q, {1, 1, 0}));
  return out;
}

/// VTK Lagrange tetrahedron: vertices, edges 0-1 1-2 2-0 0-3 1-3 2-3, faces (0,1,3)
/// (2,3,1) (0,3,2) (0,2,1) each as the interior triangle of order p - 3, then the interior
/// as a tetrahedron of order p - 4 shifted by (1,1,1).
std::vector<Lattice> tetrahedron(int p) {
  if (p == 0) return {{0, 0, 0}};
  const std::array<Lattice, 4> v = {{{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}}};
  std::vector<Lattice> out(v.begin(), v.end());
  const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& e : edges) edge(out, v[e[0]], v[e[1]], p);
  if (p >= 3) {
    const int faces[4][3] = {{0, 1, 3}, {2, 3, 1}, {0, 3, 2}, {0, 2, 1}};
    for (const auto& f : faces) {
      const Lattice a = v[f[0]], b = v[f[1]], c = v[f[2]];
      for (const Lattice& q : triangle(p - 3)) {
        Lattice x;
        for (int d = 0; d < 3; ++d) x[d] = a[d] + ((q[0] + 1) * (b[d] - a[d]) + (q[1] + 1) * (c[d] - a[d])) / p;
        out.push_back(x);
      }
    }
  }
  if (p >= 4)
    for (const Lattice& q : tetrahedron(p - 4)) out.push_back(add(q, {1, 1, 1}));
  return out;
}

/// VTK Lagrange quadrilateral: vertices counter-clockwise, edges along +x (y=0), +y (x=p),
/// +x (y=p), +y (x=0), then the interior with x fastest.
std::vector<Lattice> quadrangle(int p) {
  std::vector<Lattice> out = {{0, 0, 0}, {p, 0, 0}, {p, p, 0}, {0, p, 0}};
  edge(out, {0, 0, 0}, {p, 0, 0}, p);
  edge(out, {p, 0, 0}, {p, p, 0}, p);
  edge(out, {0, p, 0}, {p, p, 0}, p);
  edge(out, {0, 0, 0}, {0, p, 0}, p);
  for (int j = 1; j < p; ++j)
    for (int i = 1; i < p; ++i) out.push_back({i, j, 0});
  return out;
}

/// VTK Lagrange hexahedron: vertices, the bottom and top edges as in the quadrilateral,
/// the vertical edges at vertices 0, 1, 2, 3; faces x=0, x=p, y=0, y=p, z=0, z=p (lower
/// free axis fastest); then the interior with x fastest, z slowest.
std::vector<Lattice> hexahedron(int p) {
  std::vector<Lattice> out = {{0, 0, 0}, {p, 0, 0}, {p, p, 0}, {0, p, 0},
                              {0, 0, p}, {p, 0, p}, {p, p, p}, {0, p, p}};
  for (int z : {0, p}) {
    edge(out, {0, 0, z}, {p, 0, z}, p);
    edge(out, {p, 0, z}, {p, p, z}, p);
    edge(out, {0, p, z}, {p, p, z}, p);
    edge(out, {0, 0, z}, {0, p, z}, p);
  }
  for (const Lattice& c : {Lattice{0, 0, 0}, Lattice{p, 0, 0}, Lattice{p, p, 0}, Lattice{0, p, 0}})
    edge(out, c, {c[0], c[1], p}, p);
  for (int x : {0, p})
    for (int k = 1; k < p; ++k)
      for (int j = 1; j < p; ++j) out.push_back({x, j, k});
  for (int y : {0, p})
    for (int k = 1; k < p; ++k)
      for (int i = 1; i < p; ++i) out.push_back({i, y, k});
  for (int z : {0, p})
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) out.push_back({i, j, z});
  for (int k = 1; k < p; ++k)
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) out.push_back({i, j, k});
  return out;
}

/// VTK Lagrange wedge: vertices, bottom edges 0-1 1-2 2-0, top edges 3-4 4-5 5-3, vertical
/// edges 0-3 1-4 2-5; the bottom and top triangle faces (interior points, x fastest); the
/// quadrilateral faces on edges 0-1, 1-2, 2-0 (along the edge fastest, then up); then the
/// interior, layer by layer, each layer like a triangle face.
std::vector<Lattice> wedge(int p) {
  const std::array<Lattice, 3> b = {{{0, 0, 0}, {p, 0, 0}, {0, p, 0}}};
  std::vector<Lattice> out = {b[0], b[1], b[2], {0, 0, p}, {p, 0, p}, {0, p, p}};
  for (int z : {0, p})
    for (int e = 0; e < 3; ++e) edge(out, add(b[e], {0, 0, z}), add(b[(e + 1) % 3], {0, 0, z}), p);
  for (int e = 0; e < 3; ++e) edge(out, b[e], add(b[e], {0, 0, p}), p);
  auto layer = [&](int z) {
    for (int j = 1; j < p; ++j)
      for (int i = 1; i + j < p; ++i) out.push_back({i, j, z});
  };
  layer(0);
  layer(p);
  for (int e = 0; e < 3; ++e) {
    const Lattice a = b[e], c = b[(e + 1) % 3];
    for (int k = 1; k < p; ++k)
      for (int t = 1; t < p; ++t)
        out.push_back({a[0] + t * (c[0] - a[0]) / p, a[1] + t * (c[1] - a[1]) / p, k});
  }
  for (int k = 1; k < p; ++k) layer(k);
  return out;
}

/// Gmsh vertex indices spanning each lattice axis from vertex 0 (VTK's vertex order equals
/// Gmsh's for every family).
std::vector<int> lattice_axes(ElementFamily f) {
  switch (f) {
    case ElementFamily::line: return {1};
    case ElementFamily::triangle: return {1, 2};
    case ElementFamily::quadrangle: return {1, 3};
    case ElementFamily::tetrahedron: return {1, 2, 3};
    case ElementFamily::hexahedron: return {1, 3, 4};
    case ElementFamily::prism: return {1, 2, 3};
    default: return {};
  }
}

/// For each wanted reference point, the Gmsh node at that position.
std::vector<int> match_nodes(const ElementType& type, const std::vector<RefPoint>& wanted) {
  const std::span<const RefPoint> nodes = reference_nodes(type);
  std::vector<int> out;
  std::vector<bool> used(nodes.size(), false);
  for (const RefPoint& w : wanted) {
    int found = -1;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const double d = std::abs(nodes[i][0] - w[0]) + std::abs(nodes[i][1] - w[1]) + std::abs(nodes[i][2] - w[2]);
      if (d < 1e-9) {
        QV_ASSERT(found < 0, type.name << ": two nodes at one VTK point");
        found = static_cast<int>(i);
      }
    }
    QV_ASSERT(found >= 0, type.name << ": no Gmsh node at VTK point (" << w[0] << ", " << w[1] << ", " << w[2] << ")");
    QV_ASSERT(!used[static_cast<std::size_t>(found)], type.name << ": Gmsh node " << found << " used twice");
    used[static_cast<std::size_t>(found)] = true;
    out.push_back(found);
  }
  return out;
}

/// Lagrange cell of a complete type: VTK lattice points mapped onto Gmsh's reference element.
std::vector<int> lagrange_order(const ElementType& type) {
  const int p = type.order;
  std::vector<Lattice> lattice;
  switch (type.family) {
    case ElementFamily::line: {
      lattice = {{0, 0, 0}, {p, 0, 0}};
      edge(lattice, {0, 0, 0}, {p, 0, 0}, p);
      break;
    }
    case ElementFamily::triangle: lattice = triangle(p); break;
    case ElementFamily::quadrangle: lattice = quadrangle(p); break;
    case ElementFamily::tetrahedron: lattice = tetrahedron(p); break;
    case ElementFamily::hexahedron: lattice = hexahedron(p); break;
    case ElementFamily::prism: lattice = wedge(p); break;
    default: QV_ASSERT(false, "no VTK Lagrange cell for " << type.name);
  }
  QV_ASSERT(static_cast<int>(lattice.size()) == type.num_nodes,
            type.name << ": VTK rules give " << lattice.size() << " points");
  const std::span<const RefPoint> ref = reference_nodes(type);
  const std::vector<int> axes = lattice_axes(type.family);
  std::vector<RefPoint> wanted;
  for (const Lattice& l : lattice) {
    RefPoint x = ref[0];
    for (std::size_t a = 0; a < axes.size(); ++a)
      for (int d = 0; d < 3; ++d)
        x[static_cast<std::size_t>(d)] += (static_cast<double>(l[a]) / p) * (ref[static_cast<std::size_t>(axes[a])][static_cast<std::size_t>(d)] - ref[0][static_cast<std::size_t>(d)]);
    wanted.push_back(x);
  }
  return match_nodes(type, wanted);
}

/// VTK quadratic (serendipity) cell: vertices, then the midpoints of these vertex pairs.
std::vector<int> quadratic_order(const ElementType& type, int num_vertices,
                                 const std::vector<std::array<int, 2>>& edges) {
  const std::span<const RefPoint> ref = reference_nodes(type);
  std::vector<RefPoint> wanted(ref.begin(), ref.begin() + num_vertices);
  for (const auto& e : edges) {
    RefPoint m;
    for (std::size_t d = 0; d < 3; ++d) m[d] = 0.5 * (ref[static_cast<std::size_t>(e[0])][d] + ref[static_cast<std::size_t>(e[1])][d]);
    wanted.push_back(m);
  }
  return match_nodes(type, wanted);
}

int linear_vtk_type(ElementFamily f) {
  switch (f) {
    case ElementFamily::point: return 1;
    case ElementFamily::line: return 3;
    case ElementFamily::triangle: return 5;
    case ElementFamily::quadrangle: return 9;
    case ElementFamily::tetrahedron: return 10;
    case ElementFamily::hexahedron: return 12;
    case ElementFamily::prism: return 13;
    case ElementFamily::pyramid: return 14;
    default: return 0;
  }
}

const std::vector<std::array<int, 2>> kQuadEdges = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
const std::vector<std::array<int, 2>> kHexEdges = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                                   {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
const std::vector<std::array<int, 2>> kWedgeEdges = {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5},
                                                     {5, 3}, {0, 3}, {1, 4}, {2, 5}};
const std::vector<std::array<int, 2>> kPyramidEdges = {{0, 1}, {1, 2}, {2, 3}, {3, 0},
                                                       {0, 4}, {1, 4}, {2, 4}, {3, 4}};

VtkCell build(const ElementType& type) {
  VtkCell cell;
  const int corners = family_num_vertices(type.family);
  const int linear = linear_vtk_type(type.family);
  if (type.has_lagrange_basis && type.family == ElementFamily::point) {
    cell.vtk_type = 1;
    cell.gmsh_node = {0};
  } else if (type.has_lagrange_basis && type.order == 1) {
    cell.vtk_type = linear;
    cell.gmsh_node = quadratic_order(type, corners, {});
  } else if (type.has_lagrange_basis && type.complete && type.family != ElementFamily::pyramid) {
    cell.vtk_type = 67 + static_cast<int>(type.family);  // 68 line ... 73 wedge
    static_assert(static_cast<int>(ElementFamily::line) == 1 && static_cast<int>(ElementFamily::prism) == 6);
    cell.gmsh_node = lagrange_order(type);
  } else if (type.has_lagrange_basis && type.order == 2 && type.family == ElementFamily::quadrangle) {
    cell.vtk_type = 23;
    cell.gmsh_node = quadratic_order(type, 4, kQuadEdges);
  } else if (type.has_lagrange_basis && type.order == 2 && type.family == ElementFamily::hexahedron) {
    cell.vtk_type = 25;
    cell.gmsh_node = quadratic_order(type, 8, kHexEdges);
  } else if (type.has_lagrange_basis && type.order == 2 && type.family == ElementFamily::prism) {
    cell.vtk_type = 26;
    cell.gmsh_node = quadratic_order(type, 6, kWedgeEdges);
  } else if (type.has_lagrange_basis && type.order == 2 && type.family == ElementFamily::pyramid) {
    cell.vtk_type = 27;
    cell.gmsh_node = quadratic_order(type, 5, kPyramidEdges);
    if (type.complete) {
      cell.exact = false;
      cell.note = "VTK_QUADRATIC_PYRAMID without the base centre node (VTK has no Lagrange pyramid)";
    }
  } else if (linear != 0 && type.num_nodes >= corners && corners > 0) {
    cell.vtk_type = linear;
    for (int i = 0; i < corners; ++i) cell.gmsh_node.push_back(i);
    cell.exact = false;
    cell.note = "its corner-only linear cell (VTK has no such cell)";
  } else {
    cell.vtk_type = 2;  // VTK_POLY_VERTEX
    for (int i = 0; i < type.num_nodes; ++i) cell.gmsh_node.push_back(i);
    cell.exact = false;
    cell.note = "a VTK_POLY_VERTEX of its nodes (VTK has no such cell)";
  }
  return cell;
}

}  // namespace

const VtkCell& vtk_cell(const ElementType& type) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<const VtkCell>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[type.gmsh_id];
  if (!slot) slot = std::make_unique<const VtkCell>(build(type));
  return *slot;
}

}  // namespace quadval::io
