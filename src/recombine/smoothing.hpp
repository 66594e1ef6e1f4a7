#pragma once
// Vertex smoothing of Paper I §6: each free node moves toward the size-weighted mean of its
// edge neighbours; a move is kept only if it does not lower the worst shape score of the
// elements around the node (so it never inverts an element: the Jacobian check).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mixed_mesh.hpp"
#include "surface_projection.hpp"
#include "quadval/recombine.hpp"

namespace quadval::recombine_detail {

/// The score of a quad (element_score's, which calls it): eta of eq. 3 (quad_eta) when that is
/// positive, else min(quad_min_corner_sine, 0), equal to those bit for bit (their operations in
/// their order), but with each edge and its length computed once: 4 square roots instead of
/// up to 17. Returns -2 for a triangle.
/// @param element        4 corners, counter-clockwise seen from `normal`
/// @param coords         MixedMesh::coords (#nodes × 3)
/// @param normal_length  std::sqrt(n·n) of `normal`, summed in x, y, z order
double smoothing_score(const std::vector<double>& coords, const std::array<NodeIndex, 4>& element,
                       const std::array<double, 3>& normal, double normal_length) noexcept;

/// smoothing_score of up to four quads at once (lane k: quads[k], normals[k],
/// normal_lengths[k], for k < count), each equal to it bit for bit: the per-corner products,
/// square roots and eta (eta_of_cosine.hpp) in SIMD lanes with the same operations in the
/// same order (no FMA contraction: -ffp-contract=off); only invalid quads' corner sines per
/// quad. With eta in lanes instead of std::asin per quad, square-hole-1M's three smoothing
/// stages took 792 + 739 + 108 -> 617 + 550 + 87 ms (medians of 3 runs).
/// @pre 1 <= count <= 4; every quads[k] is a quad (no kNoNode)
void smoothing_scores4(const std::vector<double>& coords, const std::array<NodeIndex, 4>* const quads[4],
                       const std::array<double, 3>* const normals[4], const double normal_lengths[4], int count,
                       double out[4]) noexcept;

struct SmoothingOptions {
  int passes = 5;
  /// Optional size field: neighbour j gets the weight 1 / h(midpoint of v-j), which puts v
  /// where the two adimensional lengths (eq. 1) balance; without it, all weights are 1.
  const SizeFunction* size_field = nullptr;
  /// Project the move on the tangent plane (the mean of the element normals): for surfaces.
  bool tangential = false;
  /// Optional, per node (straight_boundary_slides): a fixed node with neighbours {a, b} moves
  /// along the line a-b instead, and only to points strictly between a and b.
  const std::vector<std::array<NodeIndex, 2>>* slides = nullptr;
  /// Movable nodes per block of the sweep (smoothing_order): blocks of one colour are
  /// smoothed in parallel.
  int block = 512;
  /// Optional, for surfaces in 3D: every trial position of a free node is first brought back
  /// to the input surface (surface_projection.hpp), so the nodes stay on it.
  SurfaceProjection* surface = nullptr;
};

/// Smooths the free nodes (fixed[v] == 0, and the fixed ones that may slide) in place, one
/// node after the other (Gauss-Seidel) in smoothing_order, the blocks of one colour on
/// several threads (OpenMP): the result does not depend on their number. Returns the number
/// of accepted moves.
/// A move to the weighted mean is tried, then half of it. Two phases of `passes` sweeps each
/// (phase 2 ends early once a sweep accepts nothing):
/// 1. a move is kept when min(score of the elements at v) does not decrease (element_score:
///    > 0 valid), which raises the worst element of the mesh;
/// 2. a move is also kept when it raises the sum of the scores at v while every one stays at
///    or above the worst score of the mesh at the start of the sweep (so eta_min never drops
///    and eta_mean rises; measured on rect-sin-a6: mean 0.740 -> 0.763, min kept).
/// No move can invalidate a valid element.
/// Cost: quads scored four at a time (smoothing_scores4) and element data copied in node
/// order; the result is the same, to the bit, as the plain sweep in smoothing_order
/// (tests/recombine/smoothing_test.cpp checks it against one). Two threads: square-hole-1M,
/// the two smoothing stages 3.6 + 2.4 s -> 1.6 + 1.9 s; four at a time (look-ahead's quads,
/// two alternating runs): 2.42-2.44 -> 2.08-2.24 s for both.
std::size_t smooth(MixedMesh& m, const std::vector<char>& fixed, const SmoothingOptions& options);

/// The order in which smooth() moves the nodes: the movable nodes in node order are cut into
/// blocks of options.block; the blocks get greedy colours (in block order, the smallest
/// colour no earlier block sharing an element has); then colour by colour, block by block,
/// each block's nodes in node order. Two blocks of one colour share no element, so their
/// moves do not interact and run in parallel.
struct SmoothingSweep {
  std::vector<NodeIndex> nodes;        ///< in the order they move
  std::vector<std::uint32_t> colors;   ///< the colour of each one's block
};
SmoothingSweep smoothing_order(const MixedMesh& m, const std::vector<char>& fixed,
                               const SmoothingOptions& options);

/// A last pass on the worst elements (the worst `share` of them, at least 16): each of their
/// movable nodes (as in smooth) does a pattern search, steps of +-h along two tangent
/// directions (or along its straight side), h halving from a tenth of its mean edge length
/// down to 1e-3 of it; a step is kept only when it strictly raises the worst score of the
/// elements at the node. So the mesh's worst element never gets worse and no element is
/// inverted (Paper I §6 asks for no inversion; the max-min search is ours). Returns moves kept.
/// The nodes are searched by levels (a node's level is one more than the highest of the
/// earlier listed nodes sharing an element with it), each level's in parallel (OpenMP): the
/// same result, to the bit, as the searches one after the other in node order, for any number
/// of threads. With the elements' scores four at a time (smoothing_scores4), square-hole-1M's
/// polish took 300 -> 160 ms on two threads (medians of 3 runs).
std::size_t polish_worst(MixedMesh& m, const std::vector<char>& fixed,
                         const SmoothingOptions& options, double share = 0.02);

/// polish_worst's search at one movable node v (free, or fixed with a slide, `sliding`), whose
/// alive elements are `star`: writes only v's position, reads only the corners of `star`.
/// Returns the moves kept.
std::size_t polish_node(MixedMesh& m, NodeIndex v, std::span<const std::uint32_t> star, bool sliding,
                        const SmoothingOptions& options);

}  // namespace quadval::recombine_detail
