// Large ASCII MSH 4.1 blocks read on several threads (io/parallel_lines.hpp): the same mesh
// as the generator wrote and as the one-by-one reading gives, on any thread count, and the
// same errors at the same lines, before, inside and after such blocks.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <fmt/core.h>

#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "io/io_test_support.hpp"
#include "io/parallel_lines.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::ScratchDir;

// A grid of side x side nodes (tags 1000 + a random permutation) and its quadrangles, as
// lines (line k of the file is lines[k - 1]), with the values written in every form the
// reader accepts: shortest round-trip doubles, some with '+', tabs, trailing blanks, "\r\n".
struct BigMesh {
  std::vector<std::string> lines;
  std::vector<Tag> node_tags;                 // in file order
  std::vector<double> coords;                 // in file order
  std::vector<Tag> quad_tags;
  std::vector<NodeIndex> quad_nodes;          // positions in file order
  std::size_t first_tag_line = 0, first_coordinate_line = 0, first_quad_line = 0;  // 1-based
  std::size_t end_elements_line = 0;

  std::string text() const {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
  }
};

BigMesh big_mesh(int side, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  BigMesh m;
  const auto n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  std::vector<Tag> tag_of_grid(n);
  std::iota(tag_of_grid.begin(), tag_of_grid.end(), Tag{1000});
  std::shuffle(tag_of_grid.begin(), tag_of_grid.end(), rng);
  // File order: the grid's order; tags permuted.
  m.node_tags = tag_of_grid;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) m.coords.push_back(testing_io::awkward_double(rng));
  const auto blank = [&] { return std::string(rng() % 3 == 0 ? "\t" : " "); };
  m.lines = {"$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Nodes"};
  m.lines.push_back(fmt::format("1 {} 1000 {}", n, 999 + n));
  m.lines.push_back(fmt::format("2 1 0 {}", n));
  m.first_tag_line = m.lines.size() + 1;
  for (Tag t : m.node_tags) m.lines.push_back(fmt::format("{}{}", t, rng() % 5 == 0 ? " " : ""));
  m.first_coordinate_line = m.lines.size() + 1;
  for (std::size_t i = 0; i < n; ++i) {
    std::string line;
    for (int k = 0; k < 3; ++k) {
      const double x = m.coords[3 * i + static_cast<std::size_t>(k)];
      line += (k ? blank() : "") + (x > 0 && rng() % 4 == 0 ? "+" : "") + fmt::format("{}", x);
    }
    m.lines.push_back(line + (rng() % 7 == 0 ? "\r" : ""));
  }
  m.lines.push_back("$EndNodes");
  m.lines.push_back("$Elements");
  const auto q = static_cast<std::size_t>(side - 1) * static_cast<std::size_t>(side - 1);
  m.lines.push_back(fmt::format("1 {} 1 {}", q, q));
  m.lines.push_back(fmt::format("2 1 3 {}", q));
  m.first_quad_line = m.lines.size() + 1;
  for (int j = 0; j + 1 < side; ++j)
    for (int i = 0; i + 1 < side; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * static_cast<std::size_t>(side) + static_cast<std::size_t>(i);
      const std::size_t corners[4] = {c, c + 1, c + 1 + static_cast<std::size_t>(side), c + static_cast<std::size_t>(side)};
      m.quad_tags.push_back(m.quad_tags.size() + 1);
      std::string line = fmt::format("{}", m.quad_tags.back());
      for (std::size_t v : corners) {
        line += blank() + fmt::format("{}", m.node_tags[v]);
        m.quad_nodes.push_back(static_cast<NodeIndex>(v));
      }
      m.lines.push_back(line);
    }
  m.lines.push_back("$EndElements");
  m.end_elements_line = m.lines.size();
  return m;
}

Mesh read_text(const ScratchDir& dir, const std::string& text) {
  return testing_io::read_mesh_text(dir / "big.msh", text);
}

