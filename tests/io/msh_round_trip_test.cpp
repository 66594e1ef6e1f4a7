// Read-write-read round trips of MSH files: exact (Mesh ==) for every Gmsh-made mesh in
// shared/data and for random meshes of every element type, in MSH 2.2 and 4.1, ASCII and
// binary; large ASCII sections (formatted on several threads) the same bytes on any
// thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include <fmt/core.h>

#include "io/io_test_support.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using testing_io::Layout;
using testing_io::ScratchDir;

struct Target {
  MeshFormat format;
  bool binary;
  const char* name;
};
const Target kTargets[] = {{MeshFormat::msh41, false, "41a"},
                           {MeshFormat::msh41, true, "41b"},
                           {MeshFormat::msh22, false, "22a"},
                           {MeshFormat::msh22, true, "22b"}};

Mesh write_and_read(const Mesh& m, const std::filesystem::path& file, const Target& t) {
  write_mesh(m, file, {t.format, t.binary});
  std::vector<std::string> warnings;
  Mesh back = read_mesh(file, &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  return back;
}

/// Nodes, element blocks and physical names: what every version keeps.
void expect_same_content(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.node_tags, b.node_tags);
  EXPECT_EQ(a.coords, b.coords);
  EXPECT_EQ(a.blocks, b.blocks);
  EXPECT_EQ(a.physical_names, b.physical_names);
}

std::vector<std::filesystem::path> shared_meshes() {
  std::vector<std::filesystem::path> out;
  for (const char* dir : {"curved", "tri"})
    for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(QUADVAL_SHARED_DIR) / "data" / dir))
      if (e.path().extension() == ".msh") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(MshRoundTrip, SharedDataFilesAreExact) {
  const auto files = shared_meshes();
  ASSERT_GE(files.size(), 13u);
  ScratchDir dir("shared_round_trip");
  for (const auto& path : files) {
    SCOPED_TRACE(path.filename().string());
    std::vector<std::string> warnings;
    const Mesh original = read_mesh(path, &warnings);
    EXPECT_TRUE(warnings.empty());
    ASSERT_GT(original.num_elements(), 0u);
    const bool is22 = testing_io::file_bytes(path).substr(0, 20).find("2.2") != std::string::npos;
    for (const Target& t : kTargets) {
      SCOPED_TRACE(t.name);
      const Mesh once = write_and_read(original, dir / (std::string("a_") + t.name + ".msh"), t);
      if ((t.format == MeshFormat::msh22) == is22) {
        EXPECT_TRUE(once == original);  // same version: everything survives
      } else {
        expect_same_content(original, once);
      }
      const Mesh twice = write_and_read(once, dir / (std::string("b_") + t.name + ".msh"), t);
      EXPECT_TRUE(twice == once);
    }
  }
}

// Counts from the data README (made by Gmsh), so that the reader is checked against an
// outside source and not only against our own writer.
TEST(MshRoundTrip, SharedDataCountsMatchTheReadme) {
  const std::filesystem::path data = std::filesystem::path(QUADVAL_SHARED_DIR) / "data";
  auto count = [](const Mesh& m, int dim) {
    std::size_t n = 0;
    for (const ElementBlock& b : m.blocks) n += b.type->dim == dim ? b.size() : 0;
    return n;
  };
  EXPECT_EQ(count(read_mesh(data / "curved/tets_h0.8_o2.msh"), 3), 9647u);
  EXPECT_EQ(count(read_mesh(data / "curved/tri_h0.4_o4.msh"), 2), 1000u);
  EXPECT_EQ(count(read_mesh(data / "curved/quad_h0.4_o2.msh"), 2), 511u);
  EXPECT_EQ(count(read_mesh(data / "curved/mixed_h0.6_o2.msh"), 3), 1452u);
  EXPECT_EQ(count(read_mesh(data / "curved/hex_box_N20_amp0.35_seed777.msh"), 3), 8000u);
  EXPECT_EQ(count(read_mesh(data / "tri/uniform-10k-a6.msh"), 2), 10076u);
  const Mesh hex = read_mesh(data / "curved/hex_box_N20_amp0.35_seed777.msh");
  EXPECT_EQ(hex.num_nodes(), 21u * 21u * 21u);
}

class MshRandomRoundTrip : public ::testing::TestWithParam<Target> {};

TEST_P(MshRandomRoundTrip, EveryFixedSizeTypeIsExact) {
  const Target t = GetParam();
  ScratchDir dir(std::string("random_") + t.name);
  const Layout layout = t.format == MeshFormat::msh41 ? Layout::msh41 : Layout::msh22;
  for (const ElementType* type : testing_io::fixed_size_types()) {
    SCOPED_TRACE(fmt::format("type {} ({})", type->gmsh_id, type->name));
    const Mesh m = testing_io::random_mesh({type}, static_cast<std::uint64_t>(type->gmsh_id), layout);
    EXPECT_TRUE(write_and_read(m, dir / "one.msh", t) == m);
  }
  // All types in one mesh, several elements each.
  const Mesh all = testing_io::random_mesh(testing_io::fixed_size_types(), 2024, layout, 5);
  const Mesh back = write_and_read(all, dir / "all.msh", t);
  EXPECT_TRUE(back == all);
  expect_same_content(all, back);
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, MshRandomRoundTrip, ::testing::ValuesIn(kTargets),
                         [](const auto& info) { return std::string(info.param.name); });

