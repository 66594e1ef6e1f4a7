#include "node_order.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

// The 21 low bits of x spread to every third bit.
std::uint64_t spread3(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

}  // namespace

void order_nodes_along_curve(TriangleSurface& s) {
  const std::size_t n = s.node_tags.size();
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    lo[d] = std::numeric_limits<double>::infinity();
    hi[d] = -lo[d];
  }
  for (std::size_t v = 0; v < n; ++v)
    for (int d = 0; d < 3; ++d) {
      const double x = s.coords[3 * v + d];
      if (!std::isfinite(x)) continue;
      lo[d] = std::min(lo[d], x);
      hi[d] = std::max(hi[d], x);
    }
  constexpr double kCells = (1 << 21) - 1;
  std::vector<std::uint64_t> key(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    std::uint64_t k = 0;
    for (int d = 0; d < 3; ++d) {
      const double x = s.coords[3 * v + d];
      const double extent = hi[d] - lo[d];
      if (!std::isfinite(x) || !(extent > 0)) continue;
      const double cell = std::clamp((x - lo[d]) / extent * kCells, 0.0, kCells);
      k |= spread3(static_cast<std::uint64_t>(cell)) << d;
    }
    key[v] = k;
  }
  std::vector<NodeIndex> order(n);
  std::iota(order.begin(), order.end(), NodeIndex{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](NodeIndex a, NodeIndex b) { return key[a] < key[b]; });
  std::vector<NodeIndex> new_index(n);
  std::vector<double> coords(3 * n);
  std::vector<Tag> tags(n);
  for (std::size_t i = 0; i < n; ++i) {
    const NodeIndex v = order[i];
    new_index[v] = static_cast<NodeIndex>(i);
    tags[i] = s.node_tags[v];
    for (int d = 0; d < 3; ++d) coords[3 * i + d] = s.coords[3 * std::size_t{v} + d];
  }
  s.coords = std::move(coords);
  s.node_tags = std::move(tags);
  for (auto& t : s.triangles)
    for (NodeIndex& v : t) v = new_index[v];
  s.topology.reset();  // of the old numbering
}

void order_triangles_along_curve(TriangleSurface& s) {
  QV_ASSERT(s.forbidden_pairs.empty(), "triangles reordered after parity splits");
  const std::size_t nt = s.triangles.size();
  // A counting sort by the smallest node (stable, linear).
  std::vector<std::uint32_t> first(s.node_tags.size() + 1, 0), order(nt);
  const auto lowest = [&](std::size_t t) {
    return std::min({s.triangles[t][0], s.triangles[t][1], s.triangles[t][2]});
  };
  for (std::size_t t = 0; t < nt; ++t) ++first[lowest(t) + 1];
  for (std::size_t v = 0; v + 1 < first.size(); ++v) first[v + 1] += first[v];
  for (std::size_t t = 0; t < nt; ++t) order[first[lowest(t)]++] = static_cast<std::uint32_t>(t);
  const auto permute = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(v.size());
    for (std::size_t i = 0; i < nt; ++i) out[i] = v[order[i]];
    v = std::move(out);
  };
  permute(s.triangles);
  permute(s.region);
  permute(s.triangle_tags);
  permute(s.input_index);
  s.topology.reset();  // of the old order
}

}  // namespace quadval::recombine_detail
