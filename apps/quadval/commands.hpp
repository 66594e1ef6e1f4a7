#pragma once
// One function per subcommand: each adds itself to the app and runs when chosen.
#include <CLI/CLI.hpp>

namespace quadval::cli {

/// Exit codes shared by every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFindings = 1;  ///< e.g. `check` found invalid or undetermined elements
inline constexpr int kExitBadInput = 2;

/// Each add_* registers a subcommand; its callback stores the exit code in `exit_code`.
void add_info_command(CLI::App& app, int& exit_code);
void add_convert_command(CLI::App& app, int& exit_code);
void add_recombine_command(CLI::App& app, int& exit_code);
void add_mesh_command(CLI::App& app, int& exit_code);
void add_demo_command(CLI::App& app, int& exit_code);
void add_check_command(CLI::App& app, int& exit_code);

}  // namespace quadval::cli
