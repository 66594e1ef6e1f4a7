// quadval convert: read a mesh in any supported format and write it in another, chosen by
// the output extension.
//
//   quadval convert in.msh out.vtu
//   quadval convert in.stl out.msh --msh-version 2.2 --binary
#include <memory>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "quadval/io.hpp"

namespace quadval::cli {

namespace {

struct ConvertOptions {
  std::string input;
  std::string output;
  std::string msh_version = "4.1";
  bool binary = false;
};

int run_convert(const ConvertOptions& o) {
  const MeshFormat out_format = output_format_from_extension(o.output);  // fails before reading
  const Mesh mesh = read_mesh(o.input);
  WriteOptions w;
  w.format = out_format;
  if (out_format == MeshFormat::msh41 && o.msh_version == "2.2") w.format = MeshFormat::msh22;
  w.binary = o.binary;
  write_mesh(mesh, o.output, w);
  fmt::print("{}: {} nodes, {} elements in {} blocks -> {}\n", o.input, mesh.num_nodes(), mesh.num_elements(),
             mesh.blocks.size(), o.output);
  return kExitOk;
}

}  // namespace

void add_convert_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ConvertOptions>();
  auto* cmd = app.add_subcommand(
      "convert",
      "Convert a mesh between formats, chosen by extension.\n"
      "Reads .msh (Gmsh MSH 2.2 or 4.1, ASCII or binary), .stl (ASCII or binary), .obj, .off.\n"
      "Writes .msh (MSH 4.1 ASCII unless --msh-version / --binary say otherwise), .vtu\n"
      "(VTK XML for ParaView, Lagrange cells for curved elements), or .obj / .off (the\n"
      "triangles and quadrangles as faces; curved ones by their corners).\n"
      "Exit status: 0 done, 2 bad input (the message names the file and line or byte offset).");
  cmd->add_option("input", options->input, "Mesh to read (.msh, .stl, .obj, .off)")->required();
  cmd->add_option("output", options->output, "Mesh to write (.msh, .vtu, .obj, .off); written to a temporary file, then renamed")
      ->required();
  cmd->add_option("--msh-version", options->msh_version, "MSH version of a .msh output")
      ->check(CLI::IsMember({"2.2", "4.1"}))
      ->capture_default_str();
  cmd->add_flag("--binary", options->binary, "Write binary MSH instead of ASCII (.msh output only)");
  cmd->callback([options, &exit_code] { exit_code = run_convert(*options); });
}

}  // namespace quadval::cli
