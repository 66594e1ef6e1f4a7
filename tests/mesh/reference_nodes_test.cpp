// Reference elements and node positions: against Gmsh 4.8.4's own answers (recorded by
// scripts/make_gmsh_reference_data.py) and against closed forms (lattices, planes).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mesh/lagrange_test_data.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using F = ElementFamily;

using testing_data::lagrange_types;

double distance(const RefPoint& a, const RefPoint& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Every point of the order-p lattice of a family, written from its closed form.
std::vector<RefPoint> lattice(F f, int p) {
  std::vector<RefPoint> out;
  const double q = p;
  switch (f) {
    case F::point: out.push_back({0, 0, 0}); break;
    case F::line:
      for (int i = 0; i <= p; ++i) out.push_back({-1 + 2 * i / q, 0, 0});
      break;
    case F::triangle:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j) out.push_back({i / q, j / q, 0});
      break;
    case F::quadrangle:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; j <= p; ++j) out.push_back({-1 + 2 * i / q, -1 + 2 * j / q, 0});
      break;
    case F::tetrahedron:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
          for (int k = 0; i + j + k <= p; ++k) out.push_back({i / q, j / q, k / q});
      break;
    case F::hexahedron:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; j <= p; ++j)
          for (int k = 0; k <= p; ++k)
            out.push_back({-1 + 2 * i / q, -1 + 2 * j / q, -1 + 2 * k / q});
      break;
    case F::prism:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
          for (int k = 0; k <= p; ++k) out.push_back({i / q, j / q, -1 + 2 * k / q});
      break;
    case F::pyramid:  // level k: a (p-k+1)^2 grid of spacing 2/p on [-(1-z), 1-z]^2
      for (int k = 0; k <= p; ++k)
        for (int i = 0; i <= p - k; ++i)
          for (int j = 0; j <= p - k; ++j)
            out.push_back({-(1 - k / q) + 2 * i / q, -(1 - k / q) + 2 * j / q, k / q});
      break;
    default: break;
  }
  return out;
}

bool strictly_inside(F f, const RefPoint& x) {
  const double e = 1e-12;
  switch (f) {
    case F::line: return std::abs(x[0]) < 1 - e;
    case F::triangle: return x[0] > e && x[1] > e && x[0] + x[1] < 1 - e;
    case F::quadrangle: return std::abs(x[0]) < 1 - e && std::abs(x[1]) < 1 - e;
    case F::tetrahedron: return x[0] > e && x[1] > e && x[2] > e && x[0] + x[1] + x[2] < 1 - e;
    case F::hexahedron:
      return std::abs(x[0]) < 1 - e && std::abs(x[1]) < 1 - e && std::abs(x[2]) < 1 - e;
    case F::prism:
      return x[0] > e && x[1] > e && x[0] + x[1] < 1 - e && std::abs(x[2]) < 1 - e;
    case F::pyramid:
      return x[2] > e && std::abs(x[0]) < 1 - x[2] - e && std::abs(x[1]) < 1 - x[2] - e;
    default: return false;
  }
}

// (s, t) with x = a + s (b - a) + t (c - a), and the distance of x from that plane.
struct PlaneCoords { double s, t, off_plane; };
PlaneCoords plane_coords(const RefPoint& a, const RefPoint& b, const RefPoint& c,
                         const RefPoint& x) {
  double u[3], v[3], w[3];
  for (int d = 0; d < 3; ++d) u[d] = b[d] - a[d], v[d] = c[d] - a[d], w[d] = x[d] - a[d];
  auto dot = [](const double* p, const double* q) { return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]; };
  const double uu = dot(u, u), uv = dot(u, v), vv = dot(v, v), wu = dot(w, u), wv = dot(w, v);
  const double det = uu * vv - uv * uv;
  const double s = (wu * vv - wv * uv) / det, t = (wv * uu - wu * uv) / det;
  double r = 0;
  for (int d = 0; d < 3; ++d) r += std::pow(w[d] - s * u[d] - t * v[d], 2);
  return {s, t, std::sqrt(r)};
}

