#pragma once
/// The look-ahead trees of Paper II (thesis lines 798-942): recombination as sequential
/// decision-making. State: the current mixed mesh; action: merge two adjacent triangles;
/// reward: eta of the new quad (Paper I eq. 3); global quality q: the sum of the rewards.
/// Actions that violate the recombination criterion (Definition 2: the merge would leave a
/// polder set, i.e. a connected set of triangles, of odd size) are never taken.
///
/// Used through recombine() with RecombineAlgorithm::lookahead; these are its options and
/// per-run figures.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace quadval {

enum class LookaheadTree {
  /// §5: branch only on the options of the triangle with the fewest options (chosen among the
  /// neighbours of the quads made along the branch when possible). Branching <= 3, so the
  /// cost is about #triangles * 2^horizon.
  selective,
  /// §4: branch on every allowed action. Cost about #triangles^(horizon + 1): small meshes or
  /// horizon 1 only (horizon 1 is the greedy algorithm with the criterion, §6.2).
  uniform,
};

struct LookaheadOptions {
  int horizon = 3;  ///< depth of the tree (>= 1)
  LookaheadTree tree = LookaheadTree::selective;
  /// Run i (0-based) draws its random choices (ties, which triangle among the most
  /// constrained) from std::mt19937_64 seeded with seed + i.
  std::uint64_t seed = 1;
  int runs = 1;  ///< best of `runs` independent runs (in parallel; ties: lowest run index)
};

/// Figures of one run (one seed).
struct LookaheadRun {
  std::uint64_t seed = 0;
  double quality = 0.0;               ///< q = sum of eta over the quads made
  std::size_t quads = 0;              ///< merges made
  std::size_t triangles_left = 0;     ///< triangles never merged
  double seconds = 0.0;
  /// Triangles visited by the parity searches of the criterion (a cost figure: it should
  /// grow linearly with the mesh).
  std::uint64_t search_steps = 0;
};

}  // namespace quadval
