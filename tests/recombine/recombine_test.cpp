// The whole pipeline on generated meshes and on the Gmsh meshes of ../shared/data/tri.
#include "quadval/recombine.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "quadval/io.hpp"
#include "quadval/quad_quality.hpp"
#include "recombine/quad_mesh_checks.hpp"
#include "recombine/test_meshes.hpp"

namespace quadval {
namespace {

TEST(Recombine, GeneratedMeshesBecomeValidAllQuadMeshes) {
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const Mesh in = test::random_grid_mesh(4 + seed % 7, 3 + seed % 5, seed);
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    for (bool optimize : {false, true}) {
      RecombineOptions o;
      o.optimize = optimize;
      const RecombineResult r = recombine(in, o);
      const auto s = test::expect_valid_recombination(in, r.mesh);
      EXPECT_EQ(s.triangles, 0u);
      EXPECT_EQ(r.stats.triangles, 0u);
      EXPECT_EQ(s.quads, r.stats.quads);
      // Half the triangles, plus one per vertex duplication, minus one per clean-up.
      EXPECT_EQ(s.quads + r.stats.vertex_merges + r.stats.doublet_collapses,
                r.stats.input_triangles / 2 + r.stats.vertex_duplications);
      EXPECT_EQ(r.stats.invalid_quads, 0u);
    }
  }
}

TEST(Recombine, OptimizationNeverLowersTheWorstQuad) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Mesh in = test::random_grid_mesh(8, 6, 100 + seed);
    RecombineOptions raw;
    raw.optimize = false;
    const double before = recombine(in, raw).stats.eta_min;
    const RecombineResult after = recombine(in, {});
    EXPECT_GE(after.stats.eta_min, before - 1e-12) << "seed " << seed;
  }
}

TEST(Recombine, SurfaceInThreeDimensions) {
  // The random grid wrapped on a quarter cylinder of radius 4 (arc length kept).
  Mesh in = test::random_grid_mesh(6, 5, 7);
  const double radius = 4;
  for (std::size_t i = 0; i < in.num_nodes(); ++i) {
    const double x = in.coords[3 * i], y = in.coords[3 * i + 1];
    in.coords[3 * i] = radius * std::sin(x / radius);
    in.coords[3 * i + 1] = y;
    in.coords[3 * i + 2] = radius * std::cos(x / radius);
  }
  const RecombineResult r = recombine(in, {});
  test::expect_valid_recombination(in, r.mesh, /*planar=*/false);
  EXPECT_EQ(r.stats.triangles, 0u);
  EXPECT_EQ(r.stats.invalid_quads, 0u);
  // Every node stays close to the cylinder (smoothing moves along the tangent plane).
  for (std::size_t i = 0; i < r.mesh.num_nodes(); ++i) {
    const auto p = r.mesh.node(static_cast<NodeIndex>(i));
    EXPECT_NEAR(std::hypot(p[0], p[2]), radius, 0.05);
  }
}

TEST(Recombine, GreedyLeavesTrianglesAndFullQuadRemovesThem) {
  const Mesh in = test::random_grid_mesh(9, 7, 3);
  RecombineOptions greedy;
  greedy.algorithm = RecombineAlgorithm::greedy;
  const RecombineResult g = recombine(in, greedy);
  const auto gs = test::expect_valid_recombination(in, g.mesh);
  EXPECT_EQ(2 * gs.quads + gs.triangles + 2 * (g.stats.vertex_merges + g.stats.doublet_collapses),
            in.num_elements());
  greedy.full_quad = true;
  const RecombineResult f = recombine(in, greedy);
  EXPECT_EQ(f.stats.triangles, 0u);
  // Each quad -> 4, each triangle -> 3 (Fig. 2).
  EXPECT_EQ(f.stats.quads, 4 * gs.quads + 3 * gs.triangles);
  double in_area = 0, out_area = 0;
  for (std::size_t e = 0; e < in.blocks[0].size(); ++e)
    in_area += test::shoelace_area(in, in.blocks[0].element(e));
  for (const auto& b : f.mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) out_area += test::shoelace_area(f.mesh, b.element(e));
  EXPECT_NEAR(out_area, in_area, 1e-9 * in_area);
}

