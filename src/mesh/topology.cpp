#include "quadval/topology.hpp"

#include <algorithm>
#include <utility>

#include "quadval/error.hpp"

namespace quadval {

namespace {

// Half-edge record: the edge's larger node and where it came from (triangle * 3 + k).
struct HalfEdge {
  NodeIndex high;
  std::uint32_t corner;
};

// Chains the boundary edges into loops by walking node to node (undirected).
void walk_boundary_loops(TriangleTopology& topo) {
  const std::size_t n = topo.num_nodes;
  std::vector<std::uint32_t> offsets(n + 1, 0);
  for (std::uint32_t e : topo.boundary_edges) {
    ++offsets[topo.edges[e][0] + 1];
    ++offsets[topo.edges[e][1] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  std::vector<std::uint32_t> incident(offsets[n]);
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::uint32_t e : topo.boundary_edges) {
    incident[fill[topo.edges[e][0]]++] = e;
    incident[fill[topo.edges[e][1]]++] = e;
  }
  std::vector<char> used(topo.edges.size(), 0);
  auto next_unused = [&](NodeIndex v) -> std::uint32_t {
    for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i)
      if (!used[incident[i]]) return incident[i];
    return kNoTriangle;
  };
  for (std::uint32_t start_edge : topo.boundary_edges) {
    if (used[start_edge]) continue;
    const NodeIndex start = topo.edges[start_edge][0];
    std::vector<NodeIndex> chain{start};
    NodeIndex at = start;
    std::uint32_t e = start_edge;
    bool closed = false;
    while (e != kNoTriangle) {
      used[e] = 1;
      at = topo.edges[e][0] == at ? topo.edges[e][1] : topo.edges[e][0];
      if (at == start) {
        closed = true;
        break;
      }
      chain.push_back(at);
      e = next_unused(at);
    }
    (closed ? topo.boundary_loops : topo.open_boundary_chains).push_back(std::move(chain));
  }
}

}  // namespace

TriangleTopology build_triangle_topology(std::span<const std::array<NodeIndex, 3>> triangles,
                                         std::size_t num_nodes) {
  TriangleTopology topo;
  topo.num_nodes = num_nodes;
  topo.triangles.assign(triangles.begin(), triangles.end());
  const std::size_t nt = triangles.size();
  QV_ASSERT(nt < kNoTriangle / 3, nt << " triangles");

  // Bucket the 3 nt half-edges by their smaller node (counting sort), then sort each small
  // bucket by the larger node: linear time overall.
  std::vector<std::uint32_t> offsets(num_nodes + 1, 0);
  topo.vertex_triangles.assign(num_nodes, 0);
  std::vector<char> collapsed(nt, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& v = triangles[t];
    for (int k = 0; k < 3; ++k)
      QV_ASSERT(v[k] < num_nodes, "triangle " << t << " node " << v[k] << " >= " << num_nodes);
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
      collapsed[t] = 1;
      topo.collapsed_triangles.push_back(static_cast<std::uint32_t>(t));
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      QV_ASSERT(v[k] < num_nodes, "triangle " << t << " node " << v[k] << " >= " << num_nodes);
      ++offsets[std::min(v[k], v[(k + 1) % 3]) + 1];
      ++topo.vertex_triangles[v[k]];
    }
  }
  for (std::size_t i = 0; i < num_nodes; ++i) offsets[i + 1] += offsets[i];
  std::vector<HalfEdge> half(offsets[num_nodes]);
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < nt; ++t) {
      if (collapsed[t]) continue;
      const auto& v = triangles[t];
      for (int k = 0; k < 3; ++k) {
        const NodeIndex a = v[k], b = v[(k + 1) % 3];
        half[fill[std::min(a, b)]++] = {std::max(a, b), static_cast<std::uint32_t>(3 * t + k)};
      }
    }
  }
  topo.triangle_edges.assign(nt, {kNoTriangle, kNoTriangle, kNoTriangle});
  topo.neighbors.assign(nt, {kNoTriangle, kNoTriangle, kNoTriangle});
  topo.edges.reserve(3 * nt / 2 + 16);
  topo.edge_triangle_offsets.reserve(3 * nt / 2 + 17);
  topo.edge_triangles.reserve(3 * nt);
  topo.edge_triangle_offsets.push_back(0);
  topo.vertex_valence.assign(num_nodes, 0);
  for (NodeIndex low = 0; low < num_nodes; ++low) {
    auto first = half.begin() + offsets[low], last = half.begin() + offsets[low + 1];
    std::sort(first, last, [](const HalfEdge& x, const HalfEdge& y) {
      return x.high != y.high ? x.high < y.high : x.corner < y.corner;
    });
    for (auto it = first; it != last;) {
      auto run_end = it;
      while (run_end != last && run_end->high == it->high) ++run_end;
      const auto e = static_cast<std::uint32_t>(topo.edges.size());
      topo.edges.push_back({low, it->high});
      ++topo.vertex_valence[low];
      ++topo.vertex_valence[it->high];
      for (auto h = it; h != run_end; ++h) {
        topo.triangle_edges[h->corner / 3][h->corner % 3] = e;
        topo.edge_triangles.push_back(h->corner / 3);
      }
      const auto count = static_cast<std::size_t>(run_end - it);
      if (count == 1) topo.boundary_edges.push_back(e);
      if (count > 2) topo.nonmanifold_edges.push_back(e);
      if (count == 2) {
        const std::uint32_t c0 = it->corner, c1 = (it + 1)->corner;
        topo.neighbors[c0 / 3][c0 % 3] = c1 / 3;
        topo.neighbors[c1 / 3][c1 % 3] = c0 / 3;
        // Consistent orientation: the two triangles run the shared edge in opposite ways.
        const NodeIndex from0 = triangles[c0 / 3][c0 % 3], from1 = triangles[c1 / 3][c1 % 3];
        if (from0 == from1) ++topo.num_misoriented_edges;
      }
      topo.edge_triangle_offsets.push_back(static_cast<std::uint32_t>(topo.edge_triangles.size()));
      it = run_end;
    }
  }
  walk_boundary_loops(topo);
  return topo;
}

std::vector<std::array<NodeIndex, 3>> triangle_corners(const Mesh& mesh) {
  std::vector<std::array<NodeIndex, 3>> tris;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type == nullptr || b.type->family != ElementFamily::triangle) continue;
    tris.reserve(tris.size() + b.size());
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto nodes = b.element(e);
      tris.push_back({nodes[0], nodes[1], nodes[2]});
    }
  }
  return tris;
}

TriangleTopology build_triangle_topology(const Mesh& mesh) {
  const auto tris = triangle_corners(mesh);
  return build_triangle_topology(tris, mesh.num_nodes());
}

}  // namespace quadval
