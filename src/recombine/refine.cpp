#include "refine.hpp"

#include <unordered_map>

namespace quadval::recombine_detail {

MixedMesh refine_to_quads(const MixedMesh& m, Tag& next_tag) {
  MixedMesh r;
  r.coords = m.coords;
  r.node_tags = m.node_tags;
  std::unordered_map<std::uint64_t, NodeIndex> midpoint;
  midpoint.reserve(2 * m.elements.size());
  auto mid = [&](NodeIndex a, NodeIndex b) {
    const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
    auto [it, inserted] = midpoint.emplace(key, kNoNode);
    if (inserted) {
      const auto xa = m.point(a), xb = m.point(b);
      it->second = r.add_node({0.5 * (xa[0] + xb[0]), 0.5 * (xa[1] + xb[1]), 0.5 * (xa[2] + xb[2])},
                              next_tag++);
    }
    return it->second;
  };
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    const int k = MixedMesh::size(el);
    std::array<double, 3> c{0, 0, 0};
    for (int i = 0; i < k; ++i) {
      const auto x = m.point(el[i]);
      for (int d = 0; d < 3; ++d) c[d] += x[d] / k;
    }
    std::array<NodeIndex, 4> mids{};
    for (int i = 0; i < k; ++i) mids[i] = mid(el[i], el[(i + 1) % k]);
    const NodeIndex o = r.add_node(c, next_tag++);
    // Corner i keeps the sub-quad (corner, mid of edge i, centroid, mid of edge i-1).
    for (int i = 0; i < k; ++i) {
      r.elements.push_back({el[i], mids[i], o, mids[(i + k - 1) % k]});
      r.region.push_back(m.region[e]);
      r.normal.push_back(m.normal[e]);
      r.alive.push_back(1);
    }
  }
  return r;
}

}  // namespace quadval::recombine_detail
