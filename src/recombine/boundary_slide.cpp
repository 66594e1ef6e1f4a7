#include "boundary_slide.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace quadval::recombine_detail {

std::vector<std::array<NodeIndex, 2>> straight_boundary_slides(const MixedMesh& m,
                                                                const std::vector<char>& boundary) {
  // Region-boundary edges: (low, high, region) seen once.
  std::vector<std::tuple<NodeIndex, NodeIndex, std::int32_t>> edges;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    const int k = MixedMesh::size(el);
    for (int i = 0; i < k; ++i) {
      const NodeIndex a = el[i], b = el[(i + 1) % k];
      if (boundary[a] && boundary[b]) edges.emplace_back(std::min(a, b), std::max(a, b), m.region[e]);
    }
  }
  std::sort(edges.begin(), edges.end());
  // Per node: its distinct boundary neighbours, up to 3 (3 means "more than two").
  std::vector<std::array<NodeIndex, 3>> nbr(m.num_nodes(), {kNoNode, kNoNode, kNoNode});
  auto add = [&](NodeIndex v, NodeIndex w) {
    auto& list = nbr[v];
    for (NodeIndex& x : list) {
      if (x == w) return;
      if (x == kNoNode) {
        x = w;
        return;
      }
    }
  };
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {  // one element of its region holds it: a boundary edge
      add(std::get<0>(edges[i]), std::get<1>(edges[i]));
      add(std::get<1>(edges[i]), std::get<0>(edges[i]));
    }
    i = j;
  }
  std::vector<std::array<NodeIndex, 2>> slide(m.num_nodes(), {kNoNode, kNoNode});
  for (NodeIndex v = 0; v < m.num_nodes(); ++v) {
    const auto& list = nbr[v];
    if (list[1] == kNoNode || list[2] != kNoNode) continue;  // not exactly two
    const auto x = m.point(v), a = m.point(list[0]), b = m.point(list[1]);
    const double p[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
    const double q[3] = {b[0] - x[0], b[1] - x[1], b[2] - x[2]};
    const double c[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2],
                         p[0] * q[1] - p[1] * q[0]};
    const double lp = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    const double lq = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    const double cross = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const double dot = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    if (lp > 0 && lq > 0 && dot > 0 && cross <= 1e-12 * lp * lq) slide[v] = {list[0], list[1]};
  }
  return slide;
}

}  // namespace quadval::recombine_detail
