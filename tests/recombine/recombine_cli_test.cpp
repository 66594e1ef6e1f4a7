// `quadval recombine` end to end: exit codes, output file, JSON report.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include "cli_run.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

namespace fs = std::filesystem;

using testing_cli::CliRun;
using testing_cli::run_cli;

class RecombineCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("qv_recombine_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(RecombineCli, RectSinGivesAllQuadMeshAndReport) {
  const fs::path in = fs::path(QUADVAL_SHARED_DIR) / "data/tri/rect-sin-a6.msh";
  if (!fs::exists(in)) GTEST_SKIP() << in << " missing";
  const fs::path out = dir_ / "q.msh", report = dir_ / "r.json";
  const CliRun r = run_cli("recombine " + in.string() + " -o " + out.string() + " --report " +
                        report.string() + " --size-field '0.1+0.08*sin(3*x)*cos(6*y)'");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("[blossom]"), std::string::npos) << r.output;
  const Mesh q = read_mesh(out);
  std::size_t quads = 0, others = 0;
  for (const auto& b : q.blocks) (b.type->gmsh_id == 3 ? quads : others) += b.size();
  EXPECT_GT(quads, 0u);
  EXPECT_EQ(others, 0u);
  std::ifstream f(report);
  const auto j = nlohmann::json::parse(f);
  const auto& s = j.at("statistics");
  EXPECT_EQ(s.at("quads").get<std::size_t>(), quads);
  EXPECT_EQ(s.at("triangles_left").get<std::size_t>(), 0u);
  EXPECT_GT(s.at("eta_min").get<double>(), 0.0);
  EXPECT_FALSE(s.at("tau_percent").is_null());
  EXPECT_FALSE(s.at("times").empty());
}

// --threads changes the time, never the mesh: smoothing's colour blocks and the other
// parallel loops give the same bytes on one thread and on two.
TEST_F(RecombineCli, OneThreadAndTwoWriteTheSameMesh) {
  const fs::path in = fs::path(QUADVAL_SHARED_DIR) / "data/tri/uniform-10k-a6.msh";
  if (!fs::exists(in)) GTEST_SKIP() << in << " missing";
  std::string bytes[2];
  for (int threads : {1, 2}) {
    const fs::path out = dir_ / ("t" + std::to_string(threads) + ".msh");
    const CliRun r = run_cli("recombine " + in.string() + " -o " + out.string() + " -q --threads " +
                             std::to_string(threads) + " --size-field '0.02+0.01*x'");
    ASSERT_EQ(r.code, 0) << r.output;
    std::ifstream f(out, std::ios::binary);
    bytes[threads - 1].assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  EXPECT_GT(bytes[0].size(), 100000u);
  EXPECT_EQ(bytes[0], bytes[1]);
}

TEST_F(RecombineCli, QuietPrintsNothing) {
  const fs::path in = fs::path(QUADVAL_SHARED_DIR) / "data/tri/rect-sin-a8.msh";
  if (!fs::exists(in)) GTEST_SKIP() << in << " missing";
  const CliRun r = run_cli("recombine " + in.string() + " -o " + (dir_ / "q.msh").string() + " -q");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output, "");
}

TEST_F(RecombineCli, NonManifoldInputExitsTwoWithMessage) {
  const fs::path in = dir_ / "bad.off";
  std::ofstream(in) << "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n1 1 0\n"
                       "3 0 1 2\n3 1 0 3\n3 0 1 4\n";
  const CliRun r = run_cli("recombine " + in.string() + " -o " + (dir_ / "o.msh").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("non-manifold"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "o.msh"));
}

TEST_F(RecombineCli, QuadInputAndBadSizeFieldExitTwo) {
  const fs::path in = dir_ / "quad.off";
  std::ofstream(in) << "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  CliRun r = run_cli("recombine " + in.string() + " -o " + (dir_ / "o.msh").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("triangles only"), std::string::npos) << r.output;
  const fs::path tri = dir_ / "tri.off";
  std::ofstream(tri) << "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  r = run_cli("recombine " + tri.string() + " -o " + (dir_ / "o.msh").string() +
              " --size-field 'x+*'");
  EXPECT_EQ(r.code, 2) << r.output;
}

