// The entry points of libquadval_gmsh.so (see gmsh_module.hpp). The module is built with
// hidden visibility: these three are all it exports.
#include "geometry/gmsh_module.hpp"

#include <exception>
#include <new>

namespace {

using quadval::geometry::ModuleOutcome;

template <class F>
void run_catching(ModuleOutcome& outcome, F&& f) noexcept {
  try {
    f();
  } catch (const quadval::InputError& e) {
    outcome.input_error.emplace(e);
  } catch (const std::exception& e) {
    outcome.other_error = e.what();
  } catch (...) {
    outcome.other_error = "unknown exception in the Gmsh front end";
  }
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) std::uint64_t quadval_gmsh_module_layout() {
  return quadval::geometry::module_layout();
}

__attribute__((visibility("default"))) void quadval_gmsh_triangulate_file(
    const std::filesystem::path& path, const quadval::TriangulationOptions& options,
    quadval::Triangulation& out, ModuleOutcome& outcome) {
  run_catching(outcome, [&] { out = quadval::geometry::gmsh_triangulate_file(path, options); });
}

__attribute__((visibility("default"))) void quadval_gmsh_triangulate_domain(
    const quadval::PlanarDomain& domain, const quadval::TriangulationOptions& options,
    quadval::Triangulation& out, ModuleOutcome& outcome) {
  run_catching(outcome,
               [&] { out = quadval::geometry::gmsh_triangulate_domain(domain, options); });
}

}  // extern "C"