TEST(Recombine, TauOfAUniformGridWithItsOwnSize) {
  // A 4 x 4 grid of unit squares (8 x 4 = 32 triangles without jitter) recombined with the
  // size field h = 1: the squares come back (eta 1) and all 40 edges have l = 1 -> tau 100%.
  const Mesh in = test::random_grid_mesh(4, 4, 5, 0, true, 0.0);
  RecombineOptions o;
  o.size_field = [](double, double, double) { return 1.0; };
  const RecombineResult r = recombine(in, o);
  EXPECT_EQ(r.stats.quads, 16u);
  EXPECT_NEAR(r.stats.eta_min, 1.0, 1e-12);
  EXPECT_NEAR(r.stats.eta_mean, 1.0, 1e-12);
  ASSERT_TRUE(r.stats.has_tau);
  EXPECT_NEAR(r.stats.tau, 100.0, 1e-9);
  EXPECT_EQ(r.stats.degree_min, 4);
  EXPECT_EQ(r.stats.degree_max, 4);
  EXPECT_NEAR(r.stats.degree4_share, 1.0, 0.0);
  // With h = 2 every l is 1/2: d = -1/2, tau = 100 e^{-1/2}.
  o.size_field = [](double, double, double) { return 2.0; };
  EXPECT_NEAR(recombine(in, o).stats.tau, 100.0 * std::exp(-0.5), 1e-9);
}

TEST(Recombine, CrossFieldCostAlignsQuadsWithTheField) {
  // Unjittered grid: every diagonal is at 45 degrees. With the field along the axes each
  // diagonal costs 0 (eq. 7); with the field at 45 degrees each costs 1.
  const Mesh in = test::random_grid_mesh(6, 4, 9, 0, true, 0.0);
  RecombineOptions o;
  o.cost = PairCostKind::cross_field;
  o.optimize = false;
  o.cross_field_angle = 0.0;
  const RecombineResult aligned = recombine(in, o);
  EXPECT_NEAR(aligned.stats.matching_cost, 0.0, 1e-12);
  EXPECT_NEAR(aligned.stats.eta_min, 1.0, 1e-12);  // all unit squares
  // Field at 45 degrees: the diagonals cost 1 each and the axis edges 0, so the matching
  // avoids the 24 diagonals (all-squares would cost 24) and builds parallelograms.
  o.cross_field_angle = std::numbers::pi / 4;
  const RecombineResult turned = recombine(in, o);
  EXPECT_LT(turned.stats.matching_cost, 24.0 - 1.0);
  EXPECT_LT(turned.stats.eta_mean, 0.9);
}

std::filesystem::path shared_tri(const char* name) {
  return std::filesystem::path(QUADVAL_SHARED_DIR) / "data" / "tri" / name;
}

TEST(Recombine, GmshTriangleMeshesOfSharedData) {
  for (const char* name : {"rect-sin-a6.msh", "rect-sin-a8.msh", "uniform-10k-a6.msh"}) {
    SCOPED_TRACE(name);
    const auto path = shared_tri(name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing";
    std::vector<std::string> warnings;
    const Mesh in = read_mesh(path, &warnings);
    std::size_t tris = 0;
    for (const auto& b : in.blocks)
      if (b.type->family == ElementFamily::triangle) tris += b.size();
    if (tris % 2 == 1) continue;  // the odd case is tested separately
    Mesh tri_only = in;
    std::erase_if(tri_only.blocks, [](const ElementBlock& b) { return b.type->dim != 2; });
    const RecombineResult r = recombine(in, {});
    const auto s = test::expect_valid_recombination(tri_only, r.mesh);
    EXPECT_EQ(s.triangles, 0u);
    EXPECT_EQ(r.stats.invalid_quads, 0u);
    EXPECT_EQ(s.quads + r.stats.vertex_merges + r.stats.doublet_collapses,
              tris / 2 + r.stats.vertex_duplications);
  }
}

TEST(Recombine, RectSinA6AtLeastAsGoodAsGmsh) {
  // ../shared/data/README.md: Gmsh's Blossom with its default smoothing gives eta_min 0.422
  // and eta_mean 0.754 on this mesh.
  const auto path = shared_tri("rect-sin-a6.msh");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing";
  const RecombineResult r = recombine(read_mesh(path), {});
  EXPECT_EQ(r.stats.triangles, 0u);
  EXPECT_GE(r.stats.eta_min, 0.422);
  EXPECT_GE(r.stats.eta_mean, 0.754);
}

}  // namespace
}  // namespace quadval