TEST(ReferenceNodes, MatchGmshForEveryTypeGmshCanBuild) {
  const auto& ref = testing_data::gmsh_reference();
  EXPECT_EQ(ref.gmsh_version, "4.8.4");
  int compared = 0, prisms_gmsh_cannot_build = 0;
  for (const ElementType* t : lagrange_types()) {
    SCOPED_TRACE(std::string(t->name));
    const auto it = ref.types.find(t->gmsh_id);
    if (it == ref.types.end()) {
      // The only Lagrange types Gmsh 4.8.4 cannot build: prisms of order >= 3.
      ASSERT_TRUE(ref.rejected.count(t->gmsh_id));
      EXPECT_EQ(t->family, F::prism);
      EXPECT_GE(t->order, 3);
      EXPECT_NE(ref.rejected.at(t->gmsh_id).find("FaceClosureFull not implemented for prisms"),
                std::string::npos);
      ++prisms_gmsh_cannot_build;
      continue;
    }
    const auto& g = it->second;
    EXPECT_EQ(g.name, t->name);
    EXPECT_EQ(g.dim, t->dim);
    EXPECT_EQ(g.order, t->order);
    ASSERT_EQ(g.num_nodes, t->num_nodes);
    const auto nodes = reference_nodes(*t);
    ASSERT_EQ(static_cast<int>(nodes.size()), g.num_nodes);
    for (int i = 0; i < g.num_nodes; ++i)
      EXPECT_LT(distance(nodes[i], g.nodes[i]), 1e-14) << "node " << i;
    ++compared;
  }
  EXPECT_EQ(prisms_gmsh_cannot_build, 14);  // 90, 91, 106-117
  EXPECT_EQ(compared, static_cast<int>(lagrange_types().size()) - 14);
}

TEST(ReferenceNodes, CompleteTypesHoldEveryLatticePointOnce) {
  for (const ElementType* t : lagrange_types()) {
    if (!t->complete) continue;
    SCOPED_TRACE(std::string(t->name));
    const auto nodes = reference_nodes(*t);
    const auto want = lattice(t->family, t->order);
    ASSERT_EQ(nodes.size(), want.size());
    std::vector<int> hits(want.size(), 0);
    for (const RefPoint& x : nodes)
      for (std::size_t k = 0; k < want.size(); ++k)
        if (distance(x, want[k]) < 1e-12) ++hits[k];
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_EQ(hits[k], 1) << "lattice point " << k;
  }
}

TEST(ReferenceNodes, IncompleteTypesAreTheVertexAndEdgeNodesOfTheCompleteType) {
  for (const ElementType* t : lagrange_types()) {
    if (t->complete) continue;
    SCOPED_TRACE(std::string(t->name));
    const ElementType* full = find_element_type(t->family, t->order, true);
    ASSERT_NE(full, nullptr);
    const auto a = reference_nodes(*t), b = reference_nodes(*full);
    const auto edges = reference_edges(t->family);
    ASSERT_EQ(a.size(), reference_vertices(t->family).size() + edges.size() * (t->order - 1));
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << "node " << i;
  }
}

TEST(ReferenceNodes, VerticesEdgesFacesAndInteriorAreWhereTheLayoutSays) {
  for (const ElementType* t : lagrange_types()) {
    SCOPED_TRACE(std::string(t->name));
    const auto nodes = reference_nodes(*t);
    const auto v = reference_vertices(t->family);
    const NodeLayout layout = node_layout(*t);
    const int p = t->order;
    ASSERT_EQ(layout.num_nodes, t->num_nodes);
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(nodes[i], v[i]);
    if (t->family == F::line) {  // inner points left to right
      for (int i = 1; i < p; ++i) EXPECT_NEAR(nodes[1 + i][0], -1 + 2.0 * i / p, 1e-15);
      continue;
    }
    const auto edges = reference_edges(t->family);
    for (std::size_t e = 0; e < edges.size(); ++e)
      for (int i = 1; i < p; ++i) {
        const RefPoint& a = v[edges[e][0]];
        const RefPoint& b = v[edges[e][1]];
        const RefPoint& x = nodes[layout.edge_begin + e * layout.nodes_per_edge + i - 1];
        for (int d = 0; d < 3; ++d) EXPECT_NEAR(x[d], a[d] + (b[d] - a[d]) * i / p, 1e-15);
      }
    const auto faces = reference_faces(t->family);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const ReferenceFace& face = faces[f];
      const int count = layout.face_begin[f + 1] - layout.face_begin[f];
      const int want = !t->complete ? 0
                       : face.num_vertices == 3 ? (p - 1) * (p - 2) / 2
                                                : (p - 1) * (p - 1);
      EXPECT_EQ(count, want) << "face " << f;
      const RefPoint& a = v[face.vertices[0]];
      const RefPoint& b = v[face.vertices[1]];
      const RefPoint& c = v[face.vertices[face.num_vertices == 3 ? 2 : 3]];
      for (int k = layout.face_begin[f]; k < layout.face_begin[f + 1]; ++k) {
        const PlaneCoords pc = plane_coords(a, b, c, nodes[k]);
        EXPECT_LT(pc.off_plane, 1e-14) << "node " << k;
        EXPECT_GT(pc.s, 1e-12);
        EXPECT_GT(pc.t, 1e-12);
        if (face.num_vertices == 3) {
          EXPECT_LT(pc.s + pc.t, 1 - 1e-12);
        } else {
          EXPECT_TRUE(pc.s < 1 - 1e-12 && pc.t < 1 - 1e-12);
        }
      }
    }
    if (t->family == F::point) continue;
    for (int k = layout.interior_begin; k < layout.num_nodes; ++k)
      EXPECT_TRUE(strictly_inside(t->family, nodes[k])) << "node " << k;
  }
}

