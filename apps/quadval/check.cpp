// quadval check: certified Jacobian-determinant bounds of every element (validity,
// Jacobian range, distortion), Thesis Paper III, and the certified quality measures mu
// (Paper V) and scaled Jacobian; a terminal summary and per-element files.
//
//
//   quadval check mesh.msh
//   quadval check mesh.msh --measure distortion --threads 2 -o report.csv -o coloured.vtu
//   quadval check mesh.msh --measure all --tol 1e-3 -o report.csv
//
// Results stream: elements are analysed in batches, CSV/JSON rows are written as each batch
// finishes and VTU/MSH keep one double per element and field, so memory stays near the
// mesh's own whatever its size (-v prints both).
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
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
  bool verbose = false;
  std::vector<std::string> outputs;
};

// The mesh's own memory: the bytes of its per-node and per-element arrays (node tags,
// coordinates, and per block the element tags and connectivity), by size, not capacity;
// entities and physical names (a few bytes per model entity) are left out.
std::size_t mesh_bytes(const Mesh& mesh) {
  std::size_t n = mesh.node_tags.size() * sizeof(Tag) + mesh.coords.size() * sizeof(double);
  for (const ElementBlock& b : mesh.blocks) n += b.tags.size() * sizeof(Tag) + b.nodes.size() * sizeof(NodeIndex);
  return n;
}

// Peak resident memory of this process so far (Linux: ru_maxrss in KiB).
std::size_t peak_resident_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;
}

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
  // The reading of large ASCII files runs on OpenMP's threads too.
  if (o.threads > 0) omp_set_num_threads(o.threads);
  std::vector<std::string> read_warnings;
  const Mesh mesh = read_mesh(o.input, &read_warnings);
  if (!o.quiet)  // --quiet prints nothing, warnings included
    for (const std::string& w : read_warnings) fmt::print(stderr, "quadval: warning: {}\n", w);

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
  const std::size_t worst = static_cast<std::size_t>(std::max(0, o.worst));
  opts.worst = worst;

  // CSV and JSON files are open (as temporaries, renamed once complete) during the
  // analysis and get their rows batch by batch; VTU/MSH get the collected fields after it.
  std::vector<std::string> text_outputs, mesh_outputs;
  for (const std::string& out : o.outputs) {
    const std::string e = lower_extension(out);
    (e == ".csv" || e == ".json" ? text_outputs : mesh_outputs).push_back(out);
  }
  std::optional<CheckFieldCollector> fields;
  if (!mesh_outputs.empty()) fields.emplace(mesh, opts.measure);
  std::vector<std::ostream*> csv_streams;
  std::vector<CheckJsonWriter> json_writers;
  CheckSummary summary;
  const std::function<void(std::size_t)> open_then_check = [&](std::size_t k) {
    if (k == text_outputs.size()) {
      CheckSink sink;  // none without outputs: then the analysis keeps no per-element records
      if (!csv_streams.empty() || !json_writers.empty() || fields)
        sink = [&](const CheckBatch& batch) {
          if (!csv_streams.empty()) {
            std::string rows;
            append_check_csv_rows(rows, batch);
            for (std::ostream* os : csv_streams) *os << rows;
          }
          for (CheckJsonWriter& w : json_writers) w.add(batch);
          if (fields) fields->add(batch);
        };
      summary = check_mesh_streamed(mesh, opts, o.input, sink);
      for (CheckJsonWriter& w : json_writers) w.finish(summary);
      return;
    }
    write_file_atomically(text_outputs[k], [&](std::ostream& os) {
      if (lower_extension(text_outputs[k]) == ".csv") {
        os << check_csv_header();
        csv_streams.push_back(&os);
      } else {
        json_writers.emplace_back(os);
      }
      open_then_check(k + 1);
    });
  };
  open_then_check(0);
  if (shown) fmt::print(stderr, "\r{}\r", std::string(60, ' '));

  if (!o.quiet) fmt::print("{}", format_check_summary(summary, worst));
  if (fields) {
    std::vector<ElementField> mesh_fields;
    for (auto& [name, values] : fields->take()) mesh_fields.push_back({name, std::move(values)});
    for (const std::string& out : mesh_outputs) {
      WriteOptions w;
      w.format = lower_extension(out) == ".vtu" ? MeshFormat::vtu : MeshFormat::msh41;
      write_mesh(mesh, out, w, mesh_fields);
    }
  }
  if (!o.quiet)
    for (const std::string& out : o.outputs) fmt::print("[check] wrote {}\n", out);
  if (o.verbose) {
    const double mib = 1024.0 * 1024.0;
    const std::size_t own = mesh_bytes(mesh), peak = peak_resident_bytes();
    fmt::print("[check] memory: mesh {:.1f} MiB (node tags, coordinates, element tags, connectivity), "
               "peak resident {:.1f} MiB, {:.2f} x the mesh\n",
               static_cast<double>(own) / mib, static_cast<double>(peak) / mib,
               own ? static_cast<double>(peak) / static_cast<double>(own) : 0.0);
  }
  const bool all_valid = summary.count(Validity::invalid) == 0 && summary.count(Validity::undetermined) == 0 &&
                         summary.skipped() == 0;
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
                  "--tol; distortion: also min J / J_straight (Paper III eq. 3), within --tol too;\n"
                  "mu: validity and bounds on mu; scaled-jacobian: validity and bounds on the\n"
                  "scaled Jacobian; all: distortion, mu and the scaled Jacobian")
      ->check(CLI::IsMember({"validity", "jacobian", "distortion", "mu", "scaled-jacobian", "all"}))
      ->capture_default_str();
  cmd->add_option("--tol", o->tol,
                  "Relative tolerance on the J bounds and on min J / J_straight (jacobian,\n"
                  "distortion); absolute tolerance on upper - lower of mu and the scaled Jacobian")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--abs-tol", o->abs_tol, "Absolute tolerance on the bounds (the larger one applies)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--max-subdivisions", o->max_subdivisions,
                  "Subdivisions per element before answering undetermined (mu, scaled\n"
                  "Jacobian: before stopping with bounds wider than --tol, said in the summary;\n"
                  "where these halve a subdomain at a time, dim halvings count as one)")
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
  cmd->add_flag("-v,--verbose", o->verbose,
                "Also print the mesh's own memory (its node and element arrays) and the peak\n"
                "resident memory of the run (even with --quiet)");
  cmd->callback([o, &exit_code] { exit_code = run_check(*o); });
}

}  // namespace quadval::cli
