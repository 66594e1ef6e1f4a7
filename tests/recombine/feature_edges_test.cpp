// Surfaces in 3D: a triangulated cube given as one surface (as an STL is) keeps its shape
// through recombination (feature_edges.hpp), the odd pieces of a closed surface cut at its
// features are made even in pairs (make_regions_even), and the nodes of a sphere stay on it
// (surface_projection.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "quadval/recombine.hpp"
#include "recombine/feature_edges.hpp"
#include "recombine/test_meshes.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval {
namespace {

using test::make_triangle_mesh_3d;

// The surface of the unit cube, k segments per edge, each face cell cut along a diagonal
// (alternating), outward; the nodes inside a face jittered within it. With `odd_faces`, the
// first segment of the edge y = z = 0 gets a midpoint node and its two triangles are split
// there: the faces y = 0 and z = 0 then hold an odd number of triangles each.
Mesh cube_surface(int k, unsigned seed, bool odd_faces) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  std::vector<std::array<double, 3>> xyz;
  std::map<std::array<int, 3>, NodeIndex> index;
  const auto node = [&](std::array<int, 3> p) {
    auto [it, inserted] = index.emplace(p, static_cast<NodeIndex>(xyz.size()));
    if (inserted) xyz.push_back({double(p[0]) / k, double(p[1]) / k, double(p[2]) / k});
    return it->second;
  };
  std::vector<std::array<NodeIndex, 3>> tris;
  for (int a = 0; a < 3; ++a)
    for (int side : {0, k}) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int u = 0; u < k; ++u)
        for (int v = 0; v < k; ++v) {
          std::array<NodeIndex, 4> q;
          const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int i = 0; i < 4; ++i) {
            std::array<int, 3> p{};
            p[a] = side;
            p[b] = u + du[i];
            p[c] = v + dv[i];
            q[i] = node(p);
          }
          if (side == 0) std::swap(q[1], q[3]);  // outward: -e_a
          if ((u + v) % 2 == 0) {
            tris.push_back({q[0], q[1], q[2]});
            tris.push_back({q[0], q[2], q[3]});
          } else {
            tris.push_back({q[0], q[1], q[3]});
            tris.push_back({q[1], q[2], q[3]});
          }
        }
    }
  for (const auto& [p, i] : index) {
    const int on_sides = (p[0] % k == 0) + (p[1] % k == 0) + (p[2] % k == 0);
    if (on_sides != 1) continue;  // on a cube edge or corner: stays
    for (int d = 0; d < 3; ++d)
      if (p[d] % k != 0) xyz[i][d] += jitter(rng) / k;
  }
  if (odd_faces) {
    const NodeIndex a = index.at({0, 0, 0}), b = index.at({1, 0, 0});
    const auto m = static_cast<NodeIndex>(xyz.size());
    xyz.push_back({0.5 / k, 0, 0});
    const std::size_t count = tris.size();
    for (std::size_t t = 0; t < count; ++t)
      for (int i = 0; i < 3; ++i) {
        const NodeIndex p = tris[t][i], q = tris[t][(i + 1) % 3], r = tris[t][(i + 2) % 3];
        if ((p == a && q == b) || (p == b && q == a)) {
          tris[t] = {p, m, r};
          tris.push_back({m, q, r});
          break;
        }
      }
  }
  return make_triangle_mesh_3d(xyz, tris);
}

// Distance of x to the cube's surface (for points on or inside it).
double off_cube(const double* x) {
  double d = INFINITY;
  for (int i = 0; i < 3; ++i) d = std::min({d, std::abs(x[i]), std::abs(1 - x[i])});
  return d;
}

// Quads whose four corners do not all lie on one face of the cube.
int quads_across_faces(const Mesh& out) {
  int across = 0;
  for (const ElementBlock& b : out.blocks) {
    if (b.type->num_nodes != 4) continue;
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto n = b.element(e);
      bool one_face = false;
      for (int axis = 0; axis < 3 && !one_face; ++axis)
        for (double plane : {0.0, 1.0}) {
          bool all = true;
          for (int i = 0; i < 4; ++i) all = all && std::abs(out.coords[3 * n[i] + axis] - plane) < 1e-12;
          one_face = one_face || all;
        }
      across += one_face ? 0 : 1;
    }
  }
  return across;
}