TEST_F(RecombineCli, OddTriangleCountIsReportedAndStillAllQuad) {
  const fs::path in = dir_ / "odd.off";
  // Three triangles: a fan over the unit square plus one on top.
  std::ofstream(in) << "OFF\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 1.6 0\n"
                       "3 0 1 2\n3 0 2 3\n3 3 2 4\n";
  const fs::path out = dir_ / "o.msh";
  const CliRun r = run_cli("recombine " + in.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("odd number of triangles"), std::string::npos) << r.output;
  const Mesh q = read_mesh(out);
  for (const auto& b : q.blocks) EXPECT_EQ(b.type->gmsh_id, 3);
}

// An STL cube, two triangles a face: its 12 edges are features by default (the report says
// so; each face gives one quad), none with --feature-angle 180, and 200 is refused.
TEST_F(RecombineCli, FeatureAngleOfAnStlCube) {
  const fs::path in = dir_ / "cube.stl", out = dir_ / "q.msh", report = dir_ / "r.json";
  {
    const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    const int face[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    std::ofstream f(in);
    f << "solid cube\n";
    for (const auto& q : face)
      for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
        f << " facet normal 0 0 0\n  outer loop\n";
        for (int v : t) f << "   vertex " << corner[v][0] << " " << corner[v][1] << " " << corner[v][2] << "\n";
        f << "  endloop\n endfacet\n";
      }
    f << "endsolid cube\n";
  }
  const auto features = [&](const std::string& option) {
    const CliRun r = run_cli("recombine " + in.string() + " -o " + out.string() + " --report " + report.string() +
                             " -q " + option);
    EXPECT_EQ(r.code, 0) << r.output;
    std::ifstream f(report);
    const auto s = nlohmann::json::parse(f).at("statistics");
    EXPECT_EQ(s.at("quads").get<std::size_t>(), 6u);
    EXPECT_EQ(s.at("triangles_left").get<std::size_t>(), 0u);
    return s.at("feature_edges").get<std::size_t>();
  };
  EXPECT_EQ(features(""), 12u);
  EXPECT_EQ(features("--feature-angle 180"), 0u);
  const CliRun bad = run_cli("recombine " + in.string() + " -o " + out.string() + " --feature-angle 200");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("--feature-angle"), std::string::npos) << bad.output;
}

// OBJ in, OBJ out: the quads as faces, as many as the report counts; an STL output is
// refused before any work, and nothing is written.
TEST_F(RecombineCli, ObjInObjOutAndStlOutRefused) {
  const fs::path in = dir_ / "strip.obj", out = dir_ / "q.obj", report = dir_ / "r.json";
  {
    std::ofstream f(in);  // a 6 x 4 grid of squares, each cut into two triangles
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i <= 6; ++i) f << "v " << i << " " << j << " 0\n";
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 6; ++i) {
        const int v = j * 7 + i + 1;
        f << "f " << v << " " << v + 1 << " " << v + 8 << "\nf " << v << " " << v + 8 << " " << v + 7 << "\n";
      }
  }
  const CliRun r = run_cli("recombine " + in.string() + " -o " + out.string() + " -q --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  const Mesh q = read_mesh(out);
  ASSERT_EQ(q.blocks.size(), 1u);
  EXPECT_EQ(q.blocks[0].type->gmsh_id, 3);
  std::ifstream f(report);
  EXPECT_EQ(q.blocks[0].size(), nlohmann::json::parse(f).at("statistics").at("quads").get<std::size_t>());
  EXPECT_GE(q.blocks[0].size(), 24u);

  const CliRun stl = run_cli("recombine " + in.string() + " -o " + (dir_ / "q.stl").string());
  EXPECT_EQ(stl.code, 2);
  EXPECT_NE(stl.err.find("q.stl: STL is read only"), std::string::npos) << stl.output;
  EXPECT_EQ(stl.err.find("[read]"), std::string::npos) << "refused only after reading: " << stl.output;
  EXPECT_FALSE(fs::exists(dir_ / "q.stl"));
}

}  // namespace
}  // namespace quadval
