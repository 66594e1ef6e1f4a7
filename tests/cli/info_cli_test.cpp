// `quadval info`: counts, parity, boundary loops and non-manifold edges, on files whose
// answers are known independently (the data README, Euler's formula, hand-made meshes).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "io/io_test_support.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::ScratchDir;

using testing_cli::CliRun;

TEST(InfoCli, RectangleTrianglesFromGmsh) {
  ScratchDir dir("info_rect");
  const std::string in = std::string(QUADVAL_SHARED_DIR) + "/data/tri/uniform-10k-a6.msh";
  const CliRun r = testing_cli::run_cli("info " + in + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto d = nlohmann::json::parse(r.out);
  const auto& t = d["triangles"];
  // The data README: 10,076 triangles on the unit square.
  EXPECT_EQ(t["count"].get<int>(), 10076);
  EXPECT_TRUE(t["even"].get<bool>());
  EXPECT_EQ(t["boundary_loops"].get<int>(), 1);
  EXPECT_EQ(t["nonmanifold_edges"].get<int>(), 0);
  // A disc-like triangulation: 3T = 2E - B (each interior edge in two triangles), and
  // Euler V - E + T = 1 over the triangle nodes.
  const int T = 10076, E = t["edges"].get<int>(), B = t["boundary_edges"].get<int>();
  EXPECT_EQ(3 * T, 2 * E - B);
  const auto& box = d["bounding_box"];
  EXPECT_DOUBLE_EQ(box["min"][0].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(box["max"][1].get<double>(), 1.0);
}

TEST(InfoCli, OddAndNonManifoldSurfaceIsReportedNotRejected) {
  ScratchDir dir("info_nm");
  // Three triangles sharing the edge 0-1 (non-manifold, odd count).
  testing_io::write_bytes(dir / "fin.off",
                          "OFF\n5 3 0\n0 0 0\n1 0 0\n0.5 1 0\n0.5 -1 0\n0.5 0 1\n"
                          "3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  const CliRun r = testing_cli::run_cli("info " + (dir / "fin.off").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("triangles 3 (odd)"));
  EXPECT_THAT(r.out, HasSubstr("non-manifold edges 1 (node tags: 1-2)"));
}

TEST(InfoCli, CurvedMeshCountsByType) {
  const CliRun r = testing_cli::run_cli(
      "info " + std::string(QUADVAL_SHARED_DIR) + "/data/curved/tets_h0.8_o2.msh --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto d = nlohmann::json::parse(r.out);
  bool found = false;
  for (const auto& t : d["element_types"])
    if (t["gmsh_type"].get<int>() == 11) {
      found = true;
      EXPECT_EQ(t["count"].get<int>(), 9647);  // the data README
      EXPECT_EQ(t["order"].get<int>(), 2);
    }
  EXPECT_TRUE(found);
  EXPECT_EQ(d["dimension"].get<int>(), 3);
}

TEST(InfoCli, MissingFileAndDirectoryExitTwo) {
  ScratchDir dir("info_bad");
  CliRun r = testing_cli::run_cli("info " + (dir / "nope.msh").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("nope.msh"));
  r = testing_cli::run_cli("info " + dir.path().string());
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("directory"));
}

}  // namespace
}  // namespace quadval
