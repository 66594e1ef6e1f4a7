#pragma once
// The Gmsh front end lives in a module, libquadval_gmsh.so, that the library loads on the
// first call of triangulate_geometry_file / triangulate_planar_domain (gmsh_loader.cpp). Why:
// libgmsh pulls in about 90 shared libraries (OpenCASCADE, FLTK, X11, ...) whose loading and
// relocation took ~130 ms at the start of every quadval process, `quadval check` of ten
// elements included, and made every command fail to start where they are not installed.
// Only `quadval mesh` and `quadval demo` need them now.
//
// This header is the interface between the two sides. Both are built from the same sources
// in the same build, so they share the layout of the structures passed by reference; the
// loader still checks kGmshModuleAbi and the sizes (module_layout) to refuse a stale module.
// Errors do not cross as exceptions: the module catches them and the loader throws again.
// Internal to src/geometry.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "quadval/error.hpp"
#include "quadval/geometry.hpp"

namespace quadval::geometry {

inline constexpr const char* kGmshModuleName = "libquadval_gmsh.so";
/// Raise when the entry points or the meaning of their arguments change.
inline constexpr std::uint32_t kGmshModuleAbi = 1;

/// A fingerprint of the structures passed across: equal on both sides of one build.
inline std::uint64_t module_layout() {
  return (std::uint64_t{kGmshModuleAbi} << 48) ^ (sizeof(Triangulation) << 32) ^
         (sizeof(TriangulationOptions) << 16) ^ (sizeof(PlanarDomain) << 8) ^
         sizeof(Mesh) ^ (sizeof(InputError) << 40);
}

/// How a call ended: nothing set is success.
struct ModuleOutcome {
  std::optional<InputError> input_error;  ///< bad input, to be thrown again as is
  std::string other_error;                ///< anything else (what() of the exception)
};

// The entry points (extern "C", so that dlsym finds them by these names).
using LayoutFn = std::uint64_t (*)();
using TriangulateFileFn = void (*)(const std::filesystem::path&, const TriangulationOptions&,
                                   Triangulation&, ModuleOutcome&);
using TriangulateDomainFn = void (*)(const PlanarDomain&, const TriangulationOptions&,
                                     Triangulation&, ModuleOutcome&);
inline constexpr const char* kLayoutSymbol = "quadval_gmsh_module_layout";
inline constexpr const char* kTriangulateFileSymbol = "quadval_gmsh_triangulate_file";
inline constexpr const char* kTriangulateDomainSymbol = "quadval_gmsh_triangulate_domain";

// The implementations, inside the module (triangulate.cpp); their documentation is that of
// triangulate_geometry_file and triangulate_planar_domain in quadval/geometry.hpp.
Triangulation gmsh_triangulate_file(const std::filesystem::path& path,
                                    const TriangulationOptions& options);
Triangulation gmsh_triangulate_domain(const PlanarDomain& domain,
                                      const TriangulationOptions& options);

}  // namespace quadval::geometry