TEST(FeatureEdges, CubeKeepsItsShape) {
  const int k = 8;
  const Mesh cube = cube_surface(k, 3, false);
  RecombineResult r = recombine(cube, {});
  EXPECT_EQ(r.stats.feature_edges, 12u * k);
  EXPECT_EQ(r.stats.triangles, 0u);
  EXPECT_EQ(r.stats.quads, 6u * k * k);
  EXPECT_GT(r.stats.eta_min, 0.0);
  EXPECT_EQ(quads_across_faces(r.mesh), 0);
  double worst = 0;
  for (std::size_t v = 0; v < r.mesh.node_tags.size(); ++v) worst = std::max(worst, off_cube(&r.mesh.coords[3 * v]));
  EXPECT_LE(worst, 1e-12);
  // One output block per entity, as in the input.
  EXPECT_EQ(r.mesh.blocks.size(), 1u);

  // Without features, quads fold over the cube's edges and its nodes leave the surface.
  RecombineOptions none;
  none.feature_angle = 180;
  r = recombine(cube, none);
  EXPECT_EQ(r.stats.feature_edges, 0u);
  EXPECT_GT(quads_across_faces(r.mesh), 0);
}

TEST(FeatureEdges, OddPiecesOfAClosedSurfaceArePairedUp) {
  const int k = 6;
  const Mesh cube = cube_surface(k, 5, true);
  const RecombineResult r = recombine(cube, {});
  EXPECT_EQ(r.stats.feature_edges, 12u * k + 1);  // the split segment counts twice
  EXPECT_EQ(r.stats.odd_splits, 1u);
  EXPECT_EQ(r.stats.triangles, 0u);
  EXPECT_EQ(r.stats.quads, (6u * 2 * k * k + 2 + 2) / 2);  // +2 odd faces, +2 from the split
  EXPECT_EQ(quads_across_faces(r.mesh), 0);
  double worst = 0;
  for (std::size_t v = 0; v < r.mesh.node_tags.size(); ++v) worst = std::max(worst, off_cube(&r.mesh.coords[3 * v]));
  EXPECT_LE(worst, 1e-12);
}

// Two flat strips meeting at a ridge where the surface turns by 30 degrees: a feature for
// angles below 30, none above.
TEST(FeatureEdges, ThresholdIsTheTurnOfTheNormals) {
  const int n = 4;
  const double turn = 30 * M_PI / 180;
  std::vector<std::array<double, 3>> xyz;
  for (int row = 0; row < 3; ++row)
    for (int i = 0; i <= n; ++i) {
      const double y = row - 1.0;  // rows -1, 0 (the ridge), 1
      xyz.push_back({double(i), y < 0 ? y : y * std::cos(turn), y > 0 ? y * std::sin(turn) : 0.0});
    }
  std::vector<std::array<NodeIndex, 3>> tris;
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i < n; ++i) {
      const auto p = static_cast<NodeIndex>(row * (n + 1) + i), q = static_cast<NodeIndex>(p + n + 1);
      tris.push_back({p, static_cast<NodeIndex>(p + 1), static_cast<NodeIndex>(q + 1)});
      tris.push_back({p, static_cast<NodeIndex>(q + 1), q});
    }
  const Mesh roof = make_triangle_mesh_3d(xyz, tris);
  for (const auto& [angle, expected] : std::vector<std::pair<double, std::size_t>>{{40, 0}, {31, 0}, {29, n}, {10, n}}) {
    std::vector<std::string> warnings;
    recombine_detail::TriangleSurface s = recombine_detail::prepare_triangles(roof, "roof", warnings);
    EXPECT_EQ(recombine_detail::split_regions_at_features(s, angle), expected) << angle;
    EXPECT_EQ(s.region_entity.size(), expected > 0 ? 2u : 1u) << angle;
  }
}

