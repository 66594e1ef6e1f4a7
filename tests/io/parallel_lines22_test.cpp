// Large ASCII MSH 2.2 sections read on several threads (io/parallel_lines.hpp): the same
// mesh as the one-by-one reading gives, on any thread count, and the same errors at the
// same lines.
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

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing_io::ScratchDir;

// A grid of side x side nodes (tags 1000 + a random permutation), its quadrangles on two
// physical groups, every tenth with a partition tag, and the boundary lines between them
// (mixed node counts in one section), as lines (line k of the file is lines[k - 1]).
struct BigMesh22 {
  std::vector<std::string> lines;
  std::vector<Tag> node_tags;  // in file order
  std::vector<double> coords;  // in file order
  std::size_t first_node_line = 0, first_element_line = 0, end_elements_line = 0;  // 1-based
  std::size_t quads = 0, boundary_lines = 0;

  std::string text() const {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
  }
};

BigMesh22 big_mesh22(int side, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  BigMesh22 m;
  const auto n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  m.node_tags.resize(n);
  std::iota(m.node_tags.begin(), m.node_tags.end(), Tag{1000});
  std::shuffle(m.node_tags.begin(), m.node_tags.end(), rng);
  const auto blank = [&] { return std::string(rng() % 3 == 0 ? "\t" : " "); };
  m.lines = {"$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", fmt::format("{}", n)};
  m.first_node_line = m.lines.size() + 1;
  for (std::size_t i = 0; i < n; ++i) {
    std::string line = fmt::format("{}", m.node_tags[i]);
    for (int k = 0; k < 3; ++k) {
      m.coords.push_back(testing_io::awkward_double(rng));
      line += blank() + (m.coords.back() > 0 && rng() % 4 == 0 ? "+" : "") + fmt::format("{}", m.coords.back());
    }
    m.lines.push_back(line + (rng() % 7 == 0 ? "\r" : ""));
  }
  m.lines.push_back("$EndNodes");
  m.lines.push_back("$Elements");
  const std::size_t count_line = m.lines.size();
  m.lines.push_back("");  // the count, set below
  m.first_element_line = m.lines.size() + 1;
  std::size_t tag = 0;
  const auto node = [&](int i, int j) { return m.node_tags[static_cast<std::size_t>(j) * static_cast<std::size_t>(side) + static_cast<std::size_t>(i)]; };
  for (int j = 0; j + 1 < side; ++j) {
    for (int i = 0; i + 1 < side; ++i) {
      ++tag;
      const std::string tags = tag % 10 == 0 ? fmt::format("3 {} 1 {}", 1 + j % 2, tag % 4 + 1) : fmt::format("2 {} 1", 1 + j % 2);
      m.lines.push_back(fmt::format("{} 3 {}{}{}{}{}{}{}{}{}", tag, tags, blank(), node(i, j), blank(), node(i + 1, j), blank(),
                                    node(i + 1, j + 1), blank(), node(i, j + 1)));
      ++m.quads;
    }
    ++tag;
    m.lines.push_back(fmt::format("{} 1 2 7 2 {} {}", tag, node(side - 1, j), node(side - 1, j + 1)));
    ++m.boundary_lines;
  }
  m.lines[count_line] = fmt::format("{}", tag);
  m.lines.push_back("$EndElements");
  m.end_elements_line = m.lines.size();
  return m;
}

Mesh read_text(const ScratchDir& dir, const std::string& text, std::vector<std::string>* warnings = nullptr) {
  return testing_io::read_mesh_text(dir / "big22.msh", text, warnings);
}

std::string read_error(const ScratchDir& dir, const std::string& text) {
  return testing_io::read_mesh_error(dir / "big22.msh", text);
}

constexpr int kSide = 200;  // 40,000 nodes, 39,601 quadrangles and 199 lines

