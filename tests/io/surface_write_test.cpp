// OBJ and OFF writing: the exact text of a small mesh, round trips through the readers
// (surface_read.cpp, which share no code with the writers) on mixed and large meshes, and
// the meshes these formats cannot hold.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "io/io_test_support.hpp"
#include "quadval/element_type.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::file_bytes;
using testing_io::ScratchDir;

ElementBlock block(int gmsh_id, std::vector<NodeIndex> nodes) {
  ElementBlock b;
  b.type = find_element_type(gmsh_id);
  b.entity_dim = b.type->dim;
  b.entity_tag = 1;
  const std::size_t n = nodes.size() / static_cast<std::size_t>(b.type->num_nodes);
  for (std::size_t e = 0; e < n; ++e) b.tags.push_back(static_cast<Tag>(e + 1));
  b.nodes = std::move(nodes);
  return b;
}

Mesh with_nodes(std::vector<double> coords) {
  Mesh m;
  m.coords = std::move(coords);
  for (std::size_t i = 0; i < m.coords.size() / 3; ++i) m.node_tags.push_back(static_cast<Tag>(10 * i + 7));
  return m;
}

std::string write_error(const Mesh& m, const std::filesystem::path& path) {
  try {
    write_mesh(m, path, WriteOptions{format_from_extension(path)});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// The faces of a surface read back, as corner lists, in file order.
std::vector<std::vector<NodeIndex>> faces_of(const Mesh& m) {
  std::vector<std::vector<NodeIndex>> out;
  for (const ElementBlock& b : m.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) out.emplace_back(b.element(e).begin(), b.element(e).end());
  return out;
}

// A unit square as one quad and a triangle beside it; node 2 is used by no element.
Mesh square_and_triangle() {
  Mesh m = with_nodes({0, 0, 0, 1, 0, 0, 9, 9, 9, 1, 1, 0, 0, 1, 0, 2, 0.5, 0.25});
  m.blocks.push_back(block(3, {0, 1, 3, 4}));
  m.blocks.push_back(block(2, {1, 5, 3}));
  return m;
}

TEST(SurfaceWrite, ObjTextOfASmallMesh) {
  ScratchDir dir("obj_text");
  write_mesh(square_and_triangle(), dir / "m.obj", WriteOptions{MeshFormat::obj});
  EXPECT_EQ(file_bytes(dir / "m.obj"),
            "# quadval: vertices 5, faces 2\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0.25\n"
            "f 1 2 3 4\nf 2 5 3\n");
}

TEST(SurfaceWrite, OffTextOfASmallMesh) {
  ScratchDir dir("off_text");
  write_mesh(square_and_triangle(), dir / "m.off", WriteOptions{MeshFormat::off});
  EXPECT_EQ(file_bytes(dir / "m.off"),
            "OFF\n5 2 0\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0.5 0.25\n"
            "4 0 1 2 3\n3 1 4 2\n");
}

// Random coordinates that printing must not round, and faces of both kinds in several
// blocks, some nodes unused: reading back gives the used nodes' exact coordinates in node
// order and every face, in block order, over the same points.
TEST(SurfaceWrite, ObjAndOffRoundTripExactly) {
  ScratchDir dir("round_trip");
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t n = 3 + rng() % 200;
    std::vector<double> coords(3 * n);
    for (double& x : coords) x = testing_io::awkward_double(rng);
    Mesh m = with_nodes(coords);
    std::vector<std::vector<NodeIndex>> expected;
    for (int b = 0; b < 3; ++b) {
      const int corners = (rng() % 2) ? 3 : 4;
      std::vector<NodeIndex> nodes;
      for (std::size_t e = 0, count = 1 + rng() % 50; e < count; ++e) {
        std::vector<NodeIndex> face;
        for (int c = 0; c < corners; ++c) face.push_back(static_cast<NodeIndex>(rng() % n));
        nodes.insert(nodes.end(), face.begin(), face.end());
        expected.push_back(face);
      }
      m.blocks.push_back(block(corners == 3 ? 2 : 3, nodes));
    }
    std::vector<char> used(n, 0);
    for (const auto& f : expected)
      for (NodeIndex v : f) used[v] = 1;
    for (const char* name : {"m.obj", "m.off"}) {
      write_mesh(m, dir / name, WriteOptions{format_from_extension(name)});
      const Mesh r = read_mesh(dir / name);
      // The readers put faces of 3 and of 4 corners in blocks of their own: compare per kind.
      std::vector<NodeIndex> kept;  // read node -> written node
      for (std::size_t v = 0; v < n; ++v)
        if (used[v]) kept.push_back(static_cast<NodeIndex>(v));
      ASSERT_EQ(r.num_nodes(), kept.size()) << name;
      for (std::size_t i = 0; i < kept.size(); ++i)
        for (int d = 0; d < 3; ++d) ASSERT_EQ(r.coords[3 * i + d], coords[3 * kept[i] + d]) << name;
      for (std::size_t size : {3u, 4u}) {
        std::vector<std::vector<NodeIndex>> want, got;
        for (const auto& f : expected)
          if (f.size() == size) want.push_back(f);
        for (const auto& f : faces_of(r))
          if (f.size() == size) {
            got.emplace_back();
            for (NodeIndex v : f) got.back().push_back(kept[v]);
          }
        EXPECT_EQ(got, want) << name << " faces of " << size;
      }
    }
  }
}

// Enough faces for the writer to format them in chunks on several threads: the same file
// as a plain loop would give, checked by reading it back.
TEST(SurfaceWrite, LargeGridRoundTrips) {
  ScratchDir dir("large");
  const int k = 230;  // 52,900 quads
  std::vector<double> coords;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) coords.insert(coords.end(), {i / 7.0, j / 3.0, 0.0});
  Mesh m = with_nodes(coords);
  std::vector<NodeIndex> quads;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const auto v = static_cast<NodeIndex>(j * (k + 1) + i);
      quads.insert(quads.end(), {v, v + 1, v + k + 2, v + k + 1});
    }
  m.blocks.push_back(block(3, quads));
  for (const char* name : {"g.obj", "g.off"}) {
    write_mesh(m, dir / name, WriteOptions{format_from_extension(name)});
    const Mesh r = read_mesh(dir / name);
    EXPECT_EQ(r.coords, coords) << name;
    ASSERT_EQ(r.blocks.size(), 1u) << name;
    EXPECT_EQ(r.blocks[0].nodes, quads) << name;
  }
}

