#include "dual_graph.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "quadval/error.hpp"
#include "quadval/quad_quality.hpp"
#include "quadval/topology.hpp"
#include "triangle_input.hpp"

namespace quadval::recombine_detail {

namespace {

using V3 = std::array<double, 3>;

V3 unit(const V3& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return n > 0 ? V3{v[0] / n, v[1] / n, v[2] / n} : V3{0, 0, 0};
}

V3 point(const std::vector<double>& x, NodeIndex i) {
  return {x[3 * std::size_t{i}], x[3 * std::size_t{i} + 1], x[3 * std::size_t{i} + 2]};
}

}  // namespace

std::array<NodeIndex, 4> quad_of_pair(const std::array<NodeIndex, 3>& t0, int t0_edge,
                                      const std::array<NodeIndex, 3>& t1) {
  const NodeIndex a = t0[t0_edge], b = t0[(t0_edge + 1) % 3], c = t0[(t0_edge + 2) % 3];
  NodeIndex d = t1[0];
  for (NodeIndex v : t1)
    if (v != a && v != b) d = v;
  return {a, d, b, c};
}

double angle_cost(const std::vector<double>& coords, const std::array<NodeIndex, 4>& quad,
                  const std::array<double, 3>& normal) {
  const QuadCorners x{point(coords, quad[0]), point(coords, quad[1]), point(coords, quad[2]),
                      point(coords, quad[3])};
  return 1.0 - quad_eta(x, normal).eta;
}

double cross_field_cost(const std::array<double, 3>& edge, const std::array<double, 3>& normal,
                        double angle) {
  const V3 n = unit(normal);
  const V3 e = unit(edge);
  V3 t1{std::cos(angle), std::sin(angle), 0.0};
  // Project the field direction on the tangent plane; if it is along the normal, use any
  // tangent (the cost is then arbitrary but bounded).
  const double along = t1[0] * n[0] + t1[1] * n[1] + t1[2] * n[2];
  t1 = unit({t1[0] - along * n[0], t1[1] - along * n[1], t1[2] - along * n[2]});
  if (t1[0] == 0 && t1[1] == 0 && t1[2] == 0) t1 = unit({n[1] - n[2], n[2] - n[0], n[0] - n[1]});
  const V3 t2{n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2],
              n[0] * t1[1] - n[1] * t1[0]};
  const double d1 = std::abs(e[0] * t1[0] + e[1] * t1[1] + e[2] * t1[2]);
  const double d2 = std::abs(e[0] * t2[0] + e[1] * t2[1] + e[2] * t2[2]);
  const double s = std::numbers::sqrt2 / 2;
  const double c = (std::max(d1, d2) - s) / (1.0 - s);
  return std::clamp(c, 0.0, 1.0);  // rounding only: max(|e.t1|,|e.t2|) is in [s, 1]
}