std::string read_error(const ScratchDir& dir, const std::string& text) {
  return testing_io::read_mesh_error(dir / "big.msh", text);
}

// 200 x 200 nodes, 199 x 199 quadrangles: every block above kParallelLines.
constexpr int kSide = 200;

TEST(ParallelLines, TheGeneratorsMeshOnAnyThreadCountAndAsReadOneByOne) {
  static_assert(199 * 199 >= io::kParallelLines);
  ScratchDir dir("parallel_lines");
  const BigMesh big = big_mesh(kSide, 7);
  const int threads = omp_get_max_threads();
  Mesh read[3];
  for (int t = 0; t < 2; ++t) {
    omp_set_num_threads(t == 0 ? 1 : std::max(2, threads));
    read[t] = read_text(dir, big.text());
  }
  omp_set_num_threads(threads);
  // A blank line inside each block: that block is read one line at a time.
  BigMesh blanks = big;
  blanks.lines.insert(blanks.lines.begin() + static_cast<std::ptrdiff_t>(big.first_quad_line + 10), "");
  blanks.lines.insert(blanks.lines.begin() + static_cast<std::ptrdiff_t>(big.first_coordinate_line + 10), "");
  blanks.lines.insert(blanks.lines.begin() + static_cast<std::ptrdiff_t>(big.first_tag_line + 10), "");
  read[2] = read_text(dir, blanks.text());
  for (const Mesh& m : read) {
    EXPECT_EQ(m.node_tags, big.node_tags);
    EXPECT_EQ(m.coords, big.coords);  // exact: shortest round-trip printing
    ASSERT_EQ(m.blocks.size(), 1u);
    EXPECT_EQ(m.blocks[0].type->gmsh_id, 3);
    EXPECT_EQ(m.blocks[0].tags, big.quad_tags);
    EXPECT_EQ(m.blocks[0].nodes, big.quad_nodes);
  }
  EXPECT_EQ(read[0], read[1]);
  EXPECT_EQ(read[0], read[2]);
}

TEST(ParallelLines, ErrorsNameTheirLineInsideAndAfterLargeBlocks) {
  ScratchDir dir("parallel_lines_errors");
  const BigMesh big = big_mesh(kSide, 11);
  const auto with = [&](std::size_t line, const std::string& text) {
    BigMesh m = big;
    m.lines[line - 1] = text;
    return read_error(dir, m.text());
  };
  const auto at = [](std::size_t line, const std::string& message) {
    return HasSubstr(fmt::format("big.msh:{}: {}", line, message));
  };
  const std::size_t tag_line = big.first_tag_line + 30000, coordinate_line = big.first_coordinate_line + 25000;
  const std::size_t quad_line = big.first_quad_line + 33000;
  EXPECT_THAT(with(tag_line, "0"), at(tag_line, "node tag 0, expected a tag >= 1"));
  EXPECT_THAT(with(tag_line, fmt::format("{}", big.node_tags[5])),
              at(tag_line, fmt::format("node tag {} appears twice", big.node_tags[5])));
  EXPECT_THAT(with(tag_line, "12x"), at(tag_line, "expected node tag (a non-negative integer), found '12x'"));
  EXPECT_THAT(with(coordinate_line, "0 nan 1"), at(coordinate_line, "node y coordinate is 'nan', expected a finite number"));
  EXPECT_THAT(with(coordinate_line, "0 1 1e999"), at(coordinate_line, "node z coordinate '1e999' is out of the range of double"));
  // Values are read one after another across line ends: one short line shifts the rest,
  // and the last coordinate then meets $EndNodes.
  const std::size_t end_nodes_line = big.first_coordinate_line + big.node_tags.size();
  EXPECT_THAT(with(coordinate_line, "0 1"),
              at(end_nodes_line, "expected node z coordinate (a number), found '$EndNodes'"));
  EXPECT_THAT(with(quad_line, "5 1000 1001 1002 7"),
              at(quad_line, "element 5 refers to node tag 7, which is not in $Nodes"));
  EXPECT_THAT(with(quad_line, "5 1000 1001 1002"), at(quad_line, "too few values on the line"));
  EXPECT_THAT(with(quad_line, "5 1000 1001 1002 1003 1004"), at(quad_line, "too many values on the line"));
  // A vertical tab separates values but may not end a record (TextCursor::end_record).
  EXPECT_THAT(with(quad_line, big.lines[quad_line - 1] + "\v"), at(quad_line, "too many values on the line"));
  EXPECT_THAT(with(big.end_elements_line, "$EndElementz"), at(big.end_elements_line, "expected $EndElements"));
  // One value too many at the end of the tags: the coordinates take it, and one of theirs
  // is left where $EndNodes should be.
  EXPECT_THAT(with(big.first_coordinate_line - 1, fmt::format("{} 5", big.node_tags.back())),
              at(end_nodes_line - 1, "expected $EndNodes"));
}

