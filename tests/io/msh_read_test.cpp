// MSH reading: hand-written files with known contents, and bad input of every kind, which
// must raise InputError naming the file and the line (ASCII) or byte offset (binary).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "io/io_test_support.hpp"
#include "io/msh_reader.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::ScratchDir;

// Lines:       1            2          3               4              5    6
const char* const kMsh41 =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 5 \"plate\"\n"
    // 7              8         9            10                   11
    "$EndPhysicalNames\n$Entities\n1 0 1 0\n7 0.5 0 0 0\n3 0 0 0 1 1 0 1 5 0\n"
    // 12           13        14          15        16  17
    "$EndEntities\n$Nodes\n2 4 10 40\n0 7 0 1\n40\n0.5 0 0\n"
    // 18      19  20  21  22       23       24       25
    "2 3 0 3\n10\n20\n30\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"
    // 26        27          28        29       30        31
    "$Elements\n2 2 100 201\n0 7 15 1\n201 40\n2 3 2 1\n100 10 20 30\n$EndElements\n";

const char* const kMsh22 =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n5 0 1 0\n"
    "$EndNodes\n$Elements\n4\n"
    "1 2 2 8 4 1 2 3\n"
    "2 2 2 8 4 1 3 5\n"
    "3 2 2 9 4 1 2 3\n"   // Gmsh's copy of element 1 for physical group 9
    "4 1 2 0 6 1 2\n"
    "$EndElements\n";

/// Writes `text` to a file and reads it; returns the InputError message, or "" if it read.
std::string read_error(const ScratchDir& dir, const std::string& text, const std::string& name = "bad.msh") {
  testing_io::write_bytes(dir / name, text);
  try {
    std::vector<std::string> warnings;
    read_mesh(dir / name, &warnings);
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(name));
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(MshRead, HandWritten41) {
  ScratchDir dir("hand41");
  testing_io::write_bytes(dir / "m.msh", kMsh41);
  const Mesh m = read_mesh(dir / "m.msh");
  EXPECT_EQ(m.node_tags, (std::vector<Tag>{40, 10, 20, 30}));
  EXPECT_EQ(m.coords, (std::vector<double>{0.5, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0}));
  ASSERT_EQ(m.node_blocks.size(), 2u);
  EXPECT_EQ(m.node_blocks[0], (NodeBlock{0, 7, 0, 1}));
  EXPECT_EQ(m.node_blocks[1], (NodeBlock{2, 3, 1, 3}));
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].type->gmsh_id, 15);
  EXPECT_EQ(m.blocks[0].tags, (std::vector<Tag>{201}));
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{0}));
  EXPECT_EQ(m.blocks[1].type->gmsh_id, 2);
  EXPECT_EQ(m.blocks[1].entity_dim, 2);
  EXPECT_EQ(m.blocks[1].entity_tag, 3);
  EXPECT_EQ(m.blocks[1].nodes, (std::vector<NodeIndex>{1, 2, 3}));
  ASSERT_EQ(m.entities.size(), 2u);
  EXPECT_EQ(m.entities[0].box, (std::array<double, 6>{0.5, 0, 0, 0.5, 0, 0}));
  EXPECT_EQ(m.entities[1].physical_tags, (std::vector<int>{5}));
  EXPECT_EQ(m.physical_names, (std::vector<PhysicalGroup>{{2, 5, "plate"}}));
}

TEST(MshRead, HandWritten22MergesAnElementListedForTwoGroups) {
  ScratchDir dir("hand22");
  testing_io::write_bytes(dir / "m.msh", kMsh22);
  const Mesh m = read_mesh(dir / "m.msh");
  EXPECT_TRUE(m.node_blocks.empty());
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].tags, (std::vector<Tag>{1, 2}));
  EXPECT_EQ(m.blocks[0].nodes, (std::vector<NodeIndex>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.blocks[0].entity_tag, 4);
  EXPECT_EQ(m.blocks[1].type->gmsh_id, 1);
  EXPECT_EQ(m.blocks[1].entity_dim, 1);
  EXPECT_EQ(m.blocks[1].entity_tag, 6);
  ASSERT_EQ(m.entities.size(), 2u);
  EXPECT_EQ(m.entities[0].physical_tags, (std::vector<int>{8, 9}));
  EXPECT_TRUE(m.entities[1].physical_tags.empty());
  // The same element listed twice under the same tag is merged as well.
  testing_io::write_bytes(dir / "same_tag.msh", replace(kMsh22, "3 2 2 9 4 1 2 3", "1 2 2 9 4 1 2 3"));
  EXPECT_TRUE(read_mesh(dir / "same_tag.msh") == m);
}

TEST(MshRead, SkipsUnusedSectionsWithAWarning) {
  ScratchDir dir("skip");
  std::string text = kMsh41;
  text += "$NodeData\n1\n\"u\"\n1\n0\n3\n0\n1\n1\n10 3.5\n$EndNodeData\n$Periodic\n0\n$EndPeriodic\n";
  testing_io::write_bytes(dir / "m.msh", text);
  std::vector<std::string> warnings;
  const Mesh m = read_mesh(dir / "m.msh", &warnings);
  EXPECT_EQ(m.num_elements(), 2u);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_THAT(warnings[0], HasSubstr("$NodeData"));
  EXPECT_THAT(warnings[1], HasSubstr("$Periodic"));
  EXPECT_THAT(warnings[0], HasSubstr("m.msh"));
}

