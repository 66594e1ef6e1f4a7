#pragma once
// Checks of a recombined mesh against its input, computed from scratch in the test.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "quadval/mesh.hpp"

namespace quadval::test {

inline double shoelace_area(const Mesh& m, std::span<const NodeIndex> nodes) {
  double a = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto p = m.node(nodes[k]), q = m.node(nodes[(k + 1) % nodes.size()]);
    a += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * a;
}

using TagEdge = std::pair<Tag, Tag>;

// Directed edges (by node tags) of every element of dimension 2, with their count.
inline std::map<TagEdge, int> directed_edges(const Mesh& m) {
  std::map<TagEdge, int> edges;
  for (const ElementBlock& b : m.blocks) {
    if (b.type->dim != 2) continue;
    const int k = b.type->family == ElementFamily::quadrangle ? 4 : 3;
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto n = b.element(e);
      for (int i = 0; i < k; ++i) ++edges[{m.node_tags[n[i]], m.node_tags[n[(i + 1) % k]]}];
    }
  }
  return edges;
}

// Boundary edges as undirected node-tag pairs: edges used once.
inline std::set<TagEdge> boundary_edges(const Mesh& m) {
  std::map<TagEdge, int> undirected;
  for (const auto& [e, c] : directed_edges(m))
    undirected[{std::min(e.first, e.second), std::max(e.first, e.second)}] += c;
  std::set<TagEdge> out;
  for (const auto& [e, c] : undirected)
    if (c == 1) out.insert(e);
  return out;
}

struct QuadMeshSummary {
  std::size_t quads = 0, triangles = 0;
};

/// Asserts: the output is conforming and manifold with one orientation (each directed edge at
/// most once, each undirected edge in at most two elements); its boundary edges and their
/// nodes lie on the input's boundary (they may slide along straight sides); for planar meshes every element has positive
/// area and the areas sum to the input's.
inline QuadMeshSummary expect_valid_recombination(const Mesh& input, const Mesh& output,
                                                  bool planar = true) {
  QuadMeshSummary s;
  for (const ElementBlock& b : output.blocks) {
    if (b.type->family == ElementFamily::quadrangle) s.quads += b.size();
    if (b.type->family == ElementFamily::triangle) s.triangles += b.size();
  }
  for (const auto& [e, count] : directed_edges(output)) {
    EXPECT_EQ(count, 1) << "directed edge " << e.first << "->" << e.second
                        << " used twice: overlap or inconsistent orientation";
    EXPECT_NE(e.first, e.second) << "collapsed edge at node " << e.first;
  }
  // Same boundary (by node tags), same boundary node positions.
  EXPECT_EQ(boundary_edges(input), boundary_edges(output));
  std::map<Tag, std::array<double, 3>> in_pos, out_pos;
  for (std::size_t i = 0; i < input.num_nodes(); ++i) in_pos[input.node_tags[i]] = input.node(static_cast<NodeIndex>(i));
  for (std::size_t i = 0; i < output.num_nodes(); ++i) out_pos[output.node_tags[i]] = output.node(static_cast<NodeIndex>(i));
  // A boundary node stays where it was or slides along a straight side: it lies on the
  // input's boundary polyline (with the same boundary edges and, below, the same area, the
  // boundary keeps its shape).
  const auto in_boundary = boundary_edges(input);
  auto distance_to_input_boundary = [&](const std::array<double, 3>& x) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [ta, tb] : in_boundary) {
      const auto &a = in_pos[ta], &b = in_pos[tb];
      double ab2 = 0, t = 0;
      for (int d = 0; d < 3; ++d) {
        ab2 += (b[d] - a[d]) * (b[d] - a[d]);
        t += (x[d] - a[d]) * (b[d] - a[d]);
      }
      t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
      double d2 = 0;
      for (int d = 0; d < 3; ++d) d2 += std::pow(x[d] - (a[d] + t * (b[d] - a[d])), 2);
      best = std::min(best, std::sqrt(d2));
    }
    return best;
  };
  for (const auto& e : in_boundary)
    for (Tag t : {e.first, e.second}) {
      EXPECT_TRUE(out_pos.count(t)) << "boundary node " << t << " lost";
      if (!out_pos.count(t) || out_pos[t] == in_pos[t]) continue;
      const double scale = std::sqrt(std::pow(in_pos[t][0], 2) + std::pow(in_pos[t][1], 2) +
                                     std::pow(in_pos[t][2], 2)) + 1.0;
      EXPECT_LE(distance_to_input_boundary(out_pos[t]), 1e-12 * scale)
          << "boundary node " << t << " left the boundary";
    }
  if (planar) {
    double in_area = 0, out_area = 0;
    for (const ElementBlock& b : input.blocks)
      if (b.type->dim == 2)
        for (std::size_t e = 0; e < b.size(); ++e) in_area += shoelace_area(input, b.element(e));
    for (const ElementBlock& b : output.blocks)
      if (b.type->dim == 2)
        for (std::size_t e = 0; e < b.size(); ++e) {
          const double a = shoelace_area(output, b.element(e));
          EXPECT_GT(a * (in_area > 0 ? 1 : -1), 0.0) << "element " << b.tags[e] << " inverted";
          out_area += a;
        }
    EXPECT_NEAR(out_area, in_area, 1e-9 * std::abs(in_area));
  }
  return s;
}

}  // namespace quadval::test
