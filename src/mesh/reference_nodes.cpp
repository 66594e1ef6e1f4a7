// Reference elements (vertices, edges, faces) and node positions in Gmsh order.
// The recursive layout is described in include/quadval/lagrange_basis.hpp.
#include <array>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using F = ElementFamily;

// Vertices, edges and faces as Gmsh numbers them (checked against
// gmsh.model.mesh.getElementProperties / getElementEdgeNodes / getElementFaceNodes).
constexpr RefPoint kPointV[] = {{0, 0, 0}};
constexpr RefPoint kLineV[] = {{-1, 0, 0}, {1, 0, 0}};
constexpr RefPoint kTriV[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
constexpr RefPoint kQuadV[] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
constexpr RefPoint kTetV[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
constexpr RefPoint kHexV[] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
constexpr RefPoint kPrismV[] = {{0, 0, -1}, {1, 0, -1}, {0, 1, -1},
                                {0, 0, 1},  {1, 0, 1},  {0, 1, 1}};
constexpr RefPoint kPyrV[] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}};

using Edge = std::array<int, 2>;
constexpr Edge kLineE[] = {{0, 1}};
constexpr Edge kTriE[] = {{0, 1}, {1, 2}, {2, 0}};
constexpr Edge kQuadE[] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
constexpr Edge kTetE[] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
constexpr Edge kHexE[] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                          {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
constexpr Edge kPrismE[] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4},
                            {2, 5}, {3, 4}, {3, 5}, {4, 5}};
constexpr Edge kPyrE[] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 4}, {2, 3}, {2, 4}, {3, 4}};

constexpr ReferenceFace kTetF[] = {
    {3, {0, 2, 1, -1}}, {3, {0, 1, 3, -1}}, {3, {0, 3, 2, -1}}, {3, {3, 1, 2, -1}}};
constexpr ReferenceFace kHexF[] = {{4, {0, 3, 2, 1}}, {4, {0, 1, 5, 4}}, {4, {0, 4, 7, 3}},
                                   {4, {1, 2, 6, 5}}, {4, {2, 3, 7, 6}}, {4, {4, 5, 6, 7}}};
constexpr ReferenceFace kPrismF[] = {{3, {0, 2, 1, -1}}, {3, {3, 4, 5, -1}}, {4, {0, 1, 4, 3}},
                                     {4, {0, 3, 5, 2}},  {4, {1, 2, 5, 4}}};
constexpr ReferenceFace kPyrF[] = {{3, {0, 1, 4, -1}}, {3, {3, 0, 4, -1}}, {3, {1, 2, 4, -1}},
                                   {3, {2, 3, 4, -1}}, {4, {0, 3, 2, 1}}};

using Nodes = std::vector<RefPoint>;

RefPoint centroid(ElementFamily f) {
  RefPoint c{0, 0, 0};
  const auto v = reference_vertices(f);
  for (const RefPoint& p : v)
    for (int d = 0; d < 3; ++d) c[d] += p[d] / static_cast<double>(v.size());
  return c;
}

Nodes make_nodes(ElementFamily f, int p, bool complete);

// The order-p element's nodes strictly inside it (for 2D and 3D families; for the line,
// its inner points). Each is a lower-order element of the same family, scaled (thesis-free:
// this is Gmsh's recursive layout, see lagrange_basis.hpp).
Nodes interior_nodes(ElementFamily f, int p) {
  Nodes out;
  const double inv = 1.0 / p;
  auto shrink = [&](ElementFamily g, int q, double s, RefPoint shift) {
    for (const RefPoint& x : make_nodes(g, q, true))
      out.push_back({shift[0] + s * x[0], shift[1] + s * x[1], shift[2] + s * x[2]});
  };
  switch (f) {
    case F::line:
      for (int i = 1; i < p; ++i) out.push_back({-1.0 + 2.0 * i * inv, 0, 0});
      break;
    case F::triangle:
      if (p >= 3) shrink(F::triangle, p - 3, (p - 3) * inv, {inv, inv, 0});
      break;
    case F::quadrangle:
      if (p >= 2) shrink(F::quadrangle, p - 2, (p - 2) * inv, {0, 0, 0});
      break;
    case F::tetrahedron:
      if (p >= 4) shrink(F::tetrahedron, p - 4, (p - 4) * inv, {inv, inv, inv});
      break;
    case F::hexahedron:
      if (p >= 2) shrink(F::hexahedron, p - 2, (p - 2) * inv, {0, 0, 0});
      break;
    case F::pyramid:
      if (p >= 3) shrink(F::pyramid, p - 3, (p - 3) * inv, {0, 0, inv});
      break;
    case F::prism: {
      if (p < 3) break;
      // quadval's convention (Gmsh 4.8.4 has none): line index outer, triangle inner.
      const Nodes tri = interior_nodes(F::triangle, p);
      const double s = (p - 2) * inv;
      for (const RefPoint& w : make_nodes(F::line, p - 2, true))
        for (const RefPoint& uv : tri) out.push_back({uv[0], uv[1], s * w[0]});
      break;
    }
    default:
      QV_ASSERT(false, "no interior nodes for family " << family_name(f));
  }
  return out;
}

