// quadval check: certified Jacobian-determinant bounds of every element (validity,
// Jacobian range, distortion), Thesis Paper III, and the certified quality measures mu
// (Paper V) and scaled Jacobian; a terminal summary and per-element files.
//
//   quadval check mesh.msh
//   quadval check mesh.msh --measure distortion --threads 2 -o report.csv -o coloured.vtu
//   quadval check mesh.msh --measure all --tol 1e-3 -o report.csv
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "commands.hpp"
#include "quadval/atomic_file.hpp"
#include "quadval/check_report.hpp"
#include "quadval/error.hpp"
#include "quadval/io.hpp"

namespace quadval::cli {

namespace {

struct CheckCliOptions {
  std::string input;
  std::string measure = "validity";
  double tol = 1e-2;
  double abs_tol = 0;
  int max_subdivisions = 1000;
  int threads = 0;
  int worst = 10;
  bool quiet = false;
  std::vector<std::string> outputs;
};

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

int run_check(const CheckCliOptions& o) {
  // Outputs are checked before the (possibly long) analysis.
  for (const std::string& out : o.outputs) {
    const std::string e = lower_extension(out);
    if (e != ".csv" && e != ".json" && e != ".vtu" && e != ".msh")
      throw InputError::in_file(out, "unknown output extension (expected .csv, .json, .vtu or .msh)");
  }
  const Mesh mesh = read_mesh(o.input);

  CheckOptions opts;
  opts.measure = o.measure == "distortion"        ? CheckMeasure::distortion
               : o.measure == "jacobian"          ? CheckMeasure::jacobian
               : o.measure == "mu"                ? CheckMeasure::mu
               : o.measure == "scaled-jacobian"   ? CheckMeasure::scaled_jacobian
               : o.measure == "all"               ? CheckMeasure::all
                                                  : CheckMeasure::validity;
  opts.rel_tol = o.tol;
  opts.quality_abs_tol = o.tol;
  opts.abs_tol = o.abs_tol;
  opts.max_subdivisions = o.max_subdivisions;
  opts.threads = o.threads;
  // A progress line on a terminal, only for runs longer than a second.
  const bool tty = isatty(STDERR_FILENO) != 0 && !o.quiet;
  const auto start = std::chrono::steady_clock::now();
  bool shown = false;
  if (tty) {
    opts.progress = [&](std::size_t done, std::size_t total) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (s < 1.0 || total == 0) return;
      fmt::print(stderr, "\r[check] {}/{} elements ({:.0f}%)", done, total, 100.0 * done / total);
      shown = true;
    };
  }
  const CheckReport report = check_mesh(mesh, opts, o.input);
  if (shown) fmt::print(stderr, "\r{}\r", std::string(60, ' '));

  if (!o.quiet) fmt::print("{}", format_check_summary(report, static_cast<std::size_t>(std::max(0, o.worst))));
  for (const std::string& out : o.outputs) {
    const std::string e = lower_extension(out);
    if (e == ".csv") {
      const std::string text = check_csv(report);
      write_file_atomically(out, [&text](std::ostream& os) { os << text; });
    } else if (e == ".json") {
      const std::string text = check_json(report);
      write_file_atomically(out, [&text](std::ostream& os) { os << text; });
    } else {
      std::vector<ElementField> fields;
      for (auto& [name, values] : check_fields(mesh, report)) fields.push_back({name, std::move(values)});
      WriteOptions w;
      w.format = e == ".vtu" ? MeshFormat::vtu : MeshFormat::msh41;
      write_mesh(mesh, out, w, fields);
    }
    if (!o.quiet) fmt::print("[check] wrote {}\n", out);
  }
  const bool all_valid = report.count(Validity::invalid) == 0 && report.count(Validity::undetermined) == 0 &&
                         report.skipped() == 0;
  return all_valid ? kExitOk : kExitFindings;
}

}  // namespace

void add_check_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<CheckCliOptions>();
  auto* cmd = app.add_subcommand(
      "check",
      "Certified bounds on the Jacobian determinant J of every element of the mesh's highest\n"
      "dimension (lines, triangles, quadrangles, tetrahedra, prisms, hexahedra, pyramids;\n"
      "complete and serendipity): valid (J > 0 proven everywhere), invalid (a point with\n"
      "J <= 0 found) or undetermined (subdivision limit reached). Rounding is accounted for;\n"
      "near-zero cases are settled in exact rational arithmetic.\n"
      "--measure mu / scaled-jacobian / all add certified bounds on the quality measure mu\n"
      "(Paper V) and on the scaled Jacobian (min det J / product of column norms); types they\n"
      "do not support are reported as skipped for that measure. Gmsh's AnalyseCurvedMesh\n"
      "ICN/IGE are related but not equal measures, and not certified bounds.\n"
      "Exit status: 0 all valid, 1 some invalid, undetermined or skipped, 2 bad input.");
  cmd->add_option("mesh", o->input, "Mesh to check (.msh 2.2/4.1, ASCII or binary)")->required();
  cmd->add_option("--measure", o->measure,
                  "validity: settle the sign of min J; jacobian: also bound min J and max J within\n"
                  "--tol; distortion: also min J / J_straight (Paper III eq. 3); mu: validity and\n"
                  "bounds on mu; scaled-jacobian: validity and bounds on the scaled Jacobian;\n"
                  "all: distortion, mu and the scaled Jacobian")
      ->check(CLI::IsMember({"validity", "jacobian", "distortion", "mu", "scaled-jacobian", "all"}))
      ->capture_default_str();
  cmd->add_option("--tol", o->tol,
                  "Relative tolerance on the J bounds (jacobian, distortion); absolute tolerance\n"
                  "on upper - lower of mu and the scaled Jacobian")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--abs-tol", o->abs_tol, "Absolute tolerance on the bounds (the larger one applies)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--max-subdivisions", o->max_subdivisions,
                  "Subdomains split per element before answering undetermined (mu, scaled\n"
                  "Jacobian: before stopping with bounds wider than --tol, said in the summary)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "Threads at most (0: all cores; small meshes use fewer, as threads would cost more than they save); results do not depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--worst", o->worst, "How many worst elements the summary lists")->capture_default_str();
  cmd->add_option("-o,--output", o->outputs,
                  "Write per-element results: .csv, .json, or the mesh with per-element fields\n"
                  "(.vtu for ParaView, .msh for Gmsh); may be given several times");
  cmd->add_flag("-q,--quiet", o->quiet, "Print nothing (the exit status tells)");
  cmd->callback([o, &exit_code] { exit_code = run_check(*o); });
}

}  // namespace quadval::cli
