// Geometry -> triangles with Gmsh's C++ API: load (file or planar domain), set the sizes and
// the algorithm, mesh curves with odd interior node counts, then surfaces; read back.
// Part of the Gmsh front-end module (gmsh_module.hpp).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <numbers>

#include <fmt/core.h>
#include <gmsh.h>

#include "geometry/gmsh_module.hpp"
#include "geometry/gmsh_session.hpp"
#include "geometry/read_gmsh_model.hpp"
#include "quadval/error.hpp"
#include "quadval/geometry.hpp"

namespace quadval {

namespace {

using Clock = std::chrono::steady_clock;

int gmsh_algorithm_id(TriangleAlgorithm a) {
  switch (a) {
    case TriangleAlgorithm::frontal_quad: return 8;
    case TriangleAlgorithm::frontal: return 6;
    case TriangleAlgorithm::delaunay: return 5;
  }
  return 6;
}

std::string join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// OpenCASCADE prints its own parse errors on stdout; while a file loads quietly, stdout goes
// to /dev/null (the errors still reach us through Gmsh's logger).
class QuietStdout {
 public:
  explicit QuietStdout(bool quiet) {
    if (!quiet) return;
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null_fd = open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null_fd >= 0) dup2(null_fd, STDOUT_FILENO);
    if (null_fd >= 0) close(null_fd);
  }
  ~QuietStdout() {
    if (saved_ < 0) return;
    std::fflush(stdout);
    dup2(saved_, STDOUT_FILENO);
    close(saved_);
  }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

 private:
  int saved_ = -1;
};

// Throws InputError if Gmsh logged errors (or threw) during `step`.
template <class F>
void run_gmsh_step(geometry::GmshSession& session, const std::string& source, const char* what,
                   F&& step) {
  std::string thrown;
  try {
    step();
  } catch (const std::exception& e) {
    thrown = e.what();
  } catch (...) {
    thrown = "unknown failure inside Gmsh";
  }
  std::vector<std::string> errors = session.take_errors();
  if (!thrown.empty()) errors.push_back(thrown);
  if (errors.empty()) return;
  // Gmsh may repeat one error for every point it tries: show the first three.
  const std::size_t more = errors.size() > 3 ? errors.size() - 3 : 0;
  errors.resize(errors.size() - more);
  if (more) errors.push_back(fmt::format("and {} more", more));
  throw InputError::in_file(source, fmt::format("Gmsh failed {}: {}", what, join(errors, "; ")));
}

// The first point where the size callback met a non-positive h (Gmsh cannot be told "stop"
// from inside the callback, so it gets a usable size and we report after meshing).
struct SizeFailure {
  std::mutex mutex;
  bool failed = false;
  double h = 0, x = 0, y = 0, z = 0;
};

// All nodes of the block within 1e-9 × its bounding-box diagonal of the plane through their
// centroid, normal to the sum of the triangles' area vectors.
bool is_planar(const Mesh& mesh, const ElementBlock& block) {
  std::array<double, 3> normal{0, 0, 0}, centroid{0, 0, 0}, lo{HUGE_VAL, HUGE_VAL, HUGE_VAL},
      hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  std::size_t count = 0;
  for (std::size_t e = 0; e < block.size(); ++e) {
    const auto n = block.element(e);
    const auto a = mesh.node(n[0]), b = mesh.node(n[1]), c = mesh.node(n[2]);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    normal[0] += u[1] * v[2] - u[2] * v[1];
    normal[1] += u[2] * v[0] - u[0] * v[2];
    normal[2] += u[0] * v[1] - u[1] * v[0];
    for (int k = 0; k < 3; ++k) {
      const auto p = mesh.node(n[k]);
      for (int d = 0; d < 3; ++d) {
        centroid[d] += p[d];
        lo[d] = std::min(lo[d], p[d]);
        hi[d] = std::max(hi[d], p[d]);
      }
      ++count;
    }
  }
  const double len = std::hypot(normal[0], normal[1], normal[2]);
  if (count == 0 || len == 0) return false;  // a closed surface has a zero area vector
  const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  for (double& c : centroid) c /= static_cast<double>(count);
  for (std::size_t e = 0; e < block.size(); ++e)
    for (const NodeIndex n : block.element(e)) {
      const auto p = mesh.node(n);
      const double d = ((p[0] - centroid[0]) * normal[0] + (p[1] - centroid[1]) * normal[1] +
                        (p[2] - centroid[2]) * normal[2]) / len;
      if (std::abs(d) > 1e-9 * diag) return false;
    }
  return true;
}

// Sizes, algorithm, parity-right curves, then surfaces; read back and check.
Triangulation mesh_current_model(geometry::GmshSession& session, const std::string& source,
                                 const TriangulationOptions& options, Clock::time_point start) {
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities);
  std::size_t count[4] = {0, 0, 0, 0};
  for (const auto& dt : entities) ++count[dt.first];
  if (count[2] == 0)
    throw InputError::in_file(
        source, fmt::format("no surfaces to mesh: the model has {} points, {} curves, {} "
                            "surfaces and {} volumes (quadval meshes surfaces)",
                            count[0], count[1], count[2], count[3]));

