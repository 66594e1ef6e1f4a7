#include "mixed_mesh.hpp"

#include <algorithm>
#include <cmath>

#include "quadval/error.hpp"
#include "smoothing.hpp"

namespace quadval::recombine_detail {

double element_score(const MixedMesh& m, const std::array<NodeIndex, 4>& element,
                     const std::array<double, 3>& normal) noexcept {
  const double nn = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  // A quad: quad_eta's eta where it is positive, else min(quad_min_corner_sine, 0), by
  // smoothing_score, which gives those values to the bit with 4 square roots instead of up to
  // 17 (1M triangles, the serial polish and swap stages: see smoothing.hpp).
  if (element[3] != kNoNode) return smoothing_score(m.coords, element, normal, nn);
  double worst = 1.0;
  for (int k = 0; k < 3; ++k) {
    const auto a = m.point(element[k]), b = m.point(element[(k + 1) % 3]),
               c = m.point(element[(k + 2) % 3]);
    const double f[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double g[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double cr[3] = {f[1] * g[2] - f[2] * g[1], f[2] * g[0] - f[0] * g[2],
                          f[0] * g[1] - f[1] * g[0]};
    const double scale = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) *
                         std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) * nn;
    if (scale == 0.0) return -1.0;
    worst = std::min(worst, (cr[0] * normal[0] + cr[1] * normal[1] + cr[2] * normal[2]) / scale);
  }
  return worst / (std::sqrt(3.0) / 2.0);
}

std::vector<char> region_boundary_nodes(const MixedMesh& m) {
  // Bucket the edges by their smaller node, then count (larger node, region) in each bucket.
  const std::size_t n = m.num_nodes();
  std::vector<std::uint32_t> offsets(n + 1, 0);
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    const int k = MixedMesh::size(el);
    for (int i = 0; i < k; ++i) ++offsets[std::min(el[i], el[(i + 1) % k]) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  struct Key {
    NodeIndex high;
    std::int32_t region;
  };
  std::vector<Key> keys(offsets[n]);
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    const int k = MixedMesh::size(el);
    for (int i = 0; i < k; ++i) {
      const NodeIndex a = el[i], b = el[(i + 1) % k];
      keys[fill[std::min(a, b)]++] = {std::max(a, b), m.region[e]};
    }
  }
  std::vector<char> boundary(n, 0);
  for (NodeIndex low = 0; low < n; ++low) {
    auto first = keys.begin() + offsets[low], last = keys.begin() + offsets[low + 1];
    std::sort(first, last, [](const Key& x, const Key& y) {
      return x.high != y.high ? x.high < y.high : x.region < y.region;
    });
    for (auto it = first; it != last;) {
      auto run = it;
      while (run != last && run->high == it->high && run->region == it->region) ++run;
      if (run - it == 1) boundary[low] = boundary[it->high] = 1;
      it = run;
    }
  }
  return boundary;
}

std::vector<std::vector<std::uint32_t>> node_elements(const MixedMesh& m) {
  // Counted first, so that each list is allocated once (growing them one push at a time took
  // three or four allocations per node).
  std::vector<std::uint32_t> count(m.num_nodes(), 0);
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e])
      for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i) ++count[m.elements[e][i]];
  std::vector<std::vector<std::uint32_t>> at(m.num_nodes());
  for (std::size_t v = 0; v < at.size(); ++v) at[v].reserve(count[v]);
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    for (int i = 0; i < MixedMesh::size(el); ++i) at[el[i]].push_back(static_cast<std::uint32_t>(e));
  }
  return at;
}

int corner_of(const std::array<NodeIndex, 4>& e, NodeIndex v) {
  for (int i = 0; i < MixedMesh::size(e); ++i)
    if (e[i] == v) return i;
  QV_ASSERT(false, "node " << v << " is not a corner of the element");
  return -1;
}

}  // namespace quadval::recombine_detail