TEST(ParallelLines22, TheSameMeshOnAnyThreadCountAndAsReadOneByOne) {
  static_assert(199 * 199 >= io::kParallelLines);
  ScratchDir dir("parallel_lines22");
  const BigMesh22 big = big_mesh22(kSide, 5);
  const int threads = omp_get_max_threads();
  Mesh read[3];
  std::vector<std::string> warnings[3];
  for (int t = 0; t < 2; ++t) {
    omp_set_num_threads(t == 0 ? 1 : std::max(2, threads));
    read[t] = read_text(dir, big.text(), &warnings[t]);
  }
  omp_set_num_threads(threads);
  // A blank line in each section: both are read one line at a time.
  BigMesh22 blanks = big;
  blanks.lines.insert(blanks.lines.begin() + static_cast<std::ptrdiff_t>(big.first_element_line + 10), "");
  blanks.lines.insert(blanks.lines.begin() + static_cast<std::ptrdiff_t>(big.first_node_line + 10), "");
  read[2] = read_text(dir, blanks.text(), &warnings[2]);
  for (int r = 0; r < 3; ++r) {
    const Mesh& m = read[r];
    EXPECT_EQ(m.node_tags, big.node_tags);
    EXPECT_EQ(m.coords, big.coords);  // exact: shortest round-trip printing
    std::size_t quads = 0, lines = 0;
    for (const ElementBlock& b : m.blocks) (b.type->gmsh_id == 3 ? quads : lines) += b.size();
    EXPECT_EQ(quads, big.quads);
    EXPECT_EQ(lines, big.boundary_lines);
    EXPECT_THAT(warnings[r], ElementsAre(HasSubstr("MSH 2.2 partition tags are not used and were dropped")));
  }
  EXPECT_EQ(read[0], read[1]);
  EXPECT_EQ(read[0], read[2]);
  // The first quadrangle, by hand: nodes (0, 0), (1, 0), (1, 1), (0, 1) of the grid.
  const ElementBlock* first = nullptr;
  for (const ElementBlock& b : read[1].blocks)
    if (first == nullptr && b.type->gmsh_id == 3 && !b.tags.empty() && b.tags[0] == 1) first = &b;
  ASSERT_NE(first, nullptr);
  const auto side = static_cast<NodeIndex>(kSide);
  EXPECT_THAT(first->element(0), ElementsAre(0u, 1u, side + 1, side));
}

TEST(ParallelLines22, ErrorsNameTheirLineInsideAndAfterLargeSections) {
  ScratchDir dir("parallel_lines22_errors");
  const BigMesh22 big = big_mesh22(kSide, 9);
  const auto with = [&](std::size_t line, const std::string& text) {
    BigMesh22 m = big;
    m.lines[line - 1] = text;
    return read_error(dir, m.text());
  };
  const auto at = [](std::size_t line, const std::string& message) {
    return HasSubstr(fmt::format("big22.msh:{}: {}", line, message));
  };
  const std::size_t node_line = big.first_node_line + 30000, element_line = big.first_element_line + 33000;
  EXPECT_THAT(with(node_line, "0 1 2 3"), at(node_line, "node tag 0, expected a tag >= 1"));
  EXPECT_THAT(with(node_line, fmt::format("{} 1 2 3", big.node_tags[5])),
              at(node_line, fmt::format("node tag {} appears twice", big.node_tags[5])));
  EXPECT_THAT(with(node_line, "12 1 2"), at(node_line, "too few values on the line"));
  EXPECT_THAT(with(node_line, "12 1 2 3 4"), at(node_line, "too many values on the line"));
  EXPECT_THAT(with(node_line, "12 1 nan 3"), at(node_line, "node y coordinate is 'nan', expected a finite number"));
  EXPECT_THAT(with(node_line, "-3 1 2 3"), at(node_line, "node tag -3, expected a tag >= 1"));
  EXPECT_THAT(with(element_line, "5 3 2 1 1 1000 1001 1002 7"),
              at(element_line, "element 5 refers to node tag 7, which is not in $Nodes"));
  EXPECT_THAT(with(element_line, "5 3 2 1 1 1000 1001 1002"), at(element_line, "too few values on the line"));
  EXPECT_THAT(with(element_line, "5 3 2 1 1 1000 1001 1002 1003 1004"), at(element_line, "too many values on the line"));
  EXPECT_THAT(with(element_line, "5 999 2 1 1 1000 1001"), at(element_line, "unknown element type id 999"));
  EXPECT_THAT(with(element_line, "0 3 2 1 1 1000 1001 1002 1003"), at(element_line, "element tag 0, expected a tag >= 1"));
  EXPECT_THAT(with(element_line, "5 3 1001 1 1 1000 1001 1002 1003"),
              at(element_line, "number of element tags is 1001, expected 0 to 1000"));
  // A vertical tab separates values but may not end a record (TextCursor::end_record).
  EXPECT_THAT(with(element_line, big.lines[element_line - 1] + "\v"), at(element_line, "too many values on the line"));
  EXPECT_THAT(with(big.end_elements_line, "$EndElementz"), at(big.end_elements_line, "expected $EndElements"));
}

// Elements that the one-by-one reading accepts but the fast path does not take (negative
// physical and elementary tags, more than one record's values spread over lines): the same
// mesh either way.
TEST(ParallelLines22, FormsOutsideTheFastPathReadAsBefore) {
  ScratchDir dir("parallel_lines22_forms");
  const BigMesh22 big = big_mesh22(kSide, 13);
  const Mesh plain = read_text(dir, big.text());
  BigMesh22 negative = big;
  std::string& line = negative.lines[big.first_element_line + 100 - 1];
  ASSERT_EQ(line.substr(0, 8), "101 3 2 ");
  line.replace(0, 9, "101 3 2 -1");  // physical -1 instead of 1 or 2
  const Mesh read = read_text(dir, negative.text());
  EXPECT_EQ(read.num_elements(), plain.num_elements());
  EXPECT_EQ(read.node_tags, plain.node_tags);
  EXPECT_EQ(read.coords, plain.coords);
}

}  // namespace
}  // namespace quadval