TEST(MshRead, EmptyMissingAndDirectory) {
  ScratchDir dir("files");
  EXPECT_THAT(read_error(dir, ""), HasSubstr("empty file"));
  EXPECT_THAT(read_error(dir, " \n\n"), HasSubstr("empty file"));
  std::filesystem::create_directory(dir / "folder.msh");
  try {
    read_mesh(dir / "folder.msh");
    ADD_FAILURE() << "no error for a directory";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("folder.msh: is a directory"));
  }
  EXPECT_THROW(read_mesh(dir / "none.msh"), InputError);
  EXPECT_THROW(read_mesh(dir / "m.xyz"), InputError);
}

TEST(MshRead, AsciiErrorsNameTheLine) {
  ScratchDir dir("ascii_errors");
  const std::string ok = kMsh41;
  EXPECT_THAT(read_error(dir, replace(ok, "100 10 20 30", "100 10 20 99")),
              HasSubstr("bad.msh:31: element 100 refers to node tag 99, which is not in $Nodes"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 3 2 1", "2 3 999 1")),
              HasSubstr("bad.msh:30: unknown element type id 999"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 3 2 1", "2 3 76 1")), HasSubstr("unknown element type id 76"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 3 2 1", "2 3 34 1")), HasSubstr("variable node count"));
  EXPECT_THAT(read_error(dir, replace(ok, "1 0 0\n0 1 0", "1 nan 0\n0 1 0")),
              HasSubstr("bad.msh:23: node y coordinate is 'nan', expected a finite number"));
  EXPECT_THAT(read_error(dir, replace(ok, "1 0 0\n0 1 0", "1 0 -inf\n0 1 0")), HasSubstr("finite"));
  EXPECT_THAT(read_error(dir, replace(ok, "1 0 0\n0 1 0", "1 0 1e999\n0 1 0")), HasSubstr("range"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 4 10 40", "2 5 10 40")), HasSubstr("header says 5 nodes, its blocks hold 4"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 2 100 201", "2 3 100 201")), HasSubstr("says 3 elements"));
  EXPECT_THAT(read_error(dir, replace(ok, "100 10 20 30", "100 10 20 30 40")),
              HasSubstr("bad.msh:31: too many values on the line"));
  EXPECT_THAT(read_error(dir, replace(ok, "100 10 20 30", "100 10 20\n30")),
              HasSubstr("bad.msh:31: too few values on the line"));
  EXPECT_THAT(read_error(dir, replace(ok, "20\n30", "20\n10")), HasSubstr("node tag 10 appears twice"));
  EXPECT_THAT(read_error(dir, replace(ok, "4.1 0 8", "3.0 0 8")), HasSubstr("bad.msh:2: MSH version 3.0 is not supported"));
  EXPECT_THAT(read_error(dir, replace(ok, "4.1 0 8", "4.1 0 4")), HasSubstr("data size 4"));
  EXPECT_THAT(read_error(dir, "$NOD\n1\n1 0 0 0\n$ENDNOD\n"), HasSubstr("MSH version 1"));
  EXPECT_THAT(read_error(dir, "solid x\n"), HasSubstr("expected $MeshFormat"));
  EXPECT_THAT(read_error(dir, replace(ok, "$EndNodes", "$EndNodez")), HasSubstr("bad.msh:25: expected $EndNodes"));
  // A section that never ends, and sections missing from a file cut at a section boundary.
  EXPECT_THAT(read_error(dir, ok + "$NodeData\n1\n"), HasSubstr("not closed by $EndNodeData"));
  EXPECT_THAT(read_error(dir, ok.substr(0, ok.find("$Elements"))), HasSubstr("without an $Elements section"));
  // 2.2
  const std::string ok22 = kMsh22;
  EXPECT_THAT(read_error(dir, replace(ok22, "4 1 2 0 6 1 2", "4 1 2 0 6 1 4")),
              HasSubstr("bad.msh:16: element 4 refers to node tag 4"));
  EXPECT_THAT(read_error(dir, replace(ok22, "3 2 2 9 4 1 2 3", "1 2 2 9 4 1 2 5")),
              HasSubstr("bad.msh:15: element tag 1 appears twice"));
  EXPECT_THAT(read_error(dir, replace(ok22, "$Nodes\n4\n", "$Nodes\n5\n")), HasSubstr("bad.msh:10: expected node tag"));
}