// The fast path itself: taken on the plain form, the cursor then where reading the values
// one by one leaves it (after the last value, on the last line); refused, nothing changed,
// on a blank line, a bad value or an unknown node tag.
TEST(ParallelLines, ElementLinesTakenOrRefusedWithoutChange) {
  const std::uint64_t count = io::kParallelLines + 5;
  io::TagIndex index(10);
  for (Tag t = 1; t <= 4; ++t) index.insert(t, static_cast<std::uint32_t>(t - 1));
  std::string text = "2 1 3 " + std::to_string(count) + "  \n";
  for (std::uint64_t e = 0; e < count; ++e) text += fmt::format("{} {} 2 3 {}\n", e + 1, 1 + e % 4, 4 - e % 2);
  text += "$EndElements\n";
  const auto run = [&](io::TextCursor& in, std::vector<Tag>& tags, std::vector<NodeIndex>& nodes) {
    in.token("");  // the header's values, one by one
    in.token("");
    in.token("");
    in.token("");
    return io::read_element_lines(in, count, 4, index, tags, nodes);
  };
  {
    io::TextCursor in(text, "x.msh");
    std::vector<Tag> tags{99};
    std::vector<NodeIndex> nodes{7};
    ASSERT_TRUE(run(in, tags, nodes));
    ASSERT_EQ(tags.size(), count + 1);
    ASSERT_EQ(nodes.size(), 4 * count + 1);
    EXPECT_EQ(tags[0], 99u);
    EXPECT_EQ(nodes[0], 7u);
    for (std::uint64_t e = 0; e < count; ++e) {
      EXPECT_EQ(tags[1 + e], e + 1);
      EXPECT_EQ(nodes[1 + 4 * e], e % 4);
      EXPECT_EQ(nodes[4 + 4 * e], 3 - e % 2);
    }
    EXPECT_EQ(in.line(), static_cast<long>(count) + 1);
    EXPECT_EQ(text.substr(in.position(), 13), "\n$EndElements");
    EXPECT_EQ(in.token(""), "$EndElements");
  }
  for (const auto& [from, to] : {std::pair{"\n71 ", "\n\n71 "}, std::pair{"\n71 3", "\n71 x"}, std::pair{"\n71 3", "\n71 5"},
                                 std::pair{"\n71 3 2 3 4", "\n71 3 2 3"}}) {
    std::string bad = text;
    bad.replace(bad.find(from), std::string(from).size(), to);
    io::TextCursor in(bad, "x.msh");
    std::vector<Tag> tags{99};
    std::vector<NodeIndex> nodes{7};
    EXPECT_FALSE(run(in, tags, nodes)) << to;
    EXPECT_EQ(tags, std::vector<Tag>{99});
    EXPECT_EQ(nodes, std::vector<NodeIndex>{7});
    EXPECT_EQ(in.line(), 1);
    EXPECT_EQ(bad.substr(in.position(), 3), "  \n");
  }
}

}  // namespace
}  // namespace quadval
