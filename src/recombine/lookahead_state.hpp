#pragma once
// The state of the look-ahead recombination (Paper II §3): which triangles are still
// triangles, the quads made so far, and the recombination criterion (Definition 2), with
// apply/undo so that a look-ahead tree can explore from it.
//
// Definition 2, maintained incrementally. Let R be the set of free triangles (not yet merged)
// and C the polder set (connected component of R's dual graph) holding a pair (T, T'). The
// merge forbids itself iff R \ {T, T'} has a component of odd size inside C. Since every
// polder set is kept even (the criterion's invariant), |C| - 2 is even.
//
// Local test. Walk around the boundary of the would-be quad Q = T ∪ T': its 4 corners and its
// 4 edges. An edge is "closed" when no free triangle lies across it (a quad, or the boundary
// of the region); a corner v is closed when v is on the boundary of the region or a quad
// touches it. The free triangles across the open edges form "arcs" between closed runs.
//   (a) Inside one arc the neighbours are joined around the open corners between them (an
//       open corner has a full fan of free triangles), so with at most one closed run all
//       neighbours of Q are connected in R \ Q and C stays whole: allowed.
//   (b) The complement of R (quads and outside of the region) is vertex-connected into
//       components, kept in a union-find over nodes (a quad unites its 4 corners; each
//       boundary edge its 2 ends; rolled back on undo). On a genus-0 region (checked once:
//       Euler characteristic and boundary loops), a part of C \ Q is cut off only by a closed
//       curve made of Q and one complement component, which must leave Q through two
//       distinct closed runs of that component (Jordan curve theorem). Hence arcs i and j end
//       in different parts iff two closed runs of the same component lie one on each side of
//       them around Q; arcs not so separated are in one part.
//   (c) The sizes of the parts are counted by one breadth-first search per part, run in
//       lock-step, stopped once all but one part are exhausted: the last part's parity is
//       then known (|C| - 2 is even). Cost: (#parts) × (size of the second-largest part).
//       On a region of higher genus (b) is not used: every arc starts its own search and
//       searches that meet are merged.
// So each check is O(1) unless Q really cuts C, and then it is proportional to the pieces
// cut off (in practice the small pocket next to the front).
//
// Lemma (forbidden is forever): if X is forbidden in state M and Q is allowed, X is forbidden
// or unavailable after Q. Proof: X forbidden gives an odd component O of C \ X, adjacent to
// X. If Q is outside O, O is still a component next to X. If Q is in O, the components of
// O \ Q not adjacent to X are components of C \ Q (their only links to the rest were Q and
// X), hence even since Q is allowed; their total is |O| - 2 minus those, so some component
// of O \ Q adjacent to X is odd. So allowed options only decrease, which makes a greedy pass
// over a priority queue exact for horizon 1 and lets cached option counts be upper bounds.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "dual_graph.hpp"

namespace quadval::recombine_detail {

inline constexpr std::uint32_t kNone = 0xffffffffu;

/// The immutable part, shared by all runs: adjacency (real pairs of one region), rewards,
/// boundary nodes. Built once from the dual graph (extra pairs are ignored).
struct LookaheadGraph {
  std::uint32_t num_triangles = 0;
  std::size_t num_nodes = 0;
  std::vector<std::array<NodeIndex, 3>> triangles;
  /// #triangles × 3: the triangle across edge k (corners k, k+1) in the same region, or kNone.
  std::vector<std::array<std::uint32_t, 3>> neighbor;
  /// #triangles × 3: the real pair across edge k (index into pairs), or kNone.
  std::vector<std::array<std::uint32_t, 3>> pair_at;
  std::vector<TrianglePair> pairs;    ///< the real pairs of the dual graph
  std::vector<double> reward;         ///< #pairs: 1 - cost, i.e. eta(Q) for the angle cost
  std::vector<char> boundary_node;    ///< on an edge with no free neighbour from the start
  /// Union-find seed: each node's representative after uniting the ends of boundary edges.
  std::vector<NodeIndex> initial_parent;
  /// CSR: the triangles at each node.
  std::vector<std::uint32_t> node_offsets, node_triangles;
  /// Every dual component is a genus-0 manifold surface: the separation rule (b) holds.
  bool planar_rule = true;
};

/// @pre g built by build_dual_graph on `triangles` (extra pairs allowed, ignored).
LookaheadGraph build_lookahead_graph(const DualGraph& g,
                                     std::span<const std::array<NodeIndex, 3>> triangles,
                                     std::size_t num_nodes);

/// The quad corners (a, d, b, c) of pair p, as quad_of_pair.
std::array<NodeIndex, 4> lookahead_quad(const LookaheadGraph& g, std::uint32_t p);

class LookaheadState {
 public:
  explicit LookaheadState(const LookaheadGraph& g);

