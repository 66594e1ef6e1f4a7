#include "lookahead_parity.hpp"

#include <algorithm>
#include <optional>

#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

void make_pieces_even(TriangleSurface& s) {
  std::optional<TriangleTopology> built;
  const TriangleTopology& topo = topology_of(s, built);
  const auto n = static_cast<std::uint32_t>(s.triangles.size());
  // Pieces: components over edges shared by two triangles of the same region.
  std::vector<std::int32_t> piece(n, -1);
  std::vector<std::int32_t> piece_region;
  std::vector<std::uint32_t> stack;
  for (std::uint32_t start = 0; start < n; ++start) {
    if (piece[start] >= 0) continue;
    const auto id = static_cast<std::int32_t>(piece_region.size());
    piece_region.push_back(s.region[start]);
    piece[start] = id;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (std::uint32_t u : topo.neighbors[t])
        if (u != kNoTriangle && piece[u] < 0 && s.region[u] == s.region[t]) {
          piece[u] = id;
          stack.push_back(u);
        }
    }
  }
  if (piece_region.size() == s.region_entity.size()) {  // one piece per region
    make_regions_even(s);
    return;
  }
  // Run make_regions_even with the pieces as regions, then map back.
  std::vector<std::int32_t> region = std::move(s.region);
  std::vector<int> region_entity = std::move(s.region_entity);
  s.region = std::move(piece);
  s.region_entity.resize(piece_region.size());
  for (std::size_t p = 0; p < piece_region.size(); ++p)
    s.region_entity[p] = region_entity[static_cast<std::size_t>(piece_region[p])];
  const std::size_t left_before = s.odd_regions_left.size();
  make_regions_even(s);
  for (std::size_t t = region.size(); t < s.region.size(); ++t)  // split halves
    region.push_back(piece_region[static_cast<std::size_t>(s.region[t])]);
  for (std::size_t i = left_before; i < s.odd_regions_left.size(); ++i)
    s.odd_regions_left[i] = piece_region[static_cast<std::size_t>(s.odd_regions_left[i])];
  std::sort(s.odd_regions_left.begin() + static_cast<std::ptrdiff_t>(left_before),
            s.odd_regions_left.end());
  s.odd_regions_left.erase(
      std::unique(s.odd_regions_left.begin() + static_cast<std::ptrdiff_t>(left_before),
                  s.odd_regions_left.end()),
      s.odd_regions_left.end());
  s.region = std::move(region);
  s.region_entity = std::move(region_entity);
}

}  // namespace quadval::recombine_detail