TEST(ReferenceNodes, FacesAreOutwardAndBoundedByEdges) {
  for (F f : {F::tetrahedron, F::hexahedron, F::prism, F::pyramid}) {
    SCOPED_TRACE(std::string(family_name(f)));
    const auto v = reference_vertices(f);
    const auto edges = reference_edges(f);
    RefPoint centre{0, 0, 0};
    for (const RefPoint& x : v)
      for (int d = 0; d < 3; ++d) centre[d] += x[d] / v.size();
    for (const ReferenceFace& face : reference_faces(f)) {
      const RefPoint& a = v[face.vertices[0]];
      const RefPoint& b = v[face.vertices[1]];
      const RefPoint& c = v[face.vertices[2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                           u[0] * w[1] - u[1] * w[0]};
      EXPECT_GT(n[0] * (a[0] - centre[0]) + n[1] * (a[1] - centre[1]) + n[2] * (a[2] - centre[2]),
                0);
      for (int i = 0; i < face.num_vertices; ++i) {
        const int p = face.vertices[i], q = face.vertices[(i + 1) % face.num_vertices];
        int found = 0;
        for (const auto& e : edges) found += (e[0] == p && e[1] == q) || (e[0] == q && e[1] == p);
        EXPECT_EQ(found, 1) << p << "-" << q;
      }
    }
  }
}

// Prism 40, which Gmsh 4.8.4 cannot build: face and interior nodes derived by hand from
// the convention in lagrange_basis.hpp.
TEST(ReferenceNodes, Prism40FaceAndInteriorNodesFollowTheDocumentedConvention) {
  const double a = 1.0 / 3, b = 2.0 / 3;
  const RefPoint want[] = {
      {a, a, -1}, {a, a, 1},                                   // triangles (0,2,1), (3,4,5)
      {a, 0, -a}, {b, 0, -a}, {b, 0, a}, {a, 0, a},            // quad (0,1,4,3)
      {0, a, -a}, {0, a, a},  {0, b, a}, {0, b, -a},           // quad (0,3,5,2)
      {b, a, -a}, {a, b, -a}, {a, b, a}, {b, a, a},            // quad (1,2,5,4)
      {a, a, -a}, {a, a, a}};                                  // interior
  const auto nodes = reference_nodes(*find_element_type(90));
  ASSERT_EQ(nodes.size(), 40u);
  for (int i = 0; i < 16; ++i) EXPECT_LT(distance(nodes[24 + i], want[i]), 1e-15) << 24 + i;
  const NodeLayout layout = node_layout(*find_element_type(90));
  EXPECT_EQ(layout.edge_begin, 6);
  EXPECT_EQ(layout.nodes_per_edge, 2);
  const int face_begin[] = {24, 25, 26, 30, 34, 38};
  for (int f = 0; f < 6; ++f) EXPECT_EQ(layout.face_begin[f], face_begin[f]);
  EXPECT_EQ(layout.interior_begin, 38);
}

TEST(ReferenceNodes, Prism75InteriorIsLineOuterTriangleInner) {
  // Order 4: triangle interior (order-1 triangle at 1/4..1/2) at w = -1/2, 1/2, then 0.
  const auto nodes = reference_nodes(*find_element_type(91));
  const NodeLayout layout = node_layout(*find_element_type(91));
  ASSERT_EQ(layout.num_nodes - layout.interior_begin, 9);
  const RefPoint tri[] = {{0.25, 0.25, 0}, {0.5, 0.25, 0}, {0.25, 0.5, 0}};
  const double w[] = {-0.5, 0.5, 0.0};
  for (int l = 0; l < 3; ++l)
    for (int k = 0; k < 3; ++k)
      EXPECT_LT(distance(nodes[layout.interior_begin + 3 * l + k], {tri[k][0], tri[k][1], w[l]}),
                1e-15);
}

TEST(ReferenceNodes, TypesWithoutLagrangeBasisAreRejected) {
  for (int id : {34, 67, 84, 133, 138, 140}) {
    const ElementType* t = find_element_type(id);
    ASSERT_NE(t, nullptr);
    EXPECT_THROW(reference_nodes(*t), std::invalid_argument) << id;
    EXPECT_THROW(node_layout(*t), std::invalid_argument) << id;
  }
  EXPECT_TRUE(reference_vertices(F::polygon).empty());
  EXPECT_TRUE(reference_faces(F::quadrangle).empty());
}

TEST(ReferenceNodes, SpansStayValidAndAreSharedAcrossCalls) {
  const ElementType& t = *find_element_type(12);
  EXPECT_EQ(reference_nodes(t).data(), reference_nodes(t).data());
}

}  // namespace
}  // namespace quadval
