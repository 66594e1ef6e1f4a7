#include "geometry_pipeline.hpp"

#include <chrono>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "commands.hpp"
#include "terminal_progress.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"
#include "quadval/quad_quality.hpp"
#include "quadval/recombine.hpp"
#include "quadval/svg.hpp"

namespace quadval::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

void write_meshes(const Mesh& mesh, const std::vector<std::filesystem::path>& paths,
                  const std::vector<ElementField>& fields) {
  for (const auto& path : paths)
    write_mesh(mesh, path, WriteOptions{format_from_extension(path), false}, fields);
}

nlohmann::json recombine_json(const RecombineStats& s) {
  nlohmann::json times = nlohmann::json::array();
  for (const StageTime& t : s.times) times.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
  nlohmann::json j = {{"input_triangles", s.input_triangles},
                      {"odd_splits", s.odd_splits},
                      {"perfect_matching", s.perfect_matching},
                      {"matched_extra_pairs", s.matched_extra_pairs},
                      {"edge_swaps", s.edge_swaps},
                      {"vertex_duplications", s.vertex_duplications},
                      {"quads", s.quads},
                      {"triangles_left", s.triangles},
                      {"nodes", s.nodes},
                      {"invalid_quads", s.invalid_quads},
                      {"eta_min", s.eta_min},
                      {"eta_mean", s.eta_mean},
                      {"degree4_share", s.degree4_share},
                      {"degree_min", s.degree_min},
                      {"degree_max", s.degree_max},
                      {"times", times},
                      {"seconds", s.total_seconds}};
  j["tau_percent"] = s.has_tau ? nlohmann::json(s.tau) : nlohmann::json(nullptr);
  return j;
}

std::string percent_or_dash(bool has, double v) {
  return has ? fmt::format("{:.1f}%", v) : std::string("-");
}

}  // namespace