// VTK's own OBJ reader (tests/io/vtk_check.py) sees the same points and faces.
TEST(SurfaceWrite, VtkReadsTheObj) {
  ScratchDir dir("vtk_obj");
  std::mt19937_64 rng(9);
  std::vector<double> coords(3 * 60);
  for (double& x : coords) x = std::uniform_real_distribution<double>(-1e3, 1e3)(rng);
  Mesh m = with_nodes(coords);
  std::vector<NodeIndex> quads, triangles;
  for (int e = 0; e < 40; ++e) quads.push_back(static_cast<NodeIndex>(rng() % 60));
  for (int e = 0; e < 30; ++e) triangles.push_back(static_cast<NodeIndex>(rng() % 60));
  m.blocks.push_back(block(3, quads));
  m.blocks.push_back(block(2, triangles));
  write_mesh(m, dir / "m.obj", WriteOptions{MeshFormat::obj});
  const std::string cmd = fmt::format("{} {}/tests/io/vtk_check.py obj {} {} >{} 2>&1", QUADVAL_PYTHON,
                                      QUADVAL_SOURCE_DIR, (dir / "m.obj").string(), (dir / "v.json").string(),
                                      (dir / "log.txt").string());
  const int status = std::system(cmd.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 77) GTEST_SKIP() << file_bytes(dir / "log.txt");
  ASSERT_EQ(code, 0) << file_bytes(dir / "log.txt");
  const auto v = nlohmann::json::parse(file_bytes(dir / "v.json"));
  // The written vertices: the used nodes in node order.
  std::vector<NodeIndex> number(60, 0);
  for (NodeIndex x : quads) number[x] = 1;
  for (NodeIndex x : triangles) number[x] = 1;
  std::vector<NodeIndex> kept;
  for (NodeIndex x = 0; x < 60; ++x)
    if (number[x]) {
      number[x] = static_cast<NodeIndex>(kept.size());
      kept.push_back(x);
    }
  // vtkOBJReader keeps single-precision points: equal within one float ulp.
  ASSERT_EQ(v.at("points").size(), kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double x = coords[3 * kept[i] + d];
      EXPECT_NEAR(v.at("points")[i][d].get<double>(), x, std::abs(x) * 0x1p-23);
    }
  std::vector<std::vector<NodeIndex>> want;
  for (std::size_t e = 0; e < quads.size(); e += 4)
    want.push_back({number[quads[e]], number[quads[e + 1]], number[quads[e + 2]], number[quads[e + 3]]});
  for (std::size_t e = 0; e < triangles.size(); e += 3)
    want.push_back({number[triangles[e]], number[triangles[e + 1]], number[triangles[e + 2]]});
  EXPECT_EQ(v.at("polygons").get<std::vector<std::vector<NodeIndex>>>(), want);
}