  SizeFailure failure;
  if (options.size) {
    // Before meshing, h must be positive at the model's points (they are on the geometry;
    // the bounding box is not, e.g. a hole). Gmsh then asks the callback below everywhere
    // else, and the nodes are checked after meshing.
    std::vector<double> points;
    for (const auto& [dim, tag] : entities) {
      if (dim != 0) continue;
      std::vector<double> xyz;
      gmsh::model::getValue(0, tag, {}, xyz);
      points.insert(points.end(), xyz.begin(), xyz.end());
    }
    options.size->check_positive_at(points, "geometry point");
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    const SizeField h = *options.size;
    const double fallback = std::isfinite(options.size_max) ? options.size_max : 1.0;
    gmsh::model::mesh::setSizeCallback(
        [h, fallback, &failure](int, int, double x, double y, double z) -> double {
          const double v = h(x, y, z);
          if (std::isfinite(v) && v > 0) return v;
          std::lock_guard lock(failure.mutex);
          if (!failure.failed) {
            failure.failed = true;
            failure.h = v, failure.x = x, failure.y = y, failure.z = z;
          }
          return fallback;
        });
  }
  if (options.size_min > 0) gmsh::option::setNumber("Mesh.MeshSizeMin", options.size_min);
  if (std::isfinite(options.size_max)) gmsh::option::setNumber("Mesh.MeshSizeMax", options.size_max);
  gmsh::option::setNumber("Mesh.Algorithm", gmsh_algorithm_id(options.algorithm));
  // Debian's Gmsh 4.8.4 is built without ANN: with the default closest-point cross field,
  // Frontal-Delaunay for quads dereferences a null octree (backgroundMesh::getAngle) and
  // crashes. Computing the cross field on a background mesh avoids that path (measured:
  // 0/10 runs survive the default here, 10/10 this setting).
  gmsh::option::setNumber("Mesh.CrossFieldClosestPoint", 0);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);

  // Paper I eqs. (5)-(6): odd interior node counts on every curve make the triangle count of
  // a planar face even. Gmsh chooses such counts when recombination is on during the 1D step.
  auto mesh_curves_then_surfaces = [&] {
    if (options.odd_curve_nodes) {
      gmsh::option::setNumber("Mesh.RecombineAll", 1);
      gmsh::option::setNumber("Mesh.RecombinationAlgorithm", 1);
    }
    run_gmsh_step(session, source, "to mesh the curves", [] { gmsh::model::mesh::generate(1); });
    gmsh::option::setNumber("Mesh.RecombineAll", 0);
    run_gmsh_step(session, source, "to mesh the surfaces", [] { gmsh::model::mesh::generate(2); });
  };
  std::vector<std::string> warnings;
  try {
    mesh_curves_then_surfaces();
  } catch (const InputError& e) {
    if (options.algorithm != TriangleAlgorithm::frontal_quad || failure.failed) throw;
    // Frontal-Delaunay for quads needs a cross field on a background mesh, in which Gmsh 4.8.4
    // cannot locate points near the seam of a periodic CAD face (a cylinder's): such models
    // are meshed again with Frontal-Delaunay, which needs no cross field.
    warnings.push_back(fmt::format("Frontal-Delaunay for quads failed, so the surfaces were "
                                   "meshed with Frontal-Delaunay instead ({})",
                                   e.message()));
    gmsh::model::mesh::clear();
    (void)session.take_errors();
    gmsh::option::setNumber("Mesh.Algorithm", gmsh_algorithm_id(TriangleAlgorithm::frontal));
    mesh_curves_then_surfaces();
  }
  if (failure.failed)
    throw InputError::in_file(
        fmt::format("size expression '{}'", options.size->expression()),
        fmt::format("h = {} at ({}, {}, {}), where Gmsh asked for a size; a size field must be "
                    "positive",
                    failure.h, failure.x, failure.y, failure.z));

  Triangulation out;
  out.warnings = std::move(warnings);
  out.mesh = geometry::read_gmsh_model_mesh(2);
  out.num_volumes_skipped = count[3];
  for (const ElementBlock& block : out.mesh.blocks) {
    if (block.entity_dim == 1 && block.type->family == ElementFamily::line) {
      std::vector<std::size_t> tags;
      std::vector<double> xyz, uvw;
      gmsh::model::mesh::getNodes(tags, xyz, uvw, 1, block.entity_tag, false, false);
      out.curves.push_back({block.entity_tag, tags.size()});
    }
    if (block.entity_dim == 2 && block.type->family == ElementFamily::triangle) {
      out.surfaces.push_back({block.entity_tag, block.size(), is_planar(out.mesh, block)});
      out.num_triangles += block.size();
    }
  }
  std::sort(out.curves.begin(), out.curves.end(),
            [](const CurveNodes& a, const CurveNodes& b) { return a.curve < b.curve; });
  if (out.num_triangles == 0)
    throw InputError::in_file(source, "Gmsh made no triangles on the model's surfaces");
  if (options.size) options.size->check_positive_at(out.mesh.coords, "mesh node");
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

