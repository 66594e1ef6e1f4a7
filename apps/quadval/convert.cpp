#include "commands.hpp"
namespace quadval::cli {
void add_convert_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("convert", "Convert a mesh between formats (by extension)");
  (void)cmd; (void)exit_code;
}
}  // namespace quadval::cli