DualGraph build_dual_graph(const DualGraphInput& in) {
  const auto& coords = *in.coords;
  const auto& tris = *in.triangles;
  const auto& region = *in.region;
  std::optional<TriangleTopology> built;
  const TriangleTopology& topo =
      in.topology != nullptr ? *in.topology : built.emplace(build_triangle_topology(tris, in.num_nodes));
  DualGraph g;
  g.num_triangles = static_cast<std::uint32_t>(tris.size());
  g.pairs.reserve(3 * tris.size() / 2 + 16);
  std::vector<char> has_forbidden(tris.size(), 0);
  if (in.forbidden_pairs != nullptr)
    for (const auto& f : *in.forbidden_pairs) has_forbidden[std::min(f[0], f[1])] = 1;
  auto forbidden = [&](std::uint32_t t, std::uint32_t u) {
    if (!has_forbidden[t]) return false;
    for (const auto& f : *in.forbidden_pairs)
      if (std::min(f[0], f[1]) == t && std::max(f[0], f[1]) == u) return true;
    return false;
  };
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = topo.neighbors[t][k];
      if (u != kNoTriangle && t < u && region[t] == region[u] && !forbidden(t, u))
        g.pairs.push_back({t, u, 0.0, PairKind::real, static_cast<std::uint8_t>(k), 0});
    }
  g.num_real = g.pairs.size();

  const auto num_real = static_cast<std::ptrdiff_t>(g.num_real);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < num_real; ++i) {
    TrianglePair& p = g.pairs[static_cast<std::size_t>(i)];
    const V3 n0 = unit(triangle_normal(coords, tris[p.t0]));
    const V3 n1 = unit(triangle_normal(coords, tris[p.t1]));
    const V3 n{n0[0] + n1[0], n0[1] + n1[1], n0[2] + n1[2]};
    if (in.cost == PairCostKind::angle) {
      p.cost = angle_cost(coords, quad_of_pair(tris[p.t0], p.t0_edge, tris[p.t1]), n);
    } else {
      const NodeIndex a = tris[p.t0][p.t0_edge], b = tris[p.t0][(p.t0_edge + 1) % 3];
      const V3 xa = point(coords, a), xb = point(coords, b);
      // The field at the edge midpoint: the mean of the two triangles' angles when given
      // per triangle (the angle of a cross is defined modulo pi/2, so average the 4x angle).
      double angle = in.cross_field_angle;
      if (in.cross_field_per_triangle != nullptr && !in.cross_field_per_triangle->empty()) {
        const double a0 = (*in.cross_field_per_triangle)[p.t0];
        const double a1 = (*in.cross_field_per_triangle)[p.t1];
        angle = std::atan2(std::sin(4 * a0) + std::sin(4 * a1),
                           std::cos(4 * a0) + std::cos(4 * a1)) / 4;
      }
      p.cost = cross_field_cost({xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]}, n, angle);
    }
  }

  if (in.extra_edges) {
    // An edge is on the boundary of triangle t's region when no other triangle of that region
    // holds it.
    auto region_boundary = [&](std::uint32_t t, int k) {
      const std::uint32_t u = topo.neighbors[t][k];
      return u == kNoTriangle || region[u] != region[t];
    };
    auto adjacent_in_region = [&](std::uint32_t t, std::uint32_t u) {
      for (int k = 0; k < 3; ++k)
        if (topo.neighbors[t][k] == u && region[u] == region[t]) return true;
      return false;
    };
    for (std::uint32_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        if (!region_boundary(t, k)) continue;
        const std::uint32_t e = topo.triangle_edges[t][k];
        for (int end = 0; end < 2; ++end) {
          const NodeIndex v = tris[t][(k + end) % 3];
          // Walk around v away from edge e until the next boundary edge of the region.
          std::uint32_t cur = t;
          int came = k;
          std::size_t steps = 0;
          while (true) {
            // The other edge of `cur` at v: edges at corner i are i-1 and i.
            int corner = 0;
            while (tris[cur][corner] != v) ++corner;
            const int other = (came == corner) ? (corner + 2) % 3 : corner;
            if (region_boundary(cur, other)) {
              const std::uint32_t e2 = topo.triangle_edges[cur][other];
              if (e < e2 && cur != t && !adjacent_in_region(t, cur)) {
                g.pairs.push_back({std::min(t, cur), std::max(t, cur), in.extra_edge_cost,
                                   PairKind::extra, 0, v});
              }
              break;
            }
            const std::uint32_t next = topo.neighbors[cur][other];
            const std::uint32_t shared = topo.triangle_edges[cur][other];
            int next_came = 0;
            while (topo.triangle_edges[next][next_came] != shared) ++next_came;
            cur = next;
            came = next_came;
            QV_ASSERT(++steps <= tris.size(), "fan walk around node " << v << " does not end");
          }
        }
      }
  }

  g.offsets.assign(tris.size() + 1, 0);
  for (const TrianglePair& p : g.pairs) {
    ++g.offsets[p.t0 + 1];
    ++g.offsets[p.t1 + 1];
  }
  for (std::size_t i = 0; i < tris.size(); ++i) g.offsets[i + 1] += g.offsets[i];
  g.incident.resize(g.offsets.back());
  std::vector<std::uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (std::uint32_t i = 0; i < g.pairs.size(); ++i) {
    g.incident[fill[g.pairs[i].t0]++] = i;
    g.incident[fill[g.pairs[i].t1]++] = i;
  }
  return g;
}

}  // namespace quadval::recombine_detail
