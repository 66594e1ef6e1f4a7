// The `quadval` entry point: help with no arguments, --version, unknown commands.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_run.hpp"

namespace quadval {
namespace {

using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using testing_cli::run_cli;

TEST(MainCli, NoArgumentsShowsTheCommands) {
  const auto r = run_cli("");
  EXPECT_EQ(r.code, 0);
  for (const char* command : {"info", "convert", "check", "recombine", "mesh", "demo"})
    EXPECT_THAT(r.out, HasSubstr(command));
  EXPECT_THAT(r.out, HasSubstr("Usage: quadval"));
}

TEST(MainCli, VersionIsSemantic) {
  const auto r = run_cli("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_THAT(r.out, MatchesRegex("quadval [0-9]+\\.[0-9]+\\.[0-9]+\n"));
}

TEST(MainCli, UnknownCommandExitsTwoAndListsTheCommands) {
  const auto r = run_cli("chek mesh.msh");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown command 'chek'"));
  EXPECT_THAT(r.err, HasSubstr("check"));
}

TEST(MainCli, MissingArgumentExitsTwo) {
  const auto r = run_cli("check");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.output, HasSubstr("required"));
}

}  // namespace
}  // namespace quadval
