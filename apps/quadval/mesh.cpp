// quadval mesh: from a geometry (or a planar domain) to an all-quad mesh: Gmsh triangles with
// an odd number of interior nodes on every model edge, then Blossom-Quad (Paper I §7).
//
//   quadval mesh part.step -o part-quads.msh --size "2 + 0.1*z" --report part.json
//   quadval mesh --domain "outer rectangle 0 0 1 1; hole circle 0.75 0.75 0.15" -o q.vtu --size 0.03
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "geometry_pipeline.hpp"
#include "quadval/error.hpp"
#include "quadval/geometry.hpp"
#include "quadval/io.hpp"
#include "quadval/planar_domain.hpp"

namespace quadval::cli {
namespace {

struct MeshCliOptions {
  std::string geometry, domain, output, report, size, triangles_output, pictures;
  double size_min = 0, size_max = 0;
  std::string triangles = "frontal-quad", recombine = "blossom";
  bool verbose = false, quiet = false, even_curves_allowed = false;
};

#if defined(QUADVAL_WITH_GMSH)
int run(const MeshCliOptions& o) {
  if (o.geometry.empty() == o.domain.empty())
    throw InputError::in_file("quadval mesh",
                              "give exactly one of GEOMETRY (a .geo, .step, .stp, .brep, .stl or "
                              "planar-domain .txt file) and --domain \"outer ...; hole ...\"");
  output_format_from_extension(o.output);  // a bad output name fails before the meshing
  if (!o.triangles_output.empty()) output_format_from_extension(o.triangles_output);
  TriangulationOptions t;
  t.algorithm = o.triangles == "frontal" ? TriangleAlgorithm::frontal
                : o.triangles == "delaunay" ? TriangleAlgorithm::delaunay
                                            : TriangleAlgorithm::frontal_quad;
  if (!o.size.empty()) t.size = SizeField::from_expression(o.size);
  if (o.size_min < 0 || o.size_max < 0 || (o.size_max > 0 && o.size_min > o.size_max))
    throw InputError::in_file("quadval mesh",
                              fmt::format("--size-min {} and --size-max {} must be positive with "
                                          "min <= max",
                                          o.size_min, o.size_max));
  t.size_min = o.size_min;
  if (o.size_max > 0) t.size_max = o.size_max;
  t.verbose = o.verbose;
  t.odd_curve_nodes = !o.even_curves_allowed;

  PipelineSettings settings;
  Triangulation tri;
  const std::filesystem::path geometry(o.geometry);
  const std::string ext = geometry.extension().string();
  if (!o.domain.empty() || ext == ".txt" || ext == ".domain") {
    const PlanarDomain domain = o.domain.empty() ? read_planar_domain(geometry)
                                                 : parse_planar_domain(o.domain, "--domain");
    // Without a size, one twentieth of the domain's larger side: a readable first mesh.
    if (!t.size && o.size_max <= 0) {
      const auto box = domain_bounding_box(domain);
      t.size = SizeField::constant(std::max(box[3] - box[0], box[4] - box[1]) / 20);
    }
    tri = triangulate_planar_domain(domain, t);
    settings.source = domain.source;
  } else {
    tri = triangulate_geometry_file(geometry, t);
    settings.source = o.geometry;
  }
  settings.picture_label = o.domain.empty() ? geometry.filename().string() : "planar domain";
  settings.recombine = o.recombine;
  settings.size = t.size;
  settings.quiet = o.quiet;
  PipelineOutputs outputs;
  outputs.result_meshes = {o.output};
  if (!o.triangles_output.empty()) outputs.triangle_meshes = {o.triangles_output};
  outputs.picture_dir = o.pictures;
  outputs.report = o.report;
  nlohmann::json extra = {{"command", "mesh"},
                          {"triangles_algorithm", triangle_algorithm_name(t.algorithm)}};
  return run_geometry_pipeline(tri, settings, outputs, extra);
}
#else
int run(const MeshCliOptions&) { return no_gmsh_in_this_build("mesh"); }
#endif

}  // namespace

void add_mesh_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<MeshCliOptions>();
  auto* cmd = app.add_subcommand(
      "mesh",
      "Mesh a geometry (.geo, .step/.stp, .brep, .stl) or a planar domain with quadrangles: Gmsh "
      "triangles with an odd number of interior nodes on every model edge, then Blossom-Quad");
  cmd->add_option("geometry", o->geometry,
                  "Geometry file, or a planar-domain text file (.txt/.domain: 'outer rectangle 0 "
                  "0 1 1', 'hole circle 0.5 0.5 0.1', ...)");
  cmd->add_option("--domain", o->domain,
                  "Planar domain on the command line, statements separated by ';'");
  cmd->add_option("-o,--output", o->output, "Output mesh (.msh or .vtu, with the element field 'eta'; or .obj, .off)")
      ->required();
  cmd->add_option("--size", o->size,
                  "Size field h(x,y,z), e.g. \"0.1 + 0.08*sin(3*x)*cos(6*y)\" (variables x y z; "
                  "sin cos exp sqrt min max ...)");
  cmd->add_option("--size-min", o->size_min, "Smallest mesh size (Gmsh Mesh.MeshSizeMin)");
  cmd->add_option("--size-max", o->size_max, "Largest mesh size (Gmsh Mesh.MeshSizeMax)");
  cmd->add_option("--triangles", o->triangles,
                  "Triangulation: frontal-quad (right-angled triangles, Gmsh algorithm 8), "
                  "frontal (6) or delaunay (5)")
      ->check(CLI::IsMember({"frontal-quad", "frontal", "delaunay"}))
      ->capture_default_str();
  cmd->add_option("--recombine", o->recombine,
                  "blossom (optimal, all-quad), lookahead, greedy (quad-dominant) or none "
                  "(keep the triangles)")
      ->check(CLI::IsMember({"blossom", "lookahead", "greedy", "none"}))
      ->capture_default_str();
  cmd->add_option("--triangles-output", o->triangles_output,
                  "Also write the triangles (.msh, .vtu, .obj or .off)");
  cmd->add_option("--pictures", o->pictures,
                  "Directory for SVG pictures: mesh coloured by eta, histograms of eta and l^h");
  cmd->add_option("--report", o->report, "Write the statistics as JSON to this file");
  cmd->add_flag("--plain-curves", o->even_curves_allowed,
                "Let Gmsh choose curve node counts freely (no odd-count rule; for comparison)");
  cmd->add_flag("-v,--verbose", o->verbose, "Show Gmsh's own messages");
  cmd->add_flag("-q,--quiet", o->quiet, "No log and no table");
  cmd->callback([o, &exit_code]() { exit_code = run(*o); });
}

}  // namespace quadval::cli
