// quadval: quad meshing by recombination, and certified analysis of curved elements.
//
//   quadval info mesh.msh
//   quadval convert mesh.msh mesh.vtu
//   quadval demo                      (Paper I's rectangle, pictures in ./quadval-demo/rectangle/)
//   quadval mesh part.step -o part-quads.msh --size 0.5
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "quadval/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"quadval: quad meshing by recombination, and certified bounds on the Jacobian "
               "and quality of curved finite elements."};
  app.name("quadval");
  app.set_version_flag("--version", std::string("quadval ") + QUADVAL_VERSION);
  app.require_subcommand(1);
  app.fallthrough(false);

  int exit_code = quadval::cli::kExitOk;
  quadval::cli::add_info_command(app, exit_code);
  quadval::cli::add_convert_command(app, exit_code);
  quadval::cli::add_recombine_command(app, exit_code);
  quadval::cli::add_mesh_command(app, exit_code);
  quadval::cli::add_demo_command(app, exit_code);
  quadval::cli::add_check_command(app, exit_code);

  if (argc == 1) {  // no arguments: show what there is to do
    fmt::print("{}", app.help());
    return quadval::cli::kExitOk;
  }
  const auto subcommands = app.get_subcommands({});
  const bool known = std::any_of(subcommands.begin(), subcommands.end(),
                                 [&](const CLI::App* sub) { return sub->get_name() == argv[1]; });
  if (argv[1][0] != '-' && !known) {
    std::string names;
    for (const CLI::App* sub : subcommands) names += " " + sub->get_name();
    fmt::print(stderr, "quadval: error: unknown command '{}'; the commands are:{}\n", argv[1], names);
    return quadval::cli::kExitBadInput;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : quadval::cli::kExitBadInput;
  } catch (const quadval::InputError& e) {
    fmt::print(stderr, "quadval: error: {}\n", e.what());
    return quadval::cli::kExitBadInput;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "quadval: error: out of memory\n");
    return quadval::cli::kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "quadval: internal error: {}\n", e.what());
    return 3;
  }
  return exit_code;
}
