#include "surface_projection.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

namespace {

constexpr std::uint32_t kNoHost = 0xffffffffu;

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
std::array<double, 3> minus(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

}  // namespace

SurfaceProjection::SurfaceProjection(const TriangleSurface& s)
    : coords_(s.coords), triangles_(s.triangles), region_(s.region) {
  std::optional<TriangleTopology> built;
  const TriangleTopology& topo = topology_of(s, built);
  neighbors_ = topo.neighbors;
  const std::size_t nodes = s.node_tags.size();
  node_first_.assign(nodes + 1, 0);
  for (const auto& t : triangles_)
    for (NodeIndex v : t) ++node_first_[v + 1];
  for (std::size_t v = 0; v < nodes; ++v) node_first_[v + 1] += node_first_[v];
  node_triangles_.resize(node_first_[nodes]);
  std::vector<std::uint32_t> next(node_first_.begin(), node_first_.end() - 1);
  host_.assign(nodes, kNoHost);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t)
    for (NodeIndex v : triangles_[t]) {
      node_triangles_[next[v]++] = t;
      if (host_[v] == kNoHost) host_[v] = t;
    }
  // Vertex normals per region: the area-weighted mean of the normals of the region's
  // triangles at the vertex.
  std::vector<std::array<double, 3>> area_normal(triangles_.size());
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) area_normal[t] = triangle_normal(coords_, triangles_[t]);
  corner_normal_.resize(3 * triangles_.size());
  for (std::uint32_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const NodeIndex v = triangles_[t][k];
      std::array<double, 3> n{0, 0, 0};
      for (std::uint32_t i = node_first_[v]; i < node_first_[v + 1]; ++i) {
        const std::uint32_t u = node_triangles_[i];
        if (region_[u] != region_[t]) continue;
        for (int d = 0; d < 3; ++d) n[d] += area_normal[u][d];
      }
      const double l = std::sqrt(dot(n, n));
      corner_normal_[3 * std::size_t{t} + k] = l > 0 ? std::array<double, 3>{n[0] / l, n[1] / l, n[2] / l} : n;
    }
}

// Phong tessellation's point over q (on triangle t, barycentric b): alpha = 3/4 of the way
// to the barycentric mean of q's projections on the corners' tangent planes.
std::array<double, 3> SurfaceProjection::lifted(std::uint32_t t, const std::array<double, 3>& q,
                                                const std::array<double, 3>& b) const {
  constexpr double kAlpha = 0.75;
  std::array<double, 3> phong{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const double* x = &coords_[3 * std::size_t{triangles_[t][k]}];
    const auto& n = corner_normal_[3 * std::size_t{t} + k];
    const double h = (q[0] - x[0]) * n[0] + (q[1] - x[1]) * n[1] + (q[2] - x[2]) * n[2];
    for (int d = 0; d < 3; ++d) phong[d] += b[k] * (q[d] - h * n[d]);
  }
  return {(1 - kAlpha) * q[0] + kAlpha * phong[0], (1 - kAlpha) * q[1] + kAlpha * phong[1],
          (1 - kAlpha) * q[2] + kAlpha * phong[2]};
}

void SurfaceProjection::reserve_nodes(std::size_t num_nodes) {
  if (host_.size() < num_nodes) host_.resize(num_nodes, kNoHost);
}

// The nearest point of triangle t to p, by the region of the triangle's plane that p's
// projection falls in (its corners, edges or inside).
SurfaceProjection::Nearest SurfaceProjection::nearest_on(std::uint32_t t, const std::array<double, 3>& p) const {
  const auto corner = [&](int k) {
    const double* x = &coords_[3 * std::size_t{triangles_[t][k]}];
    return std::array<double, 3>{x[0], x[1], x[2]};
  };
  const auto a = corner(0), b = corner(1), c = corner(2);
  const auto ab = minus(b, a), ac = minus(c, a), ap = minus(p, a);
  const auto at = [&](double u, double v, double w, int zeros) {
    Nearest n{{u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1], u * a[2] + v * b[2] + w * c[2]},
              0.0, zeros, {u, v, w}};
    const auto d = minus(p, n.point);
    n.distance2 = dot(d, d);
    return n;
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(1, 0, 0, 2);
  const auto bp = minus(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(0, 1, 0, 2);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return at(1 - v, v, 0, 1);
  }
  const auto cp = minus(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(0, 0, 1, 2);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return at(1 - w, 0, w, 1);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return at(0, 1 - w, w, 1);
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return at(1 - v - w, v, w, 0);
}

std::array<double, 3> SurfaceProjection::project(NodeIndex v, const std::array<double, 3>& p, NodeIndex near) {
  std::uint32_t t = v < host_.size() ? host_[v] : kNoHost;
  if (t == kNoHost && near < host_.size()) t = host_[near];
  if (t == kNoHost) return p;
  const std::int32_t region = region_[t];
  Nearest best = nearest_on(t, p);
  // Downhill over the region's triangles: from an edge to the triangle across it, from a
  // corner to those around it, while the distance falls.
  for (int step = 0; step < 64 && best.zeros > 0; ++step) {
    std::uint32_t next = kNoHost;
    Nearest found = best;
    const auto consider = [&](std::uint32_t u) {
      if (u == kNoHost || u == t || region_[u] != region) return;
      const Nearest n = nearest_on(u, p);
      if (n.distance2 < found.distance2) {
        found = n;
        next = u;
      }
    };
    if (best.zeros == 1) {
      const int zero = best.bary[0] == 0 ? 0 : best.bary[1] == 0 ? 1 : 2;
      consider(neighbors_[t][(zero + 1) % 3]);  // edge k joins corners k and k + 1
    } else {
      const int one = best.bary[0] == 1 ? 0 : best.bary[1] == 1 ? 1 : 2;
      const NodeIndex corner = triangles_[t][one];
      for (std::uint32_t i = node_first_[corner]; i < node_first_[corner + 1]; ++i) consider(node_triangles_[i]);
    }
    if (next == kNoHost) break;
    t = next;
    best = found;
  }
  if (v < host_.size()) host_[v] = t;
  const auto on = lifted(t, best.point, best.bary);
  // A point already on the surface (a move within a flat face) is kept to the bit, not
  // replaced by its own image rounded: the smoothing of flat faces stays as it was.
  double scale2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double* a = &coords_[3 * std::size_t{triangles_[t][k]}];
    const double* b = &coords_[3 * std::size_t{triangles_[t][(k + 1) % 3]}];
    scale2 = std::max(scale2, (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  }
  const auto d = minus(on, p);
  return dot(d, d) <= 1e-24 * scale2 ? p : on;
}

}  // namespace quadval::recombine_detail