// Curved faces keep their corners and lines are left out, each with a warning.
TEST(SurfaceWrite, CurvedFacesByTheirCornersLinesLeftOut) {
  ScratchDir dir("curved");
  Mesh m = with_nodes({0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, -0.1, 0, 0.6, 0.6, 0, -0.1, 0.5, 0});
  m.blocks.push_back(block(1, {0, 1}));                // Line 2
  m.blocks.push_back(block(15, {2}));                  // Point
  m.blocks.push_back(block(9, {0, 1, 2, 3, 4, 5}));    // Triangle 6
  m.blocks.push_back(block(1, {1, 2}));                // Line 2, another block
  m.blocks.push_back(block(9, {0, 1, 2, 3, 4, 5}));    // Triangle 6, another block
  testing::internal::CaptureStderr();
  write_mesh(m, dir / "c.obj", WriteOptions{MeshFormat::obj});
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_THAT(err, HasSubstr("c.obj: 3 point and line elements not written (OBJ and OFF hold faces only): "
                             "2 of type 1 (Line 2), 1 of type 15 (Point)"));
  EXPECT_THAT(err, HasSubstr("c.obj: 2 curved faces written with their corners only (OBJ and OFF faces are "
                             "straight): 2 of type 9 (Triangle 6)"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 2) << err;  // one line each, blocks summed
  EXPECT_EQ(file_bytes(dir / "c.obj"), "# quadval: vertices 3, faces 2\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\n");
}

// Volumes, meshes without faces and STL are refused with the file's name, and no file is
// left behind.
TEST(SurfaceWrite, WhatTheyCannotHoldIsRefused) {
  ScratchDir dir("refused");
  Mesh tet = with_nodes({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  tet.blocks.push_back(block(4, {0, 1, 2, 3}));
  EXPECT_THAT(write_error(tet, dir / "t.off"), HasSubstr("t.off: OBJ and OFF hold surfaces"));
  EXPECT_FALSE(std::filesystem::exists(dir / "t.off"));
  Mesh lines = with_nodes({0, 0, 0, 1, 0, 0});
  lines.blocks.push_back(block(1, {0, 1}));
  EXPECT_THAT(write_error(lines, dir / "l.obj"), HasSubstr("l.obj: the mesh has no triangle or quadrangle"));
  EXPECT_FALSE(std::filesystem::exists(dir / "l.obj"));
  EXPECT_THAT(write_error(square_and_triangle(), dir / "s.stl"), HasSubstr("s.stl: STL is read only"));
  EXPECT_FALSE(std::filesystem::exists(dir / "s.stl"));
  EXPECT_THROW(output_format_from_extension("x.STL"), InputError);
  EXPECT_THROW(output_format_from_extension("x.ply"), InputError);
  EXPECT_EQ(output_format_from_extension("x.OFF"), MeshFormat::off);
}

}  // namespace
}  // namespace quadval