// Nodes of a triangle or quadrangle face of an order-p element, in the face's own order.
void append_face_nodes(const ReferenceFace& face, std::span<const RefPoint> v, int p,
                       Nodes& out) {
  const RefPoint& a = v[face.vertices[0]];
  const RefPoint& b = v[face.vertices[1]];
  const RefPoint& c = v[face.vertices[2]];
  if (face.num_vertices == 3) {
    for (const RefPoint& uv : interior_nodes(F::triangle, p)) {
      RefPoint x;
      for (int d = 0; d < 3; ++d) x[d] = a[d] + uv[0] * (b[d] - a[d]) + uv[1] * (c[d] - a[d]);
      out.push_back(x);
    }
    return;
  }
  const RefPoint& e = v[face.vertices[3]];
  for (const RefPoint& uv : interior_nodes(F::quadrangle, p)) {
    const double u0 = 0.5 * (1 - uv[0]), u1 = 0.5 * (1 + uv[0]);
    const double v0 = 0.5 * (1 - uv[1]), v1 = 0.5 * (1 + uv[1]);
    RefPoint x;
    for (int d = 0; d < 3; ++d)
      x[d] = u0 * v0 * a[d] + u1 * v0 * b[d] + u1 * v1 * c[d] + u0 * v1 * e[d];
    out.push_back(x);
  }
}

Nodes make_nodes(ElementFamily f, int p, bool complete) {
  if (p == 0) return {centroid(f)};  // order 0: one node, used by the recursion
  const auto v = reference_vertices(f);
  Nodes out(v.begin(), v.end());
  if (f == F::point) return out;
  if (f == F::line) {
    const Nodes inner = interior_nodes(f, p);
    out.insert(out.end(), inner.begin(), inner.end());
    return out;
  }
  for (const Edge& e : reference_edges(f)) {
    const RefPoint& a = v[e[0]];
    const RefPoint& b = v[e[1]];
    for (int i = 1; i < p; ++i) {
      const double t = static_cast<double>(i) / p;
      out.push_back({a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])});
    }
  }
  if (!complete) return out;
  for (const ReferenceFace& face : reference_faces(f)) append_face_nodes(face, v, p, out);
  const Nodes inner = interior_nodes(f, p);
  out.insert(out.end(), inner.begin(), inner.end());
  return out;
}

void require_lagrange(const ElementType& type) {
  if (!type.has_lagrange_basis)
    throw std::invalid_argument("element type " + std::to_string(type.gmsh_id) + " (" +
                                std::string(type.name) + ") has no Lagrange basis");
}

}  // namespace

std::span<const RefPoint> reference_vertices(ElementFamily f) noexcept {
  switch (f) {
    case F::point: return kPointV;
    case F::line: return kLineV;
    case F::triangle: return kTriV;
    case F::quadrangle: return kQuadV;
    case F::tetrahedron: return kTetV;
    case F::hexahedron: return kHexV;
    case F::prism: return kPrismV;
    case F::pyramid: return kPyrV;
    default: return {};
  }
}

std::span<const std::array<int, 2>> reference_edges(ElementFamily f) noexcept {
  switch (f) {
    case F::line: return kLineE;
    case F::triangle: return kTriE;
    case F::quadrangle: return kQuadE;
    case F::tetrahedron: return kTetE;
    case F::hexahedron: return kHexE;
    case F::prism: return kPrismE;
    case F::pyramid: return kPyrE;
    default: return {};
  }
}

std::span<const ReferenceFace> reference_faces(ElementFamily f) noexcept {
  switch (f) {
    case F::tetrahedron: return kTetF;
    case F::hexahedron: return kHexF;
    case F::prism: return kPrismF;
    case F::pyramid: return kPyrF;
    default: return {};
  }
}

NodeLayout node_layout(const ElementType& type) {
  require_lagrange(type);
  const int p = type.order;
  NodeLayout layout;
  layout.num_nodes = type.num_nodes;
  layout.nodes_per_edge = p >= 1 ? p - 1 : 0;
  layout.edge_begin = static_cast<int>(reference_vertices(type.family).size());
  int next = layout.edge_begin +
             layout.nodes_per_edge * static_cast<int>(reference_edges(type.family).size());
  if (type.family == F::line) next = layout.num_nodes;  // inner points are the edge nodes
  const auto faces = reference_faces(type.family);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    layout.face_begin[i] = next;
    if (type.complete) {
      const int inner = faces[i].num_vertices == 3 ? (p - 1) * (p - 2) / 2 : (p - 1) * (p - 1);
      next += inner;
    }
  }
  layout.face_begin[faces.size()] = next;
  layout.interior_begin = type.complete ? next : layout.num_nodes;
  QV_ASSERT(!type.complete || type.family == F::point || type.family == F::line ||
                layout.num_nodes - layout.interior_begin ==
                    static_cast<int>(interior_nodes(type.family, p).size()),
            type.name);
  return layout;
}

std::span<const RefPoint> reference_nodes(const ElementType& type) {
  require_lagrange(type);
  // One slot per Gmsh id (1..140), each built once under its own once_flag.
  static std::array<std::once_flag, 141> once;
  static std::array<std::unique_ptr<const Nodes>, 141> cache;
  const int id = type.gmsh_id;
  const ElementType* registered = find_element_type(id);
  QV_ASSERT(registered && registered->family == type.family && registered->order == type.order &&
                registered->num_nodes == type.num_nodes,
            "type " << id << " is not the registry's");
  std::call_once(once[id], [&] {
    auto nodes = std::make_unique<Nodes>(make_nodes(type.family, type.order, type.complete));
    QV_ASSERT(static_cast<int>(nodes->size()) == type.num_nodes,
              type.name << ": made " << nodes->size() << " nodes");
    cache[id] = std::move(nodes);
  });
  return *cache[id];
}

}  // namespace quadval