int run_geometry_pipeline(const Triangulation& tri, const PipelineSettings& settings,
                          const PipelineOutputs& outputs, nlohmann::json report_extra) {
  TerminalProgress progress(!settings.quiet);
  auto log = [&](const std::string& line) {
    progress.end_line();
    if (!settings.quiet) fmt::print(stderr, "{}\n", line);
    progress.start();  // the next stage starts
  };
  // Triangle stage.
  log(fmt::format("[triangles] {} triangles, {} nodes, {}/{} curves with an odd number of "
                  "interior nodes, {:.3f} s",
                  tri.num_triangles, tri.mesh.num_nodes(), tri.num_odd_curves(), tri.curves.size(),
                  tri.seconds));
  for (const auto& w : tri.warnings) log(fmt::format("[triangles] warning: {}", w));
  if (!tri.all_curves_odd())
    for (const CurveNodes& c : tri.curves)
      if (!c.odd())
        log(fmt::format("[triangles] warning: curve {} has {} interior nodes (even)", c.curve,
                        c.interior_nodes));
  std::vector<double> tri_lengths;
  double tri_tau = 0;
  if (settings.size) {
    tri_lengths = mesh_normalized_edge_lengths(tri.mesh, *settings.size);
    tri_tau = efficiency_index(tri_lengths);
  }
  std::size_t odd_surfaces = 0;
  for (const SurfaceTriangles& s : tri.surfaces) odd_surfaces += !s.even();

  // Quad stage.
  std::optional<RecombineResult> rec;
  std::vector<double> quad_lengths;
  double quad_tau = 0;
  if (settings.recombine != "none") {
    RecombineOptions options;
    options.algorithm = settings.recombine == "greedy"      ? RecombineAlgorithm::greedy
                        : settings.recombine == "lookahead" ? RecombineAlgorithm::lookahead
                                                            : RecombineAlgorithm::blossom;
    options.source = settings.source;
    if (settings.size)
      options.size_field = [h = *settings.size](double x, double y, double z) { return h(x, y, z); };
    options.log = log;
    options.matching_progress = matching_progress_on(progress);
    if (!tri.all_surfaces_planar()) {
      // The smoothing and clean-up of the recombination move nodes in 3D without projecting
      // them back onto the CAD surface (measured on a cylinder of radius 0.5, h = 0.12: up to
      // 0.009 off it), so on curved faces the matched quads are kept as they are.
      options.optimize = false;
      log("[recombine] warning: curved surfaces: no smoothing or clean-up, so that every node "
          "stays on the geometry");
    }
    rec = recombine(tri.mesh, options);
    for (const auto& w : rec->warnings) log(fmt::format("[recombine] warning: {}", w));
    if (settings.size) {
      quad_lengths = mesh_normalized_edge_lengths(rec->mesh, *settings.size);
      quad_tau = efficiency_index(quad_lengths);
    }
  }
  const Mesh& final_mesh = rec ? rec->mesh : tri.mesh;
  // NaN for anything but a quadrangle, so that pictures draw it grey and histograms skip it.
  const std::vector<double> eta = element_eta(final_mesh, std::nan(""));

  // Outputs.
  const auto write_start = Clock::now();
  write_meshes(tri.mesh, outputs.triangle_meshes, {});
  write_meshes(final_mesh, outputs.result_meshes, {ElementField{"eta", eta}});
  std::vector<std::filesystem::path> pictures;
  if (!outputs.picture_dir.empty()) {
    std::filesystem::create_directories(outputs.picture_dir);
    if (rec) {
      MeshSvgOptions m;
      m.title = fmt::format("{}: {} quads coloured by eta (Paper I eq. 3)",
                            settings.picture_label.empty() ? settings.source
                                                           : settings.picture_label,
                            rec->stats.quads);
      m.value_name = "eta";
      pictures.push_back(outputs.picture_dir / "quads-eta.svg");
      write_mesh_svg(final_mesh, eta, pictures.back(), m);
      HistogramSvgOptions h;
      h.title = "Quad quality eta (Paper I eq. 3)";
      h.x_label = "eta";
      h.markers = {{rec->stats.eta_mean, "mean"}};
      pictures.push_back(outputs.picture_dir / "eta-histogram.svg");
      write_histogram_svg(eta, pictures.back(), h);
    }
    if (settings.size) {
      HistogramSvgOptions h;
      h.title = fmt::format("Normalized edge length l^h (Paper I eq. 1) of the {}",
                            rec ? "quads" : "triangles");
      h.x_label = "l^h";
      h.lo = 0;
      h.hi = 2;
      h.markers = {{1 / std::numbers::sqrt2, "1/√2"}, {1.0, "1"}, {std::numbers::sqrt2, "√2"}};
      pictures.push_back(outputs.picture_dir / "edge-length-histogram.svg");
      write_histogram_svg(rec ? quad_lengths : tri_lengths, pictures.back(), h);
    }
  }
  const double write_seconds = seconds_since(write_start);

  // Table: triangle stage and quad stage side by side.
  const RecombineStats* s = rec ? &rec->stats : nullptr;
  if (!settings.quiet) {
    auto row = [](const std::string& name, const std::string& a, const std::string& b) {
      fmt::print("  {:<34}{:>16}{:>16}\n", name, a, b);
    };
    if (!settings.title.empty()) fmt::print("{}\n", settings.title);
    row("", "triangles", rec ? "quads" : "");
    row("elements", std::to_string(tri.num_triangles), s ? std::to_string(s->quads) : "");
    row("nodes", std::to_string(tri.mesh.num_nodes()), s ? std::to_string(s->nodes) : "");
    row("curves with odd interior nodes",
        fmt::format("{}/{}", tri.num_odd_curves(), tri.curves.size()), "");
    row("surfaces with an even count",
        fmt::format("{}/{}", tri.surfaces.size() - odd_surfaces, tri.surfaces.size()), "");
    if (s) {
      row("triangles left", "", std::to_string(s->triangles));
      row("eta min / mean", "", fmt::format("{:.3f} / {:.3f}", s->eta_min, s->eta_mean));
      row("invalid quads", "", std::to_string(s->invalid_quads));
      row("interior vertices of degree 4", "", fmt::format("{:.1f}%", 100 * s->degree4_share));
      row("vertex degree min / max", "", fmt::format("{} / {}", s->degree_min, s->degree_max));
    }
    row("efficiency index tau (eq. 2)", percent_or_dash(settings.size.has_value(), tri_tau),
        s ? percent_or_dash(settings.size.has_value(), quad_tau) : "");
    row("time", fmt::format("{:.3f} s", tri.seconds),
        s ? fmt::format("{:.3f} s", s->total_seconds) : "");
    for (const auto& p : outputs.triangle_meshes) fmt::print("  triangles: {}\n", p.string());
    for (const auto& p : outputs.result_meshes) fmt::print("  {}: {}\n", rec ? "quads" : "mesh", p.string());
    for (const auto& p : pictures) fmt::print("  picture: {}\n", p.string());
  }

  if (!outputs.report.empty()) {
    nlohmann::json curves = nlohmann::json::array(), surfaces = nlohmann::json::array();
    for (const CurveNodes& c : tri.curves)
      curves.push_back({{"curve", c.curve}, {"interior_nodes", c.interior_nodes}, {"odd", c.odd()}});
    for (const SurfaceTriangles& t : tri.surfaces)
      surfaces.push_back({{"surface", t.surface}, {"triangles", t.triangles}, {"even", t.even()}});
    nlohmann::json report = report_extra.is_object() ? report_extra : nlohmann::json::object();
    report["source"] = settings.source;
    report["size_field"] = settings.size ? nlohmann::json(settings.size->expression()) : nullptr;
    report["triangle_stage"] = {
        {"triangles", tri.num_triangles},
        {"nodes", tri.mesh.num_nodes()},
        {"all_curves_odd", tri.all_curves_odd()},
        {"curves", curves},
        {"surfaces", surfaces},
        {"volumes_skipped", tri.num_volumes_skipped},
        {"tau_percent", settings.size ? nlohmann::json(tri_tau) : nlohmann::json(nullptr)},
        {"seconds", tri.seconds}};
    report["recombine"] = settings.recombine;
    if (s) {
      report["quad_stage"] = recombine_json(*s);
      report["quad_stage"]["tau_percent_edges"] =
          settings.size ? nlohmann::json(quad_tau) : nlohmann::json(nullptr);
      report["warnings"] = rec->warnings;
    }
    report["triangle_stage"]["warnings"] = tri.warnings;
    nlohmann::json files = nlohmann::json::array();
    for (const auto& p : outputs.triangle_meshes) files.push_back(p.string());
    for (const auto& p : outputs.result_meshes) files.push_back(p.string());
    for (const auto& p : pictures) files.push_back(p.string());
    report["outputs"] = files;
    report["write_seconds"] = write_seconds;
    write_file_atomically(outputs.report,
                          [&](std::ostream& out) { out << report.dump(2) << "\n"; });
    if (!settings.quiet) fmt::print("  report: {}\n", outputs.report.string());
  }
  if (s && settings.recombine == "blossom" && s->triangles > 0) {
    log(fmt::format("[recombine] {} triangles left: the mesh is not all-quad", s->triangles));
    return kExitFindings;
  }
  return kExitOk;
}

int no_gmsh_in_this_build(const char* command) {
  fmt::print(stderr,
             "quadval: error: `quadval {}` needs the Gmsh front end, and this build has none "
             "(it was configured without libgmsh; install libgmsh-dev and reconfigure with "
             "-DQUADVAL_WITH_GMSH=ON). `quadval recombine` works on an existing triangle mesh.\n",
             command);
  return kExitBadInput;
}

}  // namespace quadval::cli
