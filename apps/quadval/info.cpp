#include "commands.hpp"
namespace quadval::cli {
void add_info_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("info", "Counts by element type, bounding box, triangle-mesh topology");
  (void)cmd; (void)exit_code;
}
}  // namespace quadval::cli