// Every face of a tetrahedron is a feature-bounded piece of one triangle, which no split
// could make a quad: they join their neighbours, and the four triangles give two quads.
TEST(FeatureEdges, SingleTrianglePiecesJoinANeighbour) {
  const Mesh tet = make_triangle_mesh_3d({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                    {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
  const RecombineResult r = recombine(tet, {});
  EXPECT_EQ(r.stats.feature_edges, 0u);
  EXPECT_EQ(r.stats.odd_splits, 0u);
  EXPECT_EQ(r.stats.quads, 2u);
  EXPECT_EQ(r.stats.triangles, 0u);
  // An octahedron: its faces join in pairs (or more), each piece even: four quads.
  const Mesh octahedron = make_triangle_mesh_3d(
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
  const RecombineResult o = recombine(octahedron, {});
  EXPECT_EQ(o.stats.quads, 4u);
  EXPECT_EQ(o.stats.triangles, 0u);
}

// An icosphere of radius 1 (icosahedron, each triangle cut in 4 `levels` times, the new
// nodes pushed out to the sphere), its nodes then moved along the sphere at random.
Mesh icosphere(int levels, unsigned seed) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<std::array<double, 3>> xyz = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                                            {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<NodeIndex, 3>> tris = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                                 {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                 {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                                 {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  const auto unit = [](std::array<double, 3> p) {
    const double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return std::array<double, 3>{p[0] / l, p[1] / l, p[2] / l};
  };
  for (auto& p : xyz) p = unit(p);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<NodeIndex, NodeIndex>, NodeIndex> middle;
    const auto mid = [&](NodeIndex a, NodeIndex b) {
      auto [it, inserted] = middle.emplace(std::minmax(a, b), static_cast<NodeIndex>(xyz.size()));
      if (inserted)
        xyz.push_back(unit({xyz[a][0] + xyz[b][0], xyz[a][1] + xyz[b][1], xyz[a][2] + xyz[b][2]}));
      return it->second;
    };
    std::vector<std::array<NodeIndex, 3>> finer;
    for (const auto& t : tris) {
      const NodeIndex ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      finer.insert(finer.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
    }
    tris = std::move(finer);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.25, 0.25);
  const double h = 1.1 / (1 << levels);  // about the edge length
  for (auto& p : xyz) p = unit({p[0] + u(rng) * h, p[1] + u(rng) * h, p[2] + u(rng) * h});
  return make_triangle_mesh_3d(xyz, tris);
}

// The nodes of a recombined curved surface stay on it: within the input triangles' own
// distance to the sphere (what smoothing in tangent planes and merges at the middle of
// diagonals did not keep), and the sphere has no features.
TEST(SurfaceProjection, SphereNodesStayOnTheSurface) {
  const Mesh sphere = icosphere(4, 7);
  double sag = 0;  // the deepest point of an input triangle below the sphere
  for (std::size_t e = 0; e < sphere.blocks[0].size(); ++e) {
    const auto n = sphere.blocks[0].element(e);
    const double* a = &sphere.coords[3 * n[0]];
    const double* b = &sphere.coords[3 * n[1]];
    const double* c = &sphere.coords[3 * n[2]];
    const std::array<double, 3> u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const std::array<double, 3> w{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double plane = std::abs(w[0] * a[0] + w[1] * a[1] + w[2] * a[2]) / std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    sag = std::max(sag, 1 - plane);
  }
  for (const bool full_quad : {false, true}) {  // refinement adds nodes at chords' middles
    RecombineOptions o;
    o.full_quad = full_quad;
    const RecombineResult r = recombine(sphere, o);
    EXPECT_EQ(r.stats.feature_edges, 0u);
    EXPECT_EQ(r.stats.triangles, 0u);
    EXPECT_GT(r.stats.vertex_merges, 0u);  // merges happened, and moved nodes
    double below = 0, above = 0;
    for (std::size_t v = 0; v < r.mesh.node_tags.size(); ++v) {
      const double* x = &r.mesh.coords[3 * v];
      const double radius = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      below = std::max(below, 1 - radius);
      above = std::max(above, radius - 1);
    }
    EXPECT_LE(below, sag + 1e-12) << full_quad;
    EXPECT_LE(above, sag) << full_quad;
  }
}

}  // namespace
}  // namespace quadval
