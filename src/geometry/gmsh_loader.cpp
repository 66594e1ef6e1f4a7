// triangulate_geometry_file and triangulate_planar_domain, on the library's side: they load
// the Gmsh front-end module once (gmsh_module.hpp says why) and call into it.
#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/gmsh_module.hpp"
#include "quadval/error.hpp"
#include "quadval/geometry.hpp"

namespace quadval {

const char* triangle_algorithm_name(TriangleAlgorithm a) noexcept {
  switch (a) {
    case TriangleAlgorithm::frontal_quad: return "frontal-quad";
    case TriangleAlgorithm::frontal: return "frontal";
    case TriangleAlgorithm::delaunay: return "delaunay";
  }
  return "?";
}

namespace {

struct Module {
  geometry::TriangulateFileFn triangulate_file = nullptr;
  geometry::TriangulateDomainFn triangulate_domain = nullptr;
  std::string error;  // why it could not be loaded
};

std::filesystem::path executable_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

// Where the module may be: $QUADVAL_GMSH_MODULE alone when it is set; otherwise, in order,
// beside the executable (the build tree), ../lib/quadval from it (the installed layout), and
// the build tree this library was configured in (tests and benchmarks run from subfolders).
std::vector<std::string> candidate_paths() {
  std::vector<std::string> paths;
  if (const char* env = std::getenv("QUADVAL_GMSH_MODULE"); env != nullptr && *env != '\0')
    return {env};
  if (const auto dir = executable_dir(); !dir.empty()) {
    paths.push_back((dir / geometry::kGmshModuleName).string());
    paths.push_back((dir / ".." / "lib" / "quadval" / geometry::kGmshModuleName).string());
  }
#ifdef QUADVAL_GMSH_MODULE_BUILD_PATH
  paths.emplace_back(QUADVAL_GMSH_MODULE_BUILD_PATH);
#endif
  return paths;
}

Module load_module() {
  Module m;
  std::string tried;
  for (const std::string& path : candidate_paths()) {
    if (access(path.c_str(), F_OK) != 0) {
      tried += "\n  " + path + ": no such file";
      continue;
    }
    // RTLD_LOCAL: the module's copies of our own functions stay private to it.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      tried += "\n  " + path + ": " + dlerror();
      continue;
    }
    const auto layout =
        reinterpret_cast<geometry::LayoutFn>(dlsym(handle, geometry::kLayoutSymbol));
    if (layout == nullptr || layout() != geometry::module_layout()) {
      tried += "\n  " + path + ": built by another version of quadval";
      dlclose(handle);
      continue;
    }
    m.triangulate_file = reinterpret_cast<geometry::TriangulateFileFn>(
        dlsym(handle, geometry::kTriangulateFileSymbol));
    m.triangulate_domain = reinterpret_cast<geometry::TriangulateDomainFn>(
        dlsym(handle, geometry::kTriangulateDomainSymbol));
    if (m.triangulate_file != nullptr && m.triangulate_domain != nullptr) return m;
    tried += "\n  " + path + ": entry points missing";
    dlclose(handle);
  }
  m.error = std::string("cannot load the Gmsh front end (") + geometry::kGmshModuleName +
            "), which `quadval mesh` and `quadval demo` need; it needs libgmsh 4.8 "
            "(Debian: apt-get install libgmsh-dev). Looked in:" + tried;
  return m;
}

const Module& module() {
  static const Module m = load_module();  // thread-safe, once per process
  return m;
}

void rethrow(const geometry::ModuleOutcome& outcome) {
  if (outcome.input_error) throw InputError(*outcome.input_error);
  if (!outcome.other_error.empty()) throw std::runtime_error(outcome.other_error);
}

const Module& loaded_module(const std::string& source) {
  const Module& m = module();
  if (!m.error.empty()) throw InputError::in_file(source, m.error);
  return m;
}

}  // namespace

Triangulation triangulate_geometry_file(const std::filesystem::path& path,
                                        const TriangulationOptions& options) {
  const Module& m = loaded_module(path.string());
  Triangulation out;
  geometry::ModuleOutcome outcome;
  m.triangulate_file(path, options, out, outcome);
  rethrow(outcome);
  return out;
}

Triangulation triangulate_planar_domain(const PlanarDomain& domain,
                                        const TriangulationOptions& options) {
  const Module& m = loaded_module(domain.source);
  Triangulation out;
  geometry::ModuleOutcome outcome;
  m.triangulate_domain(domain, options, out, outcome);
  rethrow(outcome);
  return out;
}

}  // namespace quadval
