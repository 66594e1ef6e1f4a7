#pragma once
/// Triangle-to-quadrangle recombination: Blossom-Quad (Paper I, thesis lines 449-797), the
/// greedy baseline (Paper I §3) and the full-quad route by uniform refinement (Paper I §3,
/// Fig. 2), followed by the repair of extra-edge pairs (§5.3) and the optimisation of §6.
///
/// The steps of Paper I §7:
///   1. triangles in (odd counts handled as documented in RecombineOptions::odd_policy);
///   2. dual graph with pair costs 1 - eta (eq. 3, 4) or the cross-field cost (eq. 7);
///   3. extra boundary edges of cost 1000 (§5.3);
///   4. min-cost perfect matching, exact on int64 costs (src/recombine/blossom_solver.hpp: a
///      primal-dual blossom solver with a greedy start, checked against LEMON's
///      MaxWeightedPerfectMatching and brute force in the tests; LEMON finds the maximum
///      matching when no perfect one exists);
///   5. repair of matched extra edges: edge swap (Fig. 8) or vertex duplication (Fig. 9);
///   6. smoothing (boundary nodes slide along straight boundary segments), quad-vertex-merge
///      (Fig. 10), doublet collapse (Fig. 11), then a local search on the worst 2 % of the
///      nodes that only accepts moves raising the worst quality there.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "quadval/lookahead.hpp"
#include "quadval/mesh.hpp"