TEST(MshRead, HugeCountsFailBeforeAllocating) {
  ScratchDir dir("huge");
  const std::string ok = kMsh41;
  EXPECT_THAT(read_error(dir, replace(ok, "2 4 10 40", "2 1000000000000000 10 40")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 4 10 40", "18446744073709551615 4 10 40")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 3 2 1", "2 3 2 100000000000")), HasSubstr("more elements than"));
  EXPECT_THAT(read_error(dir, replace(ok, "2 2 100 201", "2 4000000000 100 201")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(ok, "1 0 1 0", "1 0 99999999999 0")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(ok, "1 5 0", "4000000000 5 0")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(kMsh22, "$Nodes\n4\n", "$Nodes\n4000000000000\n")), HasSubstr("cannot fit"));
  EXPECT_THAT(read_error(dir, replace(kMsh22, "$Elements\n4\n", "$Elements\n4000000000000\n")), HasSubstr("cannot fit"));
  // A node tag far beyond the count must not size the lookup table by the tag.
  const std::string far = replace(replace(ok, "\n40\n", "\n18446744073709551000\n"), "201 40", "201 18446744073709551000");
  testing_io::write_bytes(dir / "far.msh", far);
  EXPECT_EQ(read_mesh(dir / "far.msh").node_tags[0], 18446744073709551000ull);
}

/// A binary file of a small random mesh, with the offsets of some landmarks.
std::string binary_file(const ScratchDir& dir, MeshFormat format) {
  const Mesh m = testing_io::random_mesh({find_element_type(2), find_element_type(11)}, 3,
                                         format == MeshFormat::msh41 ? testing_io::Layout::msh41
                                                                     : testing_io::Layout::msh22);
  write_mesh(m, dir / "bin.msh", {format, true});
  return testing_io::file_bytes(dir / "bin.msh");
}

TEST(MshRead, BinaryErrorsNameTheByteOffset) {
  ScratchDir dir("binary_errors");
  for (MeshFormat format : {MeshFormat::msh41, MeshFormat::msh22}) {
    SCOPED_TRACE(format == MeshFormat::msh41 ? "4.1" : "2.2");
    const std::string ok = binary_file(dir, format);
    // Foreign endianness: the int 1 after the header line, byte-swapped.
    const std::size_t marker = ok.find("8\n") + 2;
    std::string swapped = ok;
    std::swap(swapped[marker], swapped[marker + 3]);
    EXPECT_THAT(read_error(dir, swapped), HasSubstr("bad.msh: byte offset " + std::to_string(marker) + ": binary data of the other byte order"));
    std::string wrong = ok;
    wrong[marker] = 7;
    EXPECT_THAT(read_error(dir, wrong), HasSubstr("endianness marker is 7"));
    // Truncated in the middle of the node data.
    const std::size_t nodes = ok.find("$Nodes\n") + 7;
    EXPECT_THAT(read_error(dir, ok.substr(0, nodes + 40)),
                ::testing::MatchesRegex(".*bad.msh: byte offset [0-9]+: (unexpected end of file|the file is too short).*"));
    EXPECT_THAT(read_error(dir, ok.substr(0, ok.size() - 30)), HasSubstr("byte offset"));
    // A NaN coordinate: the first x of the first node.
    std::string nan = ok;
    // 4.1: header (4 size_t), block header (3 int, 1 size_t), the block's tags; 2.2: count line, tag.
    std::vector<std::string> w;
    const std::size_t first_block = io::read_msh(ok, "ok.msh", w).node_blocks.empty()
                                        ? 0 : io::read_msh(ok, "ok.msh", w).node_blocks[0].count;
    const std::size_t x = format == MeshFormat::msh41 ? nodes + 32 + 20 + 8 * first_block
                                                      : ok.find("\n", nodes) + 1 + 4;
    const double q = std::numeric_limits<double>::quiet_NaN();
    std::memcpy(nan.data() + x, &q, 8);
    EXPECT_THAT(read_error(dir, nan), HasSubstr("byte offset " + std::to_string(x) + ": node x coordinate is nan"));
  }
}

// Every prefix of a file, and many single-byte corruptions, either read or raise
// InputError: nothing else escapes (no crash, no bad_alloc, no hang). Parses from memory
// (io::read_msh, what read_mesh calls) to stay fast.
TEST(MshRead, PrefixesAndCorruptionsRaiseOnlyInputError) {
  ScratchDir dir("prefixes");
  std::vector<std::string> files = {kMsh41, kMsh22, binary_file(dir, MeshFormat::msh41),
                                    binary_file(dir, MeshFormat::msh22)};
  std::mt19937_64 rng(1);
  std::vector<std::string> warnings;
  for (const std::string& full : files) {
    const Mesh whole = io::read_msh(full, "whole.msh", warnings);
    for (std::size_t n = 0; n < full.size(); ++n) {
      try {
        const Mesh m = io::read_msh(std::string_view(full).substr(0, n), "p.msh", warnings);
        EXPECT_TRUE(m == whole) << "a prefix of " << n << " bytes read as a different mesh";
      } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("p.msh"));
      }
    }
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bad = full;
      for (int k = 0; k < 1 + trial % 3; ++k) bad[rng() % bad.size()] = static_cast<char>(rng());
      try {
        io::read_msh(bad, "c.msh", warnings);
      } catch (const InputError&) {
      }
    }
  }
}

}  // namespace
}  // namespace quadval
