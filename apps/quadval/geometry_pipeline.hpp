#pragma once
// What `quadval mesh` and `quadval demo` share once Gmsh has made the triangles: the
// recombination, the outputs (meshes, SVG pictures, JSON report) and the statistics table.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "quadval/geometry.hpp"
#include "quadval/size_field.hpp"

namespace quadval::cli {

struct PipelineSettings {
  std::string title;                    ///< first line of the table, e.g. the demo's name
  std::string source;                   ///< input name for messages
  std::string picture_label;            ///< short name in picture titles (default: source)
  std::string recombine = "blossom";    ///< blossom | greedy | lookahead | none
  std::optional<SizeField> size;        ///< gives tau and the l^h histogram when set
  bool quiet = false;                   ///< no stage log, no table
};

struct PipelineOutputs {
  std::vector<std::filesystem::path> triangle_meshes;  ///< .msh / .vtu, the triangle stage
  std::vector<std::filesystem::path> result_meshes;    ///< .msh / .vtu, the final (quad) mesh
  std::filesystem::path picture_dir;   ///< SVG pictures go here when not empty
  std::filesystem::path report;        ///< JSON report when not empty
};

/// Recombines `triangles` (unless settings.recombine is "none"), writes the outputs, prints
/// the statistics table (triangle stage and quad stage) and returns the exit code: 0, or 1
/// when the recombination left triangles although an all-quad mesh was asked for (blossom).
/// `report_extra` is merged into the JSON report (e.g. the demo's name and parameters).
/// @throws InputError for unwritable outputs (and what recombine() throws).
int run_geometry_pipeline(const Triangulation& triangles, const PipelineSettings& settings,
                          const PipelineOutputs& outputs, nlohmann::json report_extra = {});

/// The message and exit code of `mesh` and `demo` in a build without Gmsh.
int no_gmsh_in_this_build(const char* command);

}  // namespace quadval::cli
