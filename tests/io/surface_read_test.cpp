// STL, OBJ and OFF reading: hand-written files with known nodes and faces, and bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <map>
#include <random>

#include <fmt/core.h>

#include "io/io_test_support.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::ScratchDir;

Mesh read_text(const ScratchDir& dir, const std::string& name, const std::string& text,
               std::vector<std::string>* warnings = nullptr) {
  testing_io::write_bytes(dir / name, text);
  std::vector<std::string> local;
  return read_mesh(dir / name, warnings ? warnings : &local);
}

std::string error_of(const ScratchDir& dir, const std::string& name, const std::string& text) {
  try {
    read_text(dir, name, text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// Unit square split along its diagonal: 4 distinct vertices, 2 triangles.
const char* const kStl =
    "solid square\n"
    "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 1 1 0\n"
    "    endloop\n  endfacet\n"
    "  facet normal 0 0 1\n    outer loop\n      vertex -0 0 0\n      vertex 1 1 0\n      vertex 0 1 0\n"
    "    endloop\n  endfacet\n"
    "endsolid square\n";

TEST(SurfaceRead, AsciiStlMergesIdenticalVertices) {
  ScratchDir dir("stl");
  const Mesh m = read_text(dir, "s.stl", kStl);
  EXPECT_EQ(m.node_tags, (std::vector<Tag>{1, 2, 3, 4}));
  EXPECT_EQ(m.coords, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
  ASSERT_EQ(m.blocks.size(), 1u);
  EXPECT_EQ(m.blocks[0].type->gmsh_id, 2);
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{0, 1, 2, 0, 2, 3}));  // -0 is 0
  EXPECT_EQ(m.blocks[0].tags, (std::vector<Tag>{1, 2}));
}

// Many vertices (the merger's table grows several times), in a random order with repeats
// and -0.0 for some zeros: nodes numbered by first appearance, equal values merged, as an
// ordered map of the values finds them; binary and ASCII alike.
TEST(SurfaceRead, StlMergesThousandsOfVerticesInOrderOfFirstAppearance) {
  ScratchDir dir("stl_many");
  std::mt19937_64 rng(5);
  const int distinct = 5000, facets = 6000;
  std::vector<std::array<float, 3>> points(distinct);
  for (auto& p : points)
    for (float& c : p) c = static_cast<float>(rng() % 200) * 0.25f;  // many equal coordinates
  std::vector<std::array<float, 3>> corners;
  for (int f = 0; f < 3 * facets; ++f) {
    std::array<float, 3> p = points[rng() % distinct];
    for (float& c : p)
      if (c == 0 && rng() % 2 == 0) c = -0.0f;
    corners.push_back(p);
  }
  // The expected numbering, from an ordered map of the values (-0 and 0 the same key).
  std::map<std::array<double, 3>, NodeIndex> first;
  std::vector<NodeIndex> expected_nodes;
  std::vector<double> expected_coords;
  for (const auto& p : corners) {
    const std::array<double, 3> key{p[0] + 0.0, p[1] + 0.0, p[2] + 0.0};
    const auto [it, added] = first.emplace(key, static_cast<NodeIndex>(first.size()));
    if (added) expected_coords.insert(expected_coords.end(), {double{p[0]}, double{p[1]}, double{p[2]}});
    expected_nodes.push_back(it->second);
  }
  std::string binary(80, ' ');
  const auto count = static_cast<std::uint32_t>(facets);
  binary.append(reinterpret_cast<const char*>(&count), 4);
  std::string ascii = "solid many\n";
  for (int f = 0; f < facets; ++f) {
    const float normal[3] = {0, 0, 1};
    binary.append(reinterpret_cast<const char*>(normal), 12);
    ascii += "facet normal 0 0 1\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto& p = corners[static_cast<std::size_t>(3 * f + k)];
      binary.append(reinterpret_cast<const char*>(p.data()), 12);
      ascii += fmt::format("vertex {} {} {}\n", p[0], p[1], p[2]);
    }
    binary.append(2, '\0');
    ascii += "endloop\nendfacet\n";
  }
  ascii += "endsolid many\n";
  for (const auto& [name, text] : {std::pair{"b.stl", binary}, std::pair{"a.stl", ascii}}) {
    const Mesh m = read_text(dir, name, text);
    ASSERT_EQ(m.blocks.size(), 1u) << name;
    EXPECT_EQ(m.blocks[0].nodes, expected_nodes) << name;
    ASSERT_EQ(m.coords.size(), expected_coords.size()) << name;
    for (std::size_t i = 0; i < m.coords.size(); ++i) EXPECT_EQ(m.coords[i], expected_coords[i]) << name << " " << i;
  }
}

TEST(SurfaceRead, BinaryStlEvenWithASolidHeader) {
  ScratchDir dir("stl_binary");
  std::string bytes(80, ' ');
  std::memcpy(bytes.data(), "solid but binary", 16);
  const std::uint32_t count = 2;
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  const float facets[2][12] = {{0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 1, 0.5f}};
  for (const auto& f : facets) {
    bytes.append(reinterpret_cast<const char*>(f), sizeof f);
    bytes.append(2, '\0');
  }
  const Mesh m = read_text(dir, "b.stl", bytes);
  EXPECT_EQ(m.coords, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.5}));
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{0, 1, 2, 0, 2, 3}));
  EXPECT_THAT(error_of(dir, "t.stl", bytes.substr(0, bytes.size() - 10)), HasSubstr("binary STL header says 2 triangles"));
  std::string nan = bytes;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 84 + 12 + 4, &q, 4);
  EXPECT_THAT(error_of(dir, "n.stl", nan), HasSubstr("byte offset 100: vertex coordinate of facet 1 is nan"));
}

