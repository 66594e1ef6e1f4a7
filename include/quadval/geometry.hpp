#pragma once
/// From geometry to triangles, through Gmsh's C++ API (DESIGN.md "Data flow"): the first step
/// of Blossom-Quad (Paper I §7 step 1, thesis lines 688-690).
///
/// Every model edge (curve) is meshed with an odd number of interior nodes, so that by
/// Euler's formula (Paper I eqs. 5-6) each planar face gets an even number of triangles and a
/// perfect matching can exist. The curves are meshed with Gmsh's recombination switched on
/// for the 1D step only (Mesh.RecombineAll = 1, Mesh.RecombinationAlgorithm = 1: Gmsh then
/// picks a node count of the right parity on each curve), then the faces are triangulated
/// with recombination off. The counts are read back and checked, never assumed.
///
/// Only built when QUADVAL_WITH_GMSH is defined (libgmsh found at configure time); the core
/// library never needs it. Gmsh keeps global state and is not thread-safe: each call holds
/// a process-wide lock for its whole Gmsh session (initialize ... finalize).

#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "quadval/mesh.hpp"
#include "quadval/planar_domain.hpp"
#include "quadval/size_field.hpp"

namespace quadval {

/// Gmsh's 2D algorithms (option Mesh.Algorithm).
enum class TriangleAlgorithm {
  frontal_quad,  ///< 8: Frontal-Delaunay for quads, right-angled triangles (best for Blossom)
  frontal,       ///< 6: Frontal-Delaunay
  delaunay,      ///< 5: Delaunay
};

/// "frontal-quad", "frontal", "delaunay".
const char* triangle_algorithm_name(TriangleAlgorithm a) noexcept;

struct TriangulationOptions {
  TriangleAlgorithm algorithm = TriangleAlgorithm::frontal_quad;
  /// The size field h(x, y, z). When set, it alone drives the sizes (sizes from the
  /// geometry's points and from curvature are switched off). When empty, Gmsh's own sizes
  /// apply (the .geo file's, or a fraction of the model's size).
  std::optional<SizeField> size;
  double size_min = 0.0;  ///< Mesh.MeshSizeMin: clamps every size from below
  double size_max = std::numeric_limits<double>::infinity();  ///< Mesh.MeshSizeMax
  /// Mesh the curves with an odd number of interior nodes (the 1D recombination switch
  /// described above). Off: Gmsh's plain 1D meshing, for comparison.
  bool odd_curve_nodes = true;
  bool verbose = false;  ///< let Gmsh print to the terminal
};

/// The interior node count of one model curve (Paper I eq. 6: nodes of the curve minus its
/// end points).
struct CurveNodes {
  int curve = 0;                ///< Gmsh curve tag
  std::size_t interior_nodes = 0;
  bool odd() const noexcept { return interior_nodes % 2 == 1; }
};

/// The triangles of one model surface.
struct SurfaceTriangles {
  int surface = 0;              ///< Gmsh surface tag
  std::size_t triangles = 0;
  /// All its nodes lie in one plane (to 1e-9 of its size): smoothing inside it keeps nodes on
  /// the geometry; on a curved face it would not.
  bool planar = true;
  bool even() const noexcept { return triangles % 2 == 0; }
};

struct Triangulation {
  /// Nodes of every meshed entity (node blocks per entity, Gmsh's node tags), element blocks
  /// per entity: points (type 15), lines (type 1) on curves, triangles (type 2) on surfaces.
  /// Entities (dims 0-2) with their bounding boxes, boundaries and physical tags.
  Mesh mesh;
  std::vector<CurveNodes> curves;        ///< every meshed curve, by tag
  std::vector<SurfaceTriangles> surfaces;
  std::size_t num_triangles = 0;
  std::size_t num_volumes_skipped = 0;   ///< volumes in the model (only their surfaces are meshed)
  double seconds = 0.0;                  ///< wall time inside Gmsh (load + mesh + read back)
  /// What did not go as asked, e.g. Frontal-Delaunay for quads failed on a periodic CAD face
  /// (Gmsh 4.8.4) and the surfaces were meshed with Frontal-Delaunay instead.
  std::vector<std::string> warnings;

  std::size_t num_odd_curves() const noexcept {
    std::size_t n = 0;
    for (const CurveNodes& c : curves) n += c.odd();
    return n;
  }
  bool all_curves_odd() const noexcept { return num_odd_curves() == curves.size(); }
  bool all_surfaces_planar() const noexcept {
    for (const SurfaceTriangles& s : surfaces)
      if (!s.planar) return false;
    return true;
  }
};

/// Meshes the surfaces of a geometry file with triangles.
/// @param path  .geo (Gmsh script), .step/.stp, .brep (OpenCASCADE), or .stl (a triangulation
///              that is classified into surfaces at 40° and reparametrised before remeshing,
///              as Paper I §8.2 does).
/// @throws InputError naming the file for: a missing or unreadable file, an unsupported
///         extension (a mesh file such as .msh is pointed to `quadval recombine`), an error
///         reported by Gmsh while loading or meshing, a model without surfaces (empty, or
///         only points and curves), a size field that is not positive on the model's bounding
///         box or at a mesh node.
Triangulation triangulate_geometry_file(const std::filesystem::path& path,
                                        const TriangulationOptions& options);

/// Meshes a planar domain (outer loop and holes, planar_domain.hpp) in the plane z = 0. Each
/// polygon side is one model curve; a circle is four quarter arcs.
/// @throws InputError as above.
Triangulation triangulate_planar_domain(const PlanarDomain& domain,
                                        const TriangulationOptions& options);

}  // namespace quadval
