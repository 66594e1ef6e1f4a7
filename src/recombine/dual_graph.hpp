#pragma once
// The weighted dual graph of Paper I §4.2: one vertex per triangle, one edge (a "pair") per
// interior mesh edge whose two triangles lie in the same region, with the cost of the quad
// they would form; plus the extra boundary edges of §5.3. Reused by the look-ahead tree.

#include <array>
#include <cstdint>
#include <vector>

#include "quadval/mesh.hpp"
#include "quadval/recombine.hpp"
#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

enum class PairKind : std::uint8_t {
  real,   ///< the triangles share a mesh edge; merging them gives a quad
  extra,  ///< §5.3: triangles on successive boundary edges, sharing one boundary node only
};

struct TrianglePair {
  std::uint32_t t0, t1;  ///< t0 < t1
  double cost;           ///< 1 - eta, eq. (7), or the extra-edge cost
  PairKind kind;
  /// real: the shared edge is t0's edge `t0_edge` (corners t0_edge, t0_edge+1);
  /// extra: the shared boundary node.
  std::uint8_t t0_edge;
  NodeIndex shared_node;
};

struct DualGraph {
  std::uint32_t num_triangles = 0;
  std::vector<TrianglePair> pairs;  ///< real pairs first, then extra pairs
  std::size_t num_real = 0;
  /// CSR: the pairs each triangle takes part in.
  std::vector<std::uint32_t> offsets, incident;
};

/// The costs and the quads of merged pairs.
/// quad_of_pair: (t0 = a b c with shared edge a-b, t1 with opposite node d) -> (a, d, b, c),
/// which keeps the triangles' orientation.
std::array<NodeIndex, 4> quad_of_pair(const std::array<NodeIndex, 3>& t0, int t0_edge,
                                      const std::array<NodeIndex, 3>& t1);

/// 1 - eta(q) of Paper I eq. (3)-(4) for the quad of two triangles, angles signed by the sum
/// of the triangles' unit normals (so a non-convex quad costs 1, the highest real cost).
double angle_cost(const std::vector<double>& coords, const std::array<NodeIndex, 4>& quad,
                  const std::array<double, 3>& normal);

/// Paper I eq. (7): (max(|e.t1|, |e.t2|) - sqrt2/2) / (1 - sqrt2/2) for the unit direction e
/// of the shared (removed) edge, cross field t1 = (cos a, sin a, 0) projected on the plane
/// normal to `normal`, t2 = n × t1. In [0, 1]: 1 when e is along the field.
double cross_field_cost(const std::array<double, 3>& edge, const std::array<double, 3>& normal,
                        double angle);

struct DualGraphInput {
  const std::vector<double>* coords;
  const std::vector<std::array<NodeIndex, 3>>* triangles;  ///< oriented consistently
  const std::vector<std::int32_t>* region;                  ///< pairs never cross regions
  std::size_t num_nodes;
  PairCostKind cost = PairCostKind::angle;
  /// Per triangle cross-field angle (cross_field cost); empty: cross_field_angle for all.
  const std::vector<double>* cross_field_per_triangle = nullptr;
  double cross_field_angle = 0.0;
  bool extra_edges = true;
  double extra_edge_cost = 1000.0;
  /// Triangle pairs (t0 < t1) never to merge (the halves of a split triangle).
  const std::vector<std::array<std::uint32_t, 2>>* forbidden_pairs = nullptr;
  /// The topology of `triangles`, or null: built here.
  const TriangleTopology* topology = nullptr;
};

/// Builds the graph. Extra pairs (§5.3) join the triangles t, t' of two successive boundary
/// edges at a boundary node v (boundary: one triangle of the region holds the edge) when
/// t != t', they are not already paired, and walking around v from t inside the region
/// reaches t' (v has one fan). Costs are computed in parallel.
DualGraph build_dual_graph(const DualGraphInput& in);

}  // namespace quadval::recombine_detail
