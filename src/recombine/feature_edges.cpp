#include "feature_edges.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

std::size_t split_regions_at_features(TriangleSurface& s, double angle_degrees) {
  if (s.planar || !(angle_degrees < 180.0)) return 0;
  std::optional<TriangleTopology> built;
  const TriangleTopology& topo = topology_of(s, built);
  const std::size_t n = s.triangles.size();
  std::vector<std::array<double, 3>> normal(n);
  std::vector<double> length(n);
  for (std::size_t t = 0; t < n; ++t) {
    normal[t] = triangle_normal(s.coords, s.triangles[t]);
    const auto& v = normal[t];
    length[t] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  const double cos_limit = std::cos(angle_degrees * std::numbers::pi / 180.0);
  // A feature when the normals turn by more than the angle (cos below its cosine).
  const auto is_feature = [&](std::uint32_t t, std::uint32_t u) {
    const auto& a = normal[t];
    const auto& b = normal[u];
    const double scale = length[t] * length[u];
    return scale > 0 && a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < cos_limit * scale;
  };

  // Pieces: triangles of one region joined across edges that are not features.
  std::vector<std::uint32_t> piece(n, kNoTriangle), size;
  std::vector<std::uint32_t> stack;
  for (std::uint32_t start = 0; start < n; ++start) {
    if (piece[start] != kNoTriangle) continue;
    const auto id = static_cast<std::uint32_t>(size.size());
    size.push_back(1);
    piece[start] = id;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (std::uint32_t u : topo.neighbors[t])
        if (u != kNoTriangle && piece[u] == kNoTriangle && s.region[u] == s.region[t] && !is_feature(t, u)) {
          piece[u] = id;
          ++size[id];
          stack.push_back(u);
        }
    }
  }
  // A piece of one triangle could only become a quad folded over a feature or by a split
  // into halves that may not pair: it joins the neighbour across its least sharp edge (a
  // tetrahedron's four faces give two folded quads, as without features).
  std::vector<std::uint32_t> root(size.size());
  for (std::uint32_t p = 0; p < root.size(); ++p) root[p] = p;
  const auto find = [&](std::uint32_t p) {
    while (root[p] != p) p = root[p] = root[root[p]];
    return p;
  };
  std::vector<char> joined(n, 0);
  for (std::uint32_t t = 0; t < n; ++t) {
    if (size[piece[t]] != 1) continue;
    std::uint32_t best = kNoTriangle;
    double best_cos = -2;
    for (std::uint32_t u : topo.neighbors[t]) {
      if (u == kNoTriangle || s.region[u] != s.region[t] || !(length[t] * length[u] > 0)) continue;
      const double c = (normal[t][0] * normal[u][0] + normal[t][1] * normal[u][1] + normal[t][2] * normal[u][2]) /
                       (length[t] * length[u]);
      if (c > best_cos) {
        best_cos = c;
        best = u;
      }
    }
    if (best == kNoTriangle) continue;
    joined[t] = 1;
    root[find(piece[t])] = find(piece[best]);
  }
  // Regions: the joined pieces, numbered in the order of their first triangle.
  std::vector<std::int32_t> region(n);
  std::vector<std::int32_t> number(size.size(), -1);
  std::vector<int> entity;
  for (std::uint32_t t = 0; t < n; ++t) {
    const std::uint32_t p = find(piece[t]);
    if (number[p] < 0) {
      number[p] = static_cast<std::int32_t>(entity.size());
      entity.push_back(s.region_entity[static_cast<std::size_t>(s.region[t])]);
    }
    region[t] = number[p];
  }
  // Features: the edges of one input region between two of the new ones, and those that
  // turn too much inside a new one (a crease that does not cut the surface in two, other
  // than a joined triangle's), which still bound no quad: their triangles are a forbidden
  // pair.
  std::size_t features = 0;
  std::vector<std::array<std::uint32_t, 2>> creases;
  for (std::uint32_t t = 0; t < n; ++t)
    for (std::uint32_t u : topo.neighbors[t]) {
      if (u == kNoTriangle || t > u || s.region[u] != s.region[t]) continue;
      if (region[t] != region[u]) {
        ++features;
      } else if (!joined[t] && !joined[u] && is_feature(t, u)) {
        ++features;
        creases.push_back({t, u});
      }
    }
  if (features == 0) return 0;
  s.forbidden_pairs.insert(s.forbidden_pairs.end(), creases.begin(), creases.end());
  s.region = std::move(region);
  s.region_entity = std::move(entity);
  return features;
}

}  // namespace quadval::recombine_detail
