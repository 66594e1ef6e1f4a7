// FileBytes: a mapped file gives the file's bytes, and stays right after its parsed pages
// are given back; reading a mesh large enough to give pages back changes nothing.
#include <gtest/gtest.h>

#include <string>

#include "io/file_bytes.hpp"
#include "io/msh_reader.hpp"
#include "io_test_support.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using testing_io::ScratchDir;

TEST(FileBytes, MappedBytesSurviveRelease) {
  ScratchDir dir("file_bytes");
  std::string bytes(3'000'000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 2654435761u) >> 13);
  testing_io::write_bytes(dir / "data.bin", bytes);
  io::FileBytes file(dir / "data.bin");
  ASSERT_EQ(file.view().size(), bytes.size());
  EXPECT_TRUE(file.view() == bytes);
  file.release_before(2'500'000);
  file.release_before(1'000'000);  // behind what was given back: nothing to do
  file.release_before(10'000'000);  // past the end: up to the last whole page
  EXPECT_TRUE(file.view() == bytes) << "bytes changed after their pages were given back";
}

TEST(FileBytes, EmptyMissingAndDirectory) {
  ScratchDir dir("file_bytes_edge");
  testing_io::write_bytes(dir / "empty.msh", "");
  io::FileBytes empty(dir / "empty.msh");
  EXPECT_TRUE(empty.view().empty());
  EXPECT_THROW(io::FileBytes(dir / "missing.msh"), InputError);
  EXPECT_THROW(io::FileBytes(dir.path()), InputError);
}

// Over io::kReleaseEvery of node and element data, in ASCII and binary: read_mesh (mapped,
// giving pages back) equals read_msh on the same bytes held in memory.
TEST(FileBytes, LargeMeshReadsTheSameAsFromMemory) {
  ScratchDir dir("file_bytes_large");
  const Mesh mesh = testing_io::random_mesh({find_element_type(4)}, 11, testing_io::Layout::msh41,
                                            900'000);
  for (const bool binary : {false, true}) {
    const auto path = dir / (binary ? "big_binary.msh" : "big_ascii.msh");
    write_mesh(mesh, path, {MeshFormat::msh41, binary});
    const std::string bytes = testing_io::file_bytes(path);
    ASSERT_GT(bytes.size(), 2 * io::kReleaseEvery);
    std::vector<std::string> warnings;
    const Mesh from_memory = io::read_msh(bytes, path.string(), warnings);
    const Mesh mapped = read_mesh(path, &warnings);
    EXPECT_TRUE(mapped == from_memory) << (binary ? "binary" : "ASCII");
    EXPECT_EQ(mapped.blocks.at(0).size(), 900'000u);
  }
}

}  // namespace
}  // namespace quadval