enum class GeometryKind { geo, occ, stl };

GeometryKind kind_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".geo") return GeometryKind::geo;
  if (ext == ".step" || ext == ".stp" || ext == ".brep" || ext == ".brp") return GeometryKind::occ;
  if (ext == ".stl") return GeometryKind::stl;
  if (ext == ".msh" || ext == ".vtu" || ext == ".vtk" || ext == ".obj" || ext == ".off")
    throw InputError::in_file(path.string(),
                              "this is a mesh, not a geometry; to recombine the triangles of a "
                              "mesh, use `quadval recombine`");
  throw InputError::in_file(path.string(),
                            fmt::format("unknown geometry extension '{}'; expected .geo, .step, "
                                        ".stp, .brep or .stl",
                                        ext));
}

}  // namespace

Triangulation geometry::gmsh_triangulate_file(const std::filesystem::path& path,
                                              const TriangulationOptions& options) {
  const std::string source = path.string();
  const GeometryKind kind = kind_of(path);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError::in_file(source, "no such file");
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError::in_file(source, "not a regular file");
  if (!std::ifstream(path))
    throw InputError::in_file(source, "cannot open the file for reading");
  if (std::filesystem::file_size(path, ec) == 0)
    throw InputError::in_file(source, "the file is empty");

  const auto start = Clock::now();
  geometry::GmshSession session(options.verbose);
  run_gmsh_step(session, source, "to read the file", [&] {
    const QuietStdout quiet(!options.verbose);
    if (kind == GeometryKind::stl) {
      gmsh::merge(source);
      // A triangulation only: split it into smooth patches at 40° and give each a
      // parametrisation, so that it can be remeshed (Paper I §8.2).
      gmsh::model::mesh::classifySurfaces(40 * std::numbers::pi / 180, /*boundary=*/true,
                                          /*forReparametrization=*/true,
                                          /*curveAngle=*/std::numbers::pi);
      gmsh::model::mesh::createGeometry();
    } else {
      gmsh::open(source);
    }
  });
  return mesh_current_model(session, source, options, start);
}

Triangulation geometry::gmsh_triangulate_domain(const PlanarDomain& domain,
                                                const TriangulationOptions& options) {
  const auto start = Clock::now();
  if (options.size) {
    // A quick look at h on a 33 x 33 grid of points inside the domain, before Gmsh starts.
    const auto box = domain_bounding_box(domain);
    std::vector<double> inside;
    constexpr int kSteps = 32;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; j <= kSteps; ++j) {
        const double x = box[0] + (box[3] - box[0]) * i / kSteps;
        const double y = box[1] + (box[4] - box[1]) * j / kSteps;
        if (domain_contains(domain, x, y)) inside.insert(inside.end(), {x, y, 0.0});
      }
    options.size->check_positive_at(inside, "sample point inside the domain");
  }
  geometry::GmshSession session(options.verbose);
  gmsh::model::add("planar_domain");
  namespace occ = gmsh::model::occ;
  // One curve loop per boundary: polygon sides are lines, a circle is one closed curve (with
  // one model vertex). OpenCASCADE, unlike the built-in kernel, needs no centre point, which
  // would otherwise be meshed as a stray node.
  auto add_loop = [](const DomainLoop& loop) {
    std::vector<int> curves;
    if (loop.kind == DomainLoop::Kind::circle) {
      curves.push_back(occ::addCircle(loop.center[0], loop.center[1], 0, loop.radius));
    } else {
      std::vector<int> p;
      for (const auto& v : loop.vertices) p.push_back(occ::addPoint(v[0], v[1], 0));
      for (std::size_t k = 0; k < p.size(); ++k)
        curves.push_back(occ::addLine(p[k], p[(k + 1) % p.size()]));
    }
    return occ::addCurveLoop(curves);
  };
  run_gmsh_step(session, domain.source, "to build the planar domain", [&] {
    std::vector<int> loops{add_loop(domain.outer)};
    for (const auto& hole : domain.holes) loops.push_back(add_loop(hole));
    occ::addPlaneSurface(loops);
    occ::synchronize();
  });
  return mesh_current_model(session, domain.source, options, start);
}

}  // namespace quadval