  const LookaheadGraph& graph() const noexcept { return *g_; }
  bool is_free(std::uint32_t t) const noexcept { return free_[t] != 0; }
  /// Both triangles of pair p are free.
  bool available(std::uint32_t p) const noexcept {
    return free_[g_->pairs[p].t0] && free_[g_->pairs[p].t1];
  }
  /// Definition 2: p is available and merging it leaves no odd polder set.
  bool allowed(std::uint32_t p);
  /// Allowed pairs at triangle t (0..3), written to out (if not null) in edge order.
  int allowed_options(std::uint32_t t, std::array<std::uint32_t, 3>* out = nullptr);
  /// Free neighbours of t (an upper bound of allowed_options).
  int free_neighbors(std::uint32_t t) const noexcept;

  /// Merges pair p (must be available). Undo with undo(), last in first out.
  void apply(std::uint32_t p);
  void undo();
  /// Makes every merge applied so far permanent (no longer undoable), so that the
  /// union-find may compress their paths: called on the committed state of a run, it keeps
  /// the finds short (the complement component grows to the size of the mesh).
  void settle();

  double quality() const noexcept { return quality_; }
  std::size_t quads() const noexcept { return applied_.size(); }
  const std::vector<std::uint32_t>& applied() const noexcept { return applied_; }
  /// Triangles visited by the breadth-first searches of (c) so far (for benchmarks).
  std::uint64_t search_steps() const noexcept { return search_steps_; }

 private:
  NodeIndex find(NodeIndex v) noexcept;
  void unite(NodeIndex a, NodeIndex b);
  bool closed_corner(NodeIndex v) const noexcept {
    return g_->boundary_node[v] || quads_at_[v] > 0;
  }
  // (c): true when some part of C \ {t0, t1} is odd. seeds[i]: a triangle of arc i;
  // group[i]: a label shared by the arcs that (b) proved connected, or i.
  bool odd_part(const std::array<std::uint32_t, 4>& seeds, std::array<int, 4> group, int arcs,
                std::uint32_t t0, std::uint32_t t1);

  const LookaheadGraph* g_;
  std::vector<char> free_;
  std::vector<std::uint16_t> quads_at_;
  // Union-find by size. Links made by settled merges are compressed on find; links made
  // since (tentative_[child] set) are not, so that undo can cut them.
  std::vector<NodeIndex> parent_;
  std::vector<std::uint32_t> size_;
  std::vector<char> tentative_;
  std::vector<NodeIndex> union_log_;       // tentative children, per apply in unions_per_apply_
  std::vector<std::uint8_t> unions_per_apply_;
  std::size_t settled_ = 0;                // applied_[0, settled_) cannot be undone
  std::vector<std::uint32_t> applied_;
  double quality_ = 0.0;
  // Search scratch: stamp_[t] == epoch_ marks t as seen, owner_[t] the search that saw it.
  std::vector<std::uint32_t> stamp_;
  std::vector<std::uint8_t> owner_;
  std::uint32_t epoch_ = 0;
  std::vector<std::uint32_t> queue_[4];
  std::uint64_t search_steps_ = 0;
};

}  // namespace quadval::recombine_detail
