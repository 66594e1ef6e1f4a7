// `quadval convert`: formats by extension, options, exit codes, and no output on failure.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "cli_run.hpp"
#include "io/io_test_support.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using testing_io::ScratchDir;

using testing_cli::CliRun;

const std::string kShared = std::string(QUADVAL_SHARED_DIR) + "/data/";

TEST(ConvertCli, MshToMshInEveryEncoding) {
  ScratchDir dir("cli");
  const std::string in = kShared + "curved/mixed_h0.6_o2.msh";
  const Mesh original = read_mesh(in);
  const CliRun r41 = testing_cli::run_cli("convert " + in + " " + (dir / "a.msh").string());
  ASSERT_EQ(r41.code, 0) << r41.err;
  EXPECT_THAT(testing_io::file_bytes(dir / "a.msh"), ::testing::StartsWith("$MeshFormat\n4.1 0 8\n"));
  EXPECT_TRUE(read_mesh(dir / "a.msh") == original);
  const CliRun r22 = testing_cli::run_cli("convert " + in + " " + (dir / "b.msh").string() + " --msh-version 2.2 --binary");
  ASSERT_EQ(r22.code, 0) << r22.err;
  EXPECT_THAT(testing_io::file_bytes(dir / "b.msh"), ::testing::StartsWith("$MeshFormat\n2.2 1 8\n"));
  const Mesh b = read_mesh(dir / "b.msh");
  EXPECT_EQ(b.coords, original.coords);
  EXPECT_EQ(b.blocks, original.blocks);
}

TEST(ConvertCli, SurfaceToMsh) {
  ScratchDir dir("cli_surface");
  testing_io::write_bytes(dir / "s.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const CliRun r = testing_cli::run_cli("convert " + (dir / "s.off").string() + " " + (dir / "s.msh").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const Mesh m = read_mesh(dir / "s.msh");
  EXPECT_EQ(m.num_nodes(), 4u);
  EXPECT_EQ(m.num_elements(), 2u);
}

TEST(ConvertCli, BadInputExitsTwoAndWritesNothing) {
  ScratchDir dir("cli_bad");
  testing_io::write_bytes(dir / "bad.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n0 1 0 2\n1\n");
  const CliRun r = testing_cli::run_cli("convert " + (dir / "bad.msh").string() + " " + (dir / "out.msh").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.msh:5: 2 nodes cannot fit in the 11 bytes left"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.msh"));
  // Nothing but the (absent) output may appear in the directory: no temporary left behind.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1u);  // bad.msh only

  const CliRun missing = testing_cli::run_cli("convert " + (dir / "none.msh").string() + " " + (dir / "out.msh").string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_THAT(missing.err, HasSubstr("none.msh: no such file"));
  const CliRun ext = testing_cli::run_cli("convert " + kShared + "tri/rect-sin-a6.msh " + (dir / "out.xyz").string());
  EXPECT_EQ(ext.code, 2);
  EXPECT_THAT(ext.err, HasSubstr("unknown extension '.xyz'"));
  const CliRun version = testing_cli::run_cli("convert " + kShared + "tri/rect-sin-a6.msh " + (dir / "o.msh").string() +
                                       " --msh-version 3");
  EXPECT_EQ(version.code, 2);
  const CliRun dir_in = testing_cli::run_cli("convert " + dir.path().string() + " " + (dir / "o.msh").string());
  EXPECT_EQ(dir_in.code, 2);
  EXPECT_THAT(dir_in.err, HasSubstr("is a directory"));
}

TEST(ConvertCli, HelpExplainsFormatsAndOptions) {
  ScratchDir dir("cli_help");
  const CliRun r = testing_cli::run_cli("convert --help");
  EXPECT_EQ(r.code, 0);
  for (const char* word : {".msh", ".vtu", ".stl", ".obj", ".off", "--msh-version", "--binary", "2.2", "4.1"})
    EXPECT_THAT(r.out, HasSubstr(word));
}

}  // namespace
}  // namespace quadval