namespace quadval {

enum class RecombineAlgorithm {
  blossom,  ///< optimal: min-cost perfect matching (Paper I §4)
  greedy,   ///< best pair first, isolated triangles stay (Paper I §3)
  lookahead,  ///< look-ahead tree (Paper II), options in RecombineOptions::lookahead
};

enum class PairCostKind {
  angle,       ///< 1 - eta(quad), Paper I eq. (3)-(4)
  cross_field, ///< alignment of the removed edge with a cross field, Paper I eq. (7)
};

/// What to do when a connected piece of triangles (within one surface entity) has an odd
/// count: then no perfect matching can exist.
enum class OddPolicy {
  /// Split the longest boundary edge of each odd piece at its midpoint (its triangle becomes two):
  /// the count becomes even, the boundary keeps its shape, the result is all-quad. The odd
  /// pieces of a closed surface cut at feature edges are made even in pairs, by splitting edges
  /// between pieces (3T = 2E makes the surface's total even); a piece left odd falls back to
  /// leave_triangle.
  split_boundary_edge,
  /// Match as many triangles as possible: at least one triangle is left in the output.
  leave_triangle,
};

/// A size field h(x, y, z) > 0. Must be safe to call from several threads at once.
using SizeFunction = std::function<double(double x, double y, double z)>;

struct RecombineOptions {
  RecombineAlgorithm algorithm = RecombineAlgorithm::blossom;
  PairCostKind cost = PairCostKind::angle;
  /// Cross field for PairCostKind::cross_field: the angle (radians) of its first direction,
  /// either one constant, or one per input triangle (in the order of triangle_corners(),
  /// i.e. triangle blocks in file order). On a surface in 3D the direction
  /// (cos a, sin a, 0) is projected on the pair's tangent plane.
  double cross_field_angle = 0.0;
  std::vector<double> cross_field_per_triangle;
  /// Paper I §5.3: extra graph edges between the triangles of successive boundary edges.
  bool extra_edges = true;
  double extra_edge_cost = 1000.0;  ///< Paper I §7 step 3 ("typically 1000")
  OddPolicy odd_policy = OddPolicy::split_boundary_edge;
  /// Surfaces in 3D: an edge where the two triangles' normals turn by more than this angle
  /// (degrees) is a feature, kept as CAD curves are: no quad across it, its nodes held (or
  /// sliding along it where it is straight). 180 or more: no features. Planar meshes have none.
  double feature_angle = 40.0;
  /// Paper I §6. When false, the matched quads are returned as they are (after repair).
  bool optimize = true;
  int smoothing_passes = 5;        ///< Laplacian sweeps before and after the clean-up; 0: none
  int max_cleanup_passes = 5;      ///< rounds of quad-vertex-merge, doublet collapse and diagonal
                                   ///< swap (quad_cleanup.hpp); 0: none
  /// Full-quad route: after recombination (and optimisation), split each quad into 4 and each
  /// triangle into 3 (Fig. 2). The size halves, as the paper notes.
  bool full_quad = false;
  /// Optional size field: weights the smoothing (so that it keeps the gradation) and gives the
  /// efficiency index tau of eq. (1)-(2) in the statistics.
  SizeFunction size_field;
  /// RecombineAlgorithm::lookahead: tree, horizon, seed, runs. The triangles the tree leaves
  /// are then paired along augmenting paths (Paper II §6's post-process; all-quad on every
  /// benchmark mesh); any still left become quads with full_quad (Fig. 2 refinement).
  LookaheadOptions lookahead;
  /// lookahead: also solve Blossom on the same pairs, for quality_percent_of_blossom.
  bool compare_with_blossom = false;
  /// Name of the input for error messages (e.g. the file path).
  std::string source = "<mesh>";
  /// Stage log lines ("[blossom] 18342 pairs, 3.1 ms"); empty: silent.
  std::function<void(const std::string&)> log;
  /// Blossom's progress: called after its greedy start and after each augmentation with the
  /// triangles paired since that start and the number it left unpaired (the second is fixed).
  /// The augmentations late in a run cost the most (their trees are the largest).
  std::function<void(std::uint32_t paired, std::uint32_t unpaired_at_start)> matching_progress;
};

/// One timed stage of the pipeline.
struct StageTime {
  std::string stage;
  double seconds = 0.0;
};

struct RecombineStats {
  std::size_t input_triangles = 0;
  std::size_t odd_splits = 0;            ///< edges split to make the pieces even
  std::size_t feature_edges = 0;         ///< edges kept as features (RecombineOptions::feature_angle)
  std::size_t graph_pairs = 0;           ///< real pairs (interior edges inside one region)
  std::size_t extra_pairs = 0;           ///< extra boundary edges added (§5.3)
  bool perfect_matching = false;         ///< every triangle matched (blossom) or paired
  std::size_t matched_extra_pairs = 0;
  std::size_t edge_swaps = 0;            ///< repairs by edge swap (Fig. 8)
  std::size_t vertex_duplications = 0;   ///< repairs by vertex duplication (Fig. 9)
  double matching_cost = 0.0;            ///< sum of the costs of the matched pairs (eq. 4)
  std::size_t smoothing_moves = 0;
  std::size_t vertex_merges = 0;         ///< quad-vertex-merges (Fig. 10)
  std::size_t doublet_collapses = 0;     ///< doublet collapses (Fig. 11)
  std::size_t diagonal_swaps = 0;        ///< quads re-split with a neighbour (a corner smoothing cannot mend)
  // Final mesh.
  std::size_t quads = 0;
  std::size_t triangles = 0;             ///< triangles left (0 for an all-quad result)
  std::size_t nodes = 0;
  std::size_t invalid_quads = 0;         ///< quads with a corner Jacobian <= 0 (non-convex)
  double eta_min = 0.0;                  ///< over the final quads (eq. 3)
  double eta_mean = 0.0;
  double degree4_share = 0.0;            ///< share of interior vertices with 4 quads around
  int degree_min = 0;                    ///< quads around an interior vertex, min and max
  int degree_max = 0;
  bool has_tau = false;                  ///< tau computed (a size field was given)
  double tau = 0.0;                      ///< efficiency index, percent, eq. (1)-(2)
  std::vector<StageTime> times;
  double total_seconds = 0.0;
  // RecombineAlgorithm::lookahead (Paper II).
  double lookahead_quality = 0.0;           ///< q = sum of eta of the merges (best run)
  std::size_t lookahead_triangles_left = 0; ///< before any post-process
  std::size_t lookahead_path_pairs = 0;     ///< leftover triangles then paired along paths
  double recombined_share = 0.0;            ///< share of the triangles merged (best run)
  std::size_t lookahead_best_run = 0;
  std::vector<LookaheadRun> lookahead_runs; ///< every run, in run order
  double blossom_quality = -1.0;            ///< compare_with_blossom: Blossom's q, else -1
  double quality_percent_of_blossom = -1.0; ///< 100 q / Blossom's q, else -1
};

struct RecombineResult {
  /// Quads (Gmsh type 3) in one block per input surface entity, orientation as the input
  /// triangles (made consistent per connected region); triangles left (greedy, or no perfect
  /// matching) in type-2 blocks. Nodes: those the elements use, original tags kept, new
  /// nodes numbered after the largest input tag, listed by increasing tag (so in the input's
  /// order, new nodes last). Entities and physical names are copied;
  /// 0D/1D elements are not carried over.
  Mesh mesh;
  RecombineStats stats;
  std::vector<std::string> warnings;
};

/// Recombines the triangles of `input` into quadrangles.
/// @pre input holds triangles (any order: corner nodes used; higher-order nodes dropped with a
///      warning), possibly lines and points (ignored).
/// @throws InputError (naming options.source and the element tag) for: no triangles,
///      2D elements other than triangles, 3D elements, a zero-area triangle, two triangles on
///      the same three nodes, an edge shared by more than two triangles, a non-orientable
///      surface, a cross field of the wrong length.
RecombineResult recombine(const Mesh& input, const RecombineOptions& options = {});

}  // namespace quadval
