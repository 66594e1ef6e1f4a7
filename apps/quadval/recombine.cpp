// quadval recombine: triangles to quadrangles (Blossom-Quad, Paper I), with the greedy and
// full-quad baselines, statistics on the terminal and in JSON.
//
//   quadval recombine rect.msh -o rect-quads.msh --report rect.json
//   quadval recombine rect.msh -o rect-quads.vtu --size-field "0.1+0.08*sin(3*x)*cos(6*y)"
//   quadval recombine rect.msh -o dominant.msh --algo greedy --no-optimize
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <omp.h>

#include "commands.hpp"
#include "terminal_progress.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"
#include "quadval/quad_quality.hpp"
#include "quadval/recombine.hpp"
#include "quadval/size_field.hpp"

namespace quadval::cli {
namespace {

struct RecombineCliOptions {
  std::string input, output, report;
  std::string algo = "blossom", cost = "angle", odd = "split";
  std::string size_field, cross_field_file;
  double cross_field_degrees = 0.0;
  int smooth = 5, cleanup_passes = 5, threads = 0;
  bool no_optimize = false, full_quad = false, quiet = false, binary = false;
  bool no_extra_edges = false;
  double extra_edge_cost = 1000.0;
  double feature_angle = 40.0;
  int horizon = 3, runs = 1;
  std::uint64_t seed = 1;
  bool uniform = false, selective = false, compare_blossom = false;
};

// One angle in degrees per line ('#' starts a comment; blank lines skipped).
std::vector<double> read_cross_field(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError::in_file(path, "cannot open the cross-field file");
  std::vector<double> radians;
  std::string line;
  long number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    double degrees;
    if (!(words >> degrees)) {
      std::string rest;
      if (std::istringstream(line) >> rest)
        throw InputError::at_line(path, number, fmt::format("expected an angle in degrees, got '{}'", rest));
      continue;
    }
    std::string extra;
    if (words >> extra || !std::isfinite(degrees))
      throw InputError::at_line(path, number, "expected one finite angle in degrees per line");
    radians.push_back(degrees * std::numbers::pi / 180.0);
  }
  return radians;
}

nlohmann::json stats_json(const RecombineStats& s) {
  nlohmann::json times = nlohmann::json::array();
  for (const StageTime& t : s.times) times.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
  nlohmann::json j = {
      {"input_triangles", s.input_triangles},   {"odd_splits", s.odd_splits},
      {"feature_edges", s.feature_edges},
      {"graph_pairs", s.graph_pairs},           {"extra_pairs", s.extra_pairs},
      {"perfect_matching", s.perfect_matching}, {"matched_extra_pairs", s.matched_extra_pairs},
      {"edge_swaps", s.edge_swaps},             {"vertex_duplications", s.vertex_duplications},
      {"total_cost", s.matching_cost},          {"smoothing_moves", s.smoothing_moves},
      {"vertex_merges", s.vertex_merges},       {"doublet_collapses", s.doublet_collapses},
      {"diagonal_swaps", s.diagonal_swaps},
      {"quads", s.quads},                       {"triangles_left", s.triangles},
      {"nodes", s.nodes},                       {"invalid_quads", s.invalid_quads},
      {"eta_min", s.eta_min},                   {"eta_mean", s.eta_mean},
      {"degree4_share", s.degree4_share},       {"degree_min", s.degree_min},
      {"degree_max", s.degree_max},             {"times", times},
      {"total_seconds", s.total_seconds}};
  j["tau_percent"] = s.has_tau ? nlohmann::json(s.tau) : nlohmann::json(nullptr);
  return j;
}


int run(const RecombineCliOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const MeshFormat out_format = output_format_from_extension(o.output);  // fails before the work
  TerminalProgress progress(!o.quiet);
  auto log = [&](const std::string& line) {
    progress.end_line();
    if (!o.quiet) fmt::print(stderr, "{}\n", line);
    progress.start();  // the next stage starts
  };
  RecombineOptions options;
  options.source = o.input;
  options.algorithm = o.algo == "greedy" ? RecombineAlgorithm::greedy : RecombineAlgorithm::blossom;
  if (o.algo == "lookahead") options.algorithm = RecombineAlgorithm::lookahead;
  options.lookahead = {o.horizon, o.uniform ? LookaheadTree::uniform : LookaheadTree::selective,
                       o.seed, o.runs};
  options.compare_with_blossom = o.compare_blossom;
  options.cost = o.cost == "crossfield" ? PairCostKind::cross_field : PairCostKind::angle;
  options.cross_field_angle = o.cross_field_degrees * std::numbers::pi / 180.0;
  if (!o.cross_field_file.empty()) options.cross_field_per_triangle = read_cross_field(o.cross_field_file);
  options.odd_policy = o.odd == "leave" ? OddPolicy::leave_triangle : OddPolicy::split_boundary_edge;
  options.extra_edges = !o.no_extra_edges;
  options.extra_edge_cost = o.extra_edge_cost;
  options.feature_angle = o.feature_angle;
  options.optimize = !o.no_optimize;
  options.smoothing_passes = o.smooth;
  // The library's parallel loops (pair costs, smoothing, statistics, look-ahead runs) use
  // OpenMP's thread count; their results do not depend on it.
  if (o.threads > 0) omp_set_num_threads(o.threads);
  options.max_cleanup_passes = o.cleanup_passes;
  options.full_quad = o.full_quad;
  std::optional<SizeField> size;
  if (!o.size_field.empty()) {
    size = SizeField::from_expression(o.size_field);
    options.size_field = [field = *size](double x, double y, double z) { return field(x, y, z); };
  }
  options.log = log;
  options.matching_progress = matching_progress_on(progress);

  std::vector<std::string> read_warnings;
  const auto read_start = std::chrono::steady_clock::now();
  const Mesh input = read_mesh(o.input, &read_warnings);
  const double read_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
  for (const auto& w : read_warnings) log(fmt::format("[read] warning: {}", w));
  log(fmt::format("[read] {} nodes, {} elements, {:.1f} ms", input.num_nodes(), input.num_elements(),
                  1e3 * read_seconds));
  if (size) size->check_positive_at(input.coords, "mesh node");

  RecombineResult result = recombine(input, options);
  for (const auto& w : result.warnings) log(fmt::format("[recombine] warning: {}", w));

  const auto write_start = std::chrono::steady_clock::now();
  const ElementField eta{"eta", element_eta(result.mesh, -1.0)};  // triangles (none when all-quad): -1
  write_mesh(result.mesh, o.output, WriteOptions{out_format, o.binary},
             std::span<const ElementField>(&eta, 1));
  const double write_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  log(fmt::format("[write] {}, {:.1f} ms", o.output, 1e3 * write_seconds));

  const RecombineStats& s = result.stats;
  if (!o.quiet) {
    fmt::print("{}: {} triangles -> {} quads, {} triangles left ({})\n", o.input, s.input_triangles,
               s.quads, s.triangles, o.algo);
    fmt::print("  eta min {:.3f}  mean {:.3f}  invalid quads {}\n", s.eta_min, s.eta_mean,
               s.invalid_quads);
    fmt::print("  interior vertices of degree 4: {:.1f}%  degree min {} max {}\n",
               100.0 * s.degree4_share, s.degree_min, s.degree_max);
    if (s.has_tau) fmt::print("  efficiency index tau {:.1f}%\n", s.tau);
    if (options.algorithm == RecombineAlgorithm::lookahead) {
      fmt::print("  look-ahead: q {:.2f}, {:.2f}% of the triangles recombined, {} left before "
                 "post-process ({} paired along paths), {} after (best of {} runs: run {})\n",
                 s.lookahead_quality, 100.0 * s.recombined_share, s.lookahead_triangles_left,
                 s.lookahead_path_pairs, s.triangles, s.lookahead_runs.size(), s.lookahead_best_run);
      if (s.quality_percent_of_blossom >= 0)
        fmt::print("  Blossom q {:.2f}: look-ahead reaches {:.2f}%\n", s.blossom_quality,
                   s.quality_percent_of_blossom);
    }
    fmt::print("  total cost {:.6g}, extra pairs matched {} (swaps {}, duplications {})\n",
               s.matching_cost, s.matched_extra_pairs, s.edge_swaps, s.vertex_duplications);
    fmt::print("  time: read {:.3f} s, recombine {:.3f} s, write {:.3f} s, total {:.3f} s\n",
               read_seconds, s.total_seconds, write_seconds, total);
  }
  if (!o.report.empty()) {
    nlohmann::json report = {{"input", o.input},         {"output", o.output},
                             {"algorithm", o.algo},      {"cost", o.cost},
                             {"full_quad", o.full_quad}, {"optimize", !o.no_optimize},
                             {"smoothing_passes", o.smooth},
                             {"statistics", stats_json(s)},
                             {"warnings", result.warnings},
                             {"read_seconds", read_seconds}, {"write_seconds", write_seconds},
                             {"end_to_end_seconds", total}};
    if (!o.size_field.empty()) report["size_field"] = o.size_field;
    if (options.algorithm == RecombineAlgorithm::lookahead) {
      nlohmann::json runs = nlohmann::json::array();
      for (const LookaheadRun& r : s.lookahead_runs)
        runs.push_back({{"seed", r.seed}, {"quality", r.quality}, {"quads", r.quads},
                        {"triangles_left", r.triangles_left}, {"seconds", r.seconds}});
      report["lookahead"] = {
          {"tree", o.uniform ? "uniform" : "selective"}, {"horizon", o.horizon},
          {"seed", o.seed}, {"runs", runs}, {"best_run", s.lookahead_best_run},
          {"quality", s.lookahead_quality}, {"recombined_share", s.recombined_share},
          {"triangles_left_before_post_process", s.lookahead_triangles_left},
          {"triangles_paired_along_paths", s.lookahead_path_pairs},
          {"triangles_left_after_post_process", s.triangles},
          {"blossom_quality", s.blossom_quality >= 0 ? nlohmann::json(s.blossom_quality) : nlohmann::json(nullptr)},
          {"quality_percent_of_blossom", s.quality_percent_of_blossom >= 0 ? nlohmann::json(s.quality_percent_of_blossom) : nlohmann::json(nullptr)}};
    }
    write_file_atomically(o.report, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  }
  return kExitOk;
}

}  // namespace

void add_recombine_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<RecombineCliOptions>();
  auto* cmd = app.add_subcommand(
      "recombine",
      "Recombine a triangle mesh into quadrangles (Blossom-Quad: optimal, all-quad)");
  cmd->add_option("input", o->input, "Triangle mesh (.msh, .stl, .obj, .off)")->required();
  cmd->add_option("-o,--output", o->output, "Output mesh (.msh or .vtu, with the element field 'eta'; or .obj, .off)")
      ->required();
  cmd->add_option("--algo", o->algo, "blossom (optimal, all-quad), lookahead (look-ahead tree, see --horizon: linear time, "
                  "near-optimal; the triangles it leaves are then paired along augmenting paths: all-quad on the benchmark "
                  "meshes) or greedy (quad-dominant)")
      ->check(CLI::IsMember({"blossom", "greedy", "lookahead"}))
      ->capture_default_str();
  cmd->add_option("--cost", o->cost, "Pair cost: angle (1 - eta, eq. 3) or crossfield (eq. 7)")
      ->check(CLI::IsMember({"angle", "crossfield"}))
      ->capture_default_str();
  cmd->add_option("--cross-field-angle", o->cross_field_degrees,
                  "Constant cross-field direction, degrees from the x axis")
      ->capture_default_str();
  cmd->add_option("--cross-field-file", o->cross_field_file,
                  "Cross-field angle per triangle, degrees, one per line (triangles in file order)");
  cmd->add_option("--size-field", o->size_field,
                  "Size field h(x,y,z) (e.g. \"0.1+0.08*sin(3*x)*cos(6*y)\"): weights the "
                  "smoothing and gives the efficiency index tau");
  cmd->add_option("--smooth", o->smooth, "Smoothing passes (0: none)")->capture_default_str();
  cmd->add_option("--threads", o->threads,
                  "Threads at most (0: all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--cleanup-passes", o->cleanup_passes,
                  "Rounds of quad-vertex-merge, doublet collapse and diagonal swaps of quads smoothing cannot mend (0: none)")
      ->capture_default_str();
  cmd->add_flag("--no-optimize", o->no_optimize, "No smoothing and no clean-up (Paper I §6)");
  cmd->add_flag("--full-quad", o->full_quad,
                "Then split each quad into 4 and each triangle into 3 (sizes halve)");
  cmd->add_option("--odd", o->odd,
                  "Odd triangle count: split (the longest boundary edge, or on a closed surface an edge "
                  "between two of its pieces; all-quad result) or leave (one triangle stays)")
      ->check(CLI::IsMember({"split", "leave"}))
      ->capture_default_str();
  cmd->add_option("--feature-angle", o->feature_angle,
                  "Surfaces in 3D: edges where the surface turns by more than this many degrees are "
                  "features, kept like CAD curves (no quad across one, nodes stay on it); 180: none")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  cmd->add_flag("--no-extra-edges", o->no_extra_edges, "Do not add the extra boundary edges (§5.3)");
  cmd->add_option("--extra-edge-cost", o->extra_edge_cost, "Cost of an extra boundary edge")
      ->capture_default_str();
  cmd->add_option("--horizon", o->horizon, "lookahead: depth of the look-ahead tree")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  auto* uniform = cmd->add_flag("--uniform", o->uniform,
                                "lookahead: uniform tree (every allowed merge; small meshes)");
  cmd->add_flag("--selective", o->selective, "lookahead: selective tree (the default)")
      ->excludes(uniform);
  cmd->add_option("--seed", o->seed, "lookahead: seed of run 0 (run i uses seed + i)")
      ->capture_default_str();
  cmd->add_option("--runs", o->runs, "lookahead: keep the best of N runs")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_flag("--compare-blossom", o->compare_blossom,
                "lookahead: also solve Blossom on the same triangles and report the quality "
                "as a percentage of its optimum");
  cmd->add_option("--report", o->report, "Write the statistics as JSON to this file");
  cmd->add_flag("--binary", o->binary, "Binary MSH output");
  cmd->add_flag("-q,--quiet", o->quiet, "No log and no summary");
  cmd->callback([o, &exit_code]() { exit_code = run(*o); });
}

}  // namespace quadval::cli
