// quadval demo: built-in end-to-end examples that need no input file (Paper I's test cases):
// planar domain -> Gmsh triangles (odd node counts on every model edge) -> Blossom-Quad ->
// statistics table, meshes (MSH, VTU), SVG pictures and a JSON report.
//
//   quadval demo                 # Paper I's rectangle, into ./quadval-demo/rectangle/
//   quadval demo square-hole -o /tmp/demos
//   quadval demo --list
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "geometry_pipeline.hpp"
#include "quadval/error.hpp"
#include "quadval/geometry.hpp"
#include "quadval/planar_domain.hpp"

namespace quadval::cli {
namespace {

struct Demo {
  const char* name;
  const char* description;
  const char* domain;  // planar_domain.hpp text
  const char* size;    // size_field.hpp expression
};

// The first one is the default.
constexpr Demo kDemos[] = {
    {"rectangle",
     "Paper I's rectangle [0,1]x[0,3] with h = 0.1 + 0.08 sin(3x) cos(6y) (Paper I Figs. 1-4)",
     "outer rectangle 0 0 1 3", "0.1 + 0.08*sin(3*x)*cos(6*y)"},
    // Paper I §8.1 grows h from 0.003 on the medial axis; this one grows it linearly with the
    // distance to the boundary (sides and hole), from 0.01 there, so the demo runs in seconds.
    {"square-hole",
     "Paper I §8.1: unit square with a hole of radius 0.15 at (0.75, 0.75); h = 0.01 + 0.3 d, "
     "d the distance to the sides and the hole",
     "outer rectangle 0 0 1 1; hole circle 0.75 0.75 0.15",
     "0.01 + 0.3*min(x, 1-x, y, 1-y, sqrt((x-0.75)^2 + (y-0.75)^2) - 0.15)"},
    {"uniform-square", "unit square with a uniform size h = 0.05", "outer rectangle 0 0 1 1",
     "0.05"},
};

struct DemoCliOptions {
  std::string name = kDemos[0].name;
  std::string output_dir = "quadval-demo";
  std::string triangles = "frontal-quad", recombine = "blossom";
  bool list = false, verbose = false, quiet = false;
};

// "rectangle, square-hole, ...": the demos' names, for messages and --help.
std::string demo_names() {
  std::string names;
  for (const Demo& d : kDemos) {
    if (!names.empty()) names += ", ";
    names += d.name;
  }
  return names;
}

const Demo* find_demo(const std::string& name) {
  for (const Demo& d : kDemos)
    if (name == d.name) return &d;
  return nullptr;
}

#if defined(QUADVAL_WITH_GMSH)
int run(const DemoCliOptions& o) {
  if (o.list) {
    for (const Demo& d : kDemos) fmt::print("{:<16}{}\n", d.name, d.description);
    return kExitOk;
  }
  const Demo* demo = find_demo(o.name);
  if (!demo) {
    const std::string names = demo_names();
    throw InputError::in_file("quadval demo",
                              fmt::format("no demo called '{}'; the demos are {}", o.name, names));
  }
  const std::filesystem::path dir = std::filesystem::path(o.output_dir) / demo->name;
  std::filesystem::create_directories(dir);

  TriangulationOptions t;
  t.algorithm = o.triangles == "frontal" ? TriangleAlgorithm::frontal
                : o.triangles == "delaunay" ? TriangleAlgorithm::delaunay
                                            : TriangleAlgorithm::frontal_quad;
  t.size = SizeField::from_expression(demo->size);
  t.verbose = o.verbose;
  const PlanarDomain domain = parse_planar_domain(demo->domain, std::string("demo ") + demo->name);
  const Triangulation tri = triangulate_planar_domain(domain, t);

  PipelineSettings settings;
  settings.title = fmt::format("quadval demo {}: {}", demo->name, demo->description);
  settings.source = domain.source;
  settings.picture_label = std::string("demo ") + demo->name;
  settings.recombine = o.recombine;
  settings.size = t.size;
  settings.quiet = o.quiet;
  PipelineOutputs outputs;
  outputs.triangle_meshes = {dir / "triangles.msh", dir / "triangles.vtu"};
  outputs.result_meshes = {dir / "quads.msh", dir / "quads.vtu"};
  outputs.picture_dir = dir;
  outputs.report = dir / "report.json";
  nlohmann::json extra = {{"command", "demo"},
                          {"demo", demo->name},
                          {"description", demo->description},
                          {"domain", demo->domain},
                          {"triangles_algorithm", triangle_algorithm_name(t.algorithm)}};
  const int rc = run_geometry_pipeline(tri, settings, outputs, extra);
  if (!o.quiet) fmt::print("Open {} in a browser to see the pictures.\n", (dir / "quads-eta.svg").string());
  return rc;
}
#else
int run(const DemoCliOptions&) { return no_gmsh_in_this_build("demo"); }
#endif

}  // namespace

void add_demo_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<DemoCliOptions>();
  const std::string names = demo_names();
  auto* cmd = app.add_subcommand(
      "demo", "Run a built-in example end to end (no input file): triangles, quads, statistics, "
              "meshes, SVG pictures");
  cmd->add_option("name", o->name, "Which demo: " + names)->capture_default_str();
  cmd->add_flag("--list", o->list, "List the demos and exit");
  cmd->add_option("-o,--output-dir", o->output_dir,
                  "Outputs go to OUTPUT_DIR/NAME/ (triangles.msh/.vtu, quads.msh/.vtu, "
                  "quads-eta.svg, eta-histogram.svg, edge-length-histogram.svg, report.json)")
      ->capture_default_str();
  cmd->add_option("--triangles", o->triangles, "frontal-quad, frontal or delaunay")
      ->check(CLI::IsMember({"frontal-quad", "frontal", "delaunay"}))
      ->capture_default_str();
  cmd->add_option("--recombine", o->recombine, "blossom, lookahead, greedy or none")
      ->check(CLI::IsMember({"blossom", "lookahead", "greedy", "none"}))
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", o->verbose, "Show Gmsh's own messages");
  cmd->add_flag("-q,--quiet", o->quiet, "No log and no table");
  cmd->callback([o, &exit_code]() { exit_code = run(*o); });
}

}  // namespace quadval::cli