TEST(SurfaceRead, ObjWithSlashesNegativeIndicesAndQuads) {
  ScratchDir dir("obj");
  std::vector<std::string> warnings;
  const Mesh m = read_text(dir, "s.obj",
                           "# a square and a triangle\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\n"
                           "vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1 4\nv 2 0 0\nf -4 -1 -3\ncurv 0 1 2\n",
                           &warnings);
  EXPECT_EQ(m.num_nodes(), 5u);
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].type->gmsh_id, 2);
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{1, 4, 2}));
  EXPECT_EQ(m.blocks[0].tags, (std::vector<Tag>{2}));
  EXPECT_EQ(m.blocks[1].type->gmsh_id, 3);
  EXPECT_EQ(m.blocks[1].nodes, (std::vector<NodeIndex>{0, 1, 2, 3}));
  EXPECT_EQ(m.blocks[1].tags, (std::vector<Tag>{1}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("s.obj:12: OBJ statement 'curv'"));
  EXPECT_THAT(error_of(dir, "a.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"), HasSubstr("a.obj:3: face refers to vertex 3, the file has 2"));
  EXPECT_THAT(error_of(dir, "b.obj", "v 0 0 0\nf 1 2 3 4 5\n"), HasSubstr("b.obj:2: face with 5 vertices"));
  EXPECT_THAT(error_of(dir, "c.obj", "v 0 nan 0\n"), HasSubstr("c.obj:1: vertex y coordinate is 'nan'"));
  EXPECT_THAT(error_of(dir, "d.obj", "v 0 0 0\nf 1 0 1\n"), HasSubstr("d.obj:2: vertex index 0"));
  EXPECT_THAT(error_of(dir, "e.obj", ""), HasSubstr("no vertices and no faces"));
}

TEST(SurfaceRead, Off) {
  ScratchDir dir("off");
  const Mesh m = read_text(dir, "s.off", "OFF # comment\n# another\n4 2 5\n0 0 0\n2 0 0\n2 2 0\n0 2 0.25\n"
                                         "3 0 1 2\n4 0 1 2 3 255 0 0\n");
  EXPECT_EQ(m.coords, (std::vector<double>{0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0.25}));
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{0, 1, 2}));
  EXPECT_EQ(m.blocks[1].nodes, (std::vector<NodeIndex>{0, 1, 2, 3}));
  EXPECT_EQ(read_text(dir, "t.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").num_elements(), 1u);
  EXPECT_THAT(error_of(dir, "a.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), HasSubstr("a.off:6: vertex index 3, expected 0 to 2"));
  EXPECT_THAT(error_of(dir, "b.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), HasSubstr("b.off:4: unexpected end of file after 2 of 3 vertices"));
  EXPECT_THAT(error_of(dir, "c.off", "OFF\n300000000000 1 0\n"), HasSubstr("c.off:2: number of vertices 300000000000 does not fit"));
  EXPECT_THAT(error_of(dir, "d.off", "PLY\n"), HasSubstr("d.off:1: expected 'OFF'"));
  EXPECT_THAT(error_of(dir, "e.off", ""), HasSubstr("empty file"));
  EXPECT_THAT(error_of(dir, "f.off", "OFF\n1 0 0\n0 inf 0\n"), HasSubstr("f.off:3: vertex y coordinate is 'inf'"));
}

TEST(SurfaceRead, StlErrors) {
  ScratchDir dir("stl_errors");
  EXPECT_THAT(error_of(dir, "a.stl", ""), HasSubstr("a.stl: empty file"));
  EXPECT_THAT(error_of(dir, "b.stl", "hello"), HasSubstr("neither ASCII STL"));
  std::string truncated = kStl;
  truncated.resize(truncated.find("endloop"));
  EXPECT_THAT(error_of(dir, "c.stl", truncated), HasSubstr("c.stl:7: unexpected end of file, expected endloop"));
  std::string bad = kStl;
  bad.replace(bad.find("vertex 1 0 0"), 12, "vertex 1 x 0");
  EXPECT_THAT(error_of(dir, "d.stl", bad), HasSubstr("d.stl:5: expected vertex y coordinate (a number), found 'x'"));
}

}  // namespace
}  // namespace quadval