// 70,000 nodes (shuffled tags) and 60,000 quadrangles with an element field: ASCII 4.1 and
// 2.2 give the same bytes on one thread and two, and read back exactly.
TEST(MshRoundTrip, LargeAsciiSectionsSameBytesOnAnyThreadCount) {
  ScratchDir dir("large");
  std::mt19937_64 rng(17);
  Mesh m;
  constexpr std::size_t kNodes = 70000, kQuads = 60000;
  for (std::size_t i = 0; i < kNodes; ++i) m.node_tags.push_back(3 * i + 1 + rng() % 3);
  std::shuffle(m.node_tags.begin(), m.node_tags.end(), rng);
  for (std::size_t i = 0; i < 3 * kNodes; ++i) m.coords.push_back(testing_io::awkward_double(rng));
  ElementBlock quads;
  quads.type = find_element_type(3);
  quads.entity_dim = 2;
  quads.entity_tag = 1;
  for (std::size_t e = 0; e < kQuads; ++e) {
    quads.tags.push_back(2 * e + 5);
    for (int k = 0; k < 4; ++k) quads.nodes.push_back(static_cast<NodeIndex>(rng() % kNodes));
  }
  m.blocks.push_back(quads);
  m.entities.push_back({2, 1, {}, {}, {}});
  ElementField field{"eta", {}};
  for (std::size_t e = 0; e < kQuads; ++e) field.values.push_back(std::ldexp(static_cast<double>(rng() % 1000003), -20));
  const int threads = omp_get_max_threads();
  for (MeshFormat format : {MeshFormat::msh41, MeshFormat::msh22}) {
    std::string first;
    for (int t : {1, 2}) {
      omp_set_num_threads(t);
      const auto file = dir / fmt::format("m{}.msh", t);
      write_mesh(m, file, {format, false}, std::span<const ElementField>(&field, 1));
      const std::string bytes = testing_io::file_bytes(file);
      if (t == 1) first = bytes;
      EXPECT_EQ(bytes, first) << (format == MeshFormat::msh41 ? "4.1" : "2.2");
      std::vector<std::string> warnings;  // $ElementData is skipped on reading
      const Mesh back = read_mesh(file, &warnings);
      expect_same_content(m, back);
    }
  }
  omp_set_num_threads(threads);
}

TEST(MshRoundTrip, Msh22WritesAnElementOncePerPhysicalGroup) {
  ScratchDir dir("physicals");
  const ElementType* tri = find_element_type(2);
  const Mesh m = testing_io::random_mesh({tri}, 5, Layout::msh22, 4);  // entity in groups 7 and 3
  write_mesh(m, dir / "m.msh", {MeshFormat::msh22, false});
  const std::string text = testing_io::file_bytes(dir / "m.msh");
  // 4 triangles × 2 groups = 8 element lines; the copies carry physical tag 3.
  EXPECT_NE(text.find("$Elements\n8\n"), std::string::npos);
  std::size_t with3 = 0, pos = 0;
  while ((pos = text.find(" 2 2 3 ", pos)) != std::string::npos) ++with3, ++pos;
  EXPECT_EQ(with3, 4u);
  EXPECT_TRUE(read_mesh(dir / "m.msh") == m);
}

TEST(MshRoundTrip, Msh41WithoutNodeBlocksDerivesOneOnTheTopEntity) {
  ScratchDir dir("derived");
  Mesh m = testing_io::random_mesh({find_element_type(1), find_element_type(4)}, 9, Layout::msh41);
  m.node_blocks.clear();
  m.entities.clear();
  write_mesh(m, dir / "m.msh", {MeshFormat::msh41, false});
  const Mesh back = read_mesh(dir / "m.msh");
  ASSERT_EQ(back.node_blocks.size(), 1u);
  EXPECT_EQ(back.node_blocks[0].entity_dim, 3);  // the tetrahedron block's entity
  EXPECT_EQ(back.node_blocks[0].entity_tag, m.blocks[1].entity_tag);
  EXPECT_EQ(back.node_blocks[0].count, m.num_nodes());
  EXPECT_TRUE(back.entities.empty());
  expect_same_content(m, back);
  write_mesh(back, dir / "m2.msh", {MeshFormat::msh41, true});
  EXPECT_TRUE(read_mesh(dir / "m2.msh") == back);
}

TEST(MshRoundTrip, AsciiDoublesUseShortestExactDigits) {
  ScratchDir dir("digits");
  Mesh m;
  m.node_tags = {1};
  m.coords = {0.1, 1.0 / 3.0, 4.9406564584124654e-324};
  m.node_blocks = {{0, 1, 0, 1}};
  write_mesh(m, dir / "m.msh", {MeshFormat::msh41, false});
  const std::string text = testing_io::file_bytes(dir / "m.msh");
  EXPECT_NE(text.find("\n0.1 0.3333333333333333 5e-324\n"), std::string::npos) << text;
  EXPECT_TRUE(read_mesh(dir / "m.msh") == m);
}

}  // namespace
}  // namespace quadval
