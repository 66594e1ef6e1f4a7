// The Gmsh front end is a module loaded on demand (src/geometry/gmsh_module.hpp): the quadval
// binary itself does not need libgmsh, every other command runs without it, and a missing
// or foreign module gives a clear error and exit 2.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_run.hpp"

namespace quadval {
namespace {

using testing::HasSubstr;
using testing::Not;
using testing_cli::run_cli;
namespace fs = std::filesystem;

// The shared libraries the dynamic loader maps for a program, as ldd prints them.
std::string needed_libraries(const std::string& program) {
  const fs::path out = fs::temp_directory_path() / "quadval_gmsh_module_test_ldd.txt";
  const int rc = std::system(("ldd '" + program + "' >'" + out.string() + "' 2>&1").c_str());
  EXPECT_EQ(rc, 0);
  std::ifstream in(out);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Sets an environment variable for the CLI runs of one test (they inherit it).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() { unsetenv(name_); }

 private:
  const char* name_;
};

TEST(GmshModule, TheCliDoesNotLinkGmshAndTheModuleDoes) {
  const std::string cli = needed_libraries(QUADVAL_CLI_PATH);
  EXPECT_THAT(cli, Not(HasSubstr("libgmsh")));
  EXPECT_THAT(cli, Not(HasSubstr("libTKernel")));  // OpenCASCADE
  const fs::path module = fs::path(QUADVAL_CLI_PATH).parent_path() / "libquadval_gmsh.so";
  ASSERT_TRUE(fs::exists(module));
  EXPECT_THAT(needed_libraries(module.string()), HasSubstr("libgmsh"));
}

TEST(GmshModule, MissingModuleStopsMeshOnlyWithAClearMessage) {
  const fs::path dir = fs::temp_directory_path() / "quadval_gmsh_module_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ScopedEnv env("QUADVAL_GMSH_MODULE", (dir / "nowhere" / "libquadval_gmsh.so").string());
  const auto mesh = run_cli("mesh --domain \"outer rectangle 0 0 1 1\" -o '" +
                            (dir / "o.msh").string() + "'");
  EXPECT_EQ(mesh.code, 2) << mesh.output;
  EXPECT_THAT(mesh.err, HasSubstr("cannot load the Gmsh front end (libquadval_gmsh.so)"));
  EXPECT_THAT(mesh.err, HasSubstr("nowhere/libquadval_gmsh.so: no such file"));
  EXPECT_THAT(mesh.err, HasSubstr("apt-get install libgmsh-dev"));
  EXPECT_FALSE(fs::exists(dir / "o.msh"));
  // The other commands never load it.
  const std::string shared = QUADVAL_SHARED_DIR;
  const auto check = run_cli("check '" + shared + "/data/curved/quad_h0.4_o2.msh' -q");
  EXPECT_NE(check.code, 2) << check.output;
  EXPECT_THAT(check.err, Not(HasSubstr("Gmsh front end")));
}

TEST(GmshModule, AFileThatIsNotTheModuleIsRefused) {
  const fs::path dir = fs::temp_directory_path() / "quadval_gmsh_module_test_foreign";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "libquadval_gmsh.so") << "not a shared object\n";
  const ScopedEnv env("QUADVAL_GMSH_MODULE", (dir / "libquadval_gmsh.so").string());
  const auto demo = run_cli("demo rectangle -o '" + (dir / "out").string() + "'");
  EXPECT_EQ(demo.code, 2) << demo.output;
  EXPECT_THAT(demo.err, HasSubstr("cannot load the Gmsh front end"));
  EXPECT_THAT(demo.err, HasSubstr((dir / "libquadval_gmsh.so").string()));
}

}  // namespace
}  // namespace quadval
