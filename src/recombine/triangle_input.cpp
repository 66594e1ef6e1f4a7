#include "triangle_input.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <fmt/core.h>

#include "quadval/error.hpp"
#include "quadval/topology.hpp"

namespace quadval::recombine_detail {

std::array<double, 3> triangle_normal(const std::vector<double>& coords,
                                      const std::array<NodeIndex, 3>& t) noexcept {
  const double* a = &coords[3 * std::size_t{t[0]}];
  const double* b = &coords[3 * std::size_t{t[1]}];
  const double* c = &coords[3 * std::size_t{t[2]}];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

namespace {

double squared_distance(const std::vector<double>& x, NodeIndex a, NodeIndex b) {
  double s = 0;
  for (int i = 0; i < 3; ++i) {
    const double d = x[3 * std::size_t{a} + i] - x[3 * std::size_t{b} + i];
    s += d * d;
  }
  return s;
}

// A new node at the midpoint of edge `ends`.
NodeIndex add_midpoint(TriangleSurface& s, const std::array<NodeIndex, 2>& ends, Tag& next_tag) {
  const auto m = static_cast<NodeIndex>(s.node_tags.size());
  for (int i = 0; i < 3; ++i)
    s.coords.push_back(0.5 * (s.coords[3 * std::size_t{ends[0]} + i] + s.coords[3 * std::size_t{ends[1]} + i]));
  s.node_tags.push_back(next_tag++);
  return m;
}

// Splits triangle t of `topo` at node m on its edge e: (a, b, c) with e = a-b becomes
// (a, m, c) and (m, b, c), the same orientation; the two halves may not be paired.
void split_at(TriangleSurface& s, const TriangleTopology& topo, std::uint32_t t, std::uint32_t e,
              NodeIndex m, std::vector<char>& used) {
  const auto v = s.triangles[t];
  int k = 0;
  while (topo.triangle_edges[t][k] != e) ++k;
  const NodeIndex a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
  s.triangles[t] = {a, m, c};
  s.forbidden_pairs.push_back({t, static_cast<std::uint32_t>(s.triangles.size())});
  s.triangles.push_back({m, b, c});
  s.region.push_back(s.region[t]);
  s.triangle_tags.push_back(s.triangle_tags[t]);
  s.input_index.push_back(s.input_index[t]);
  used[t] = 1;
}

// Odd regions with no boundary edge ("stuck": the pieces of a closed surface cut at its
// feature edges, feature_edges.hpp) are made even by splitting edges between two regions
// (the longest whose triangles no other split took), each split adding a triangle to both.
// First between odd neighbours; then, over a breadth-first spanning forest of the regions'
// adjacency, deepest first, a stuck region splits an edge it shares with its parent, which
// flips the parent's parity. A region with a boundary edge left odd splits that edge later
// (make_regions_even); a stuck root left odd is reported. On a closed surface every tree
// holds an even number of odd regions (3T = 2E makes its total even), so none is left.
void split_interfaces(TriangleSurface& s, const TriangleTopology& topo, std::vector<char>& odd,
                      const std::vector<char>& has_boundary, std::vector<char>& used, Tag& next_tag) {
  const std::size_t num_regions = odd.size();
  const auto stuck = [&](std::uint32_t r) { return odd[r] && !has_boundary[r]; };
  bool any_stuck = false;
  for (std::uint32_t r = 0; r < num_regions; ++r) any_stuck |= stuck(r);
  if (!any_stuck) return;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> adjacent(num_regions);  // (region, edge)
  for (std::uint32_t e = 0; e < topo.edges.size(); ++e) {
    const std::uint32_t first = topo.edge_triangle_offsets[e];
    if (topo.edge_triangle_offsets[e + 1] - first != 2) continue;
    const auto r0 = static_cast<std::uint32_t>(s.region[topo.edge_triangles[first]]);
    const auto r1 = static_cast<std::uint32_t>(s.region[topo.edge_triangles[first + 1]]);
    if (r0 == r1) continue;
    adjacent[r0].push_back({r1, e});
    adjacent[r1].push_back({r0, e});
  }
  constexpr std::uint32_t kNone = 0xffffffffu;
  // The longest edge between regions r and `other` whose triangles no split took, or kNone.
  const auto edge_between = [&](std::uint32_t r, std::uint32_t other) {
    std::uint32_t best = kNone;
    double best_length = -1;
    for (const auto& [o, e] : adjacent[r]) {
      const std::uint32_t first = topo.edge_triangle_offsets[e];
      if (o != other || used[topo.edge_triangles[first]] || used[topo.edge_triangles[first + 1]]) continue;
      const double length = squared_distance(s.coords, topo.edges[e][0], topo.edges[e][1]);
      if (length > best_length) {
        best_length = length;
        best = e;
      }
    }
    return best;
  };
  const auto split_between = [&](std::uint32_t r, std::uint32_t other) {
    const std::uint32_t e = edge_between(r, other);
    if (e == kNone) return;
    const NodeIndex m = add_midpoint(s, topo.edges[e], next_tag);
    const std::uint32_t first = topo.edge_triangle_offsets[e];
    split_at(s, topo, topo.edge_triangles[first], e, m, used);
    split_at(s, topo, topo.edge_triangles[first + 1], e, m, used);
    ++s.odd_splits;
    odd[r] ^= 1;
    odd[other] ^= 1;
  };
  // Odd neighbours first, one of them stuck: one split makes both even.
  for (std::uint32_t r = 0; r < num_regions; ++r)
    for (std::size_t i = 0; odd[r] && i < adjacent[r].size(); ++i) {
      const std::uint32_t other = adjacent[r][i].first;
      if (odd[other] && (stuck(r) || stuck(other))) split_between(r, other);
    }
  // The forest grows from the regions with a boundary edge first: a root that ends odd
  // can then still split a boundary edge.
  std::vector<std::uint32_t> parent(num_regions, kNone), order, roots;
  for (std::uint32_t r = 0; r < num_regions; ++r)
    if (has_boundary[r]) roots.push_back(r);
  for (std::uint32_t r = 0; r < num_regions; ++r)
    if (!has_boundary[r]) roots.push_back(r);
  std::vector<char> seen(num_regions, 0);
  for (std::uint32_t root : roots) {
    if (seen[root]) continue;
    seen[root] = 1;
    order.push_back(root);
    for (std::size_t at = order.size() - 1; at < order.size(); ++at)
      for (const auto& [other, e] : adjacent[order[at]])
        if (!seen[other]) {
          seen[other] = 1;
          parent[other] = order[at];
          order.push_back(other);
        }
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it)
    if (stuck(*it) && parent[*it] != kNone) split_between(*it, parent[*it]);  // else left odd: reported
}

void collect(const Mesh& mesh, const std::string& source, TriangleSurface& s,
             std::vector<std::string>& warnings) {
  std::map<int, std::int32_t> region_of_entity;
  bool high_order = false;
  for (const ElementBlock& b : mesh.blocks) {
    QV_ASSERT(b.type != nullptr, "element block without a type");
    if (b.type->dim <= 1) continue;
    if (b.type->family != ElementFamily::triangle) {
      throw InputError::in_element(
          source, b.tags.empty() ? 0 : b.tags.front(),
          fmt::format("element is a {} ({}): recombination needs a mesh of triangles only",
                      family_name(b.type->family), b.type->name));
    }
    if (b.type->order > 1) high_order = true;
    auto [it, inserted] =
        region_of_entity.emplace(b.entity_tag, static_cast<std::int32_t>(s.region_entity.size()));
    if (inserted) s.region_entity.push_back(b.entity_tag);
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto n = b.element(e);
      s.triangles.push_back({n[0], n[1], n[2]});
      s.region.push_back(it->second);
      s.triangle_tags.push_back(b.tags[e]);
      s.input_index.push_back(static_cast<std::uint32_t>(s.input_index.size()));
    }
  }
  if (s.triangles.empty())
    throw InputError::in_file(source, "no triangles to recombine");
  if (high_order)
    warnings.push_back("high-order triangles: only their corner nodes are used");
}

void check_shapes(const std::string& source, const TriangleSurface& s) {
  // Zero area: |(b-a)x(c-a)| small against the longest edge squared (collinear corners).
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& v = s.triangles[t];
    const auto n = triangle_normal(s.coords, v);
    const double area2 = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double longest = std::max({squared_distance(s.coords, v[0], v[1]),
                                     squared_distance(s.coords, v[1], v[2]),
                                     squared_distance(s.coords, v[2], v[0])});
    if (!(area2 > 1e-12 * longest) || longest == 0.0)
      throw InputError::in_element(
          source, s.triangle_tags[t],
          fmt::format("triangle has zero area (nodes {} {} {} are collinear or repeated)",
                      s.node_tags[v[0]], s.node_tags[v[1]], s.node_tags[v[2]]));
  }
}

// The same three nodes twice: such triangles share every edge, so it is enough to compare the
// third nodes of the triangles around each edge (before check_manifold, which would report the
// edges of a duplicate inside the surface as non-manifold).
void check_duplicates(const std::string& source, const TriangleSurface& s,
                      const TriangleTopology& topo) {
  for (std::uint32_t e = 0; e < topo.num_edges(); ++e) {
    const std::uint32_t first = topo.edge_triangle_offsets[e], last = topo.edge_triangle_offsets[e + 1];
    const auto third = [&](std::uint32_t t) {
      const auto& v = s.triangles[t];
      return v[0] + v[1] + v[2] - topo.edges[e][0] - topo.edges[e][1];  // wraps consistently
    };
    for (std::uint32_t i = first; i < last; ++i)
      for (std::uint32_t j = i + 1; j < last; ++j) {
        const std::uint32_t a = topo.edge_triangles[i], b = topo.edge_triangles[j];
        if (third(a) != third(b)) continue;
        const Tag low = std::min(s.triangle_tags[a], s.triangle_tags[b]);
        const Tag high = std::max(s.triangle_tags[a], s.triangle_tags[b]);
        throw InputError::in_element(
            source, high, fmt::format("duplicate triangle: same three nodes as element {}", low));
      }
  }
}

void check_manifold(const std::string& source, const TriangleSurface& s,
                    const TriangleTopology& topo) {
  if (topo.nonmanifold_edges.empty()) return;
  const std::uint32_t e = topo.nonmanifold_edges.front();
  std::string tags;
  for (std::uint32_t i = topo.edge_triangle_offsets[e]; i < topo.edge_triangle_offsets[e + 1]; ++i) {
    if (!tags.empty()) tags += ' ';
    tags += std::to_string(s.triangle_tags[topo.edge_triangles[i]]);
  }
  throw InputError::in_element(
      source, s.triangle_tags[topo.edge_triangles[topo.edge_triangle_offsets[e] + 2]],
      fmt::format("non-manifold edge: nodes {} and {} are shared by {} triangles ({}); "
                  "recombination needs a manifold surface ({} such edges in all)",
                  s.node_tags[topo.edges[e][0]], s.node_tags[topo.edges[e][1]],
                  topo.edge_degree(e), tags, topo.nonmanifold_edges.size()));
}

// Orients each connected component consistently (breadth first over shared edges), keeping
// the orientation most of its input triangles have.
void orient(const std::string& source, TriangleSurface& s, const TriangleTopology& topo) {
  const std::size_t nt = s.triangles.size();
  std::vector<signed char> flip(nt, -1);
  std::vector<std::uint32_t> queue, component;
  auto runs_forward = [&](std::uint32_t t, NodeIndex a, NodeIndex b) {
    const auto& v = s.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (v[k] == a && v[(k + 1) % 3] == b) return true;
    return false;
  };
  for (std::uint32_t seed = 0; seed < nt; ++seed) {
    if (flip[seed] >= 0) continue;
    flip[seed] = 0;
    queue.assign(1, seed);
    component.clear();
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::uint32_t t = queue[q];
      component.push_back(t);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t u = topo.neighbors[t][k];
        if (u == kNoTriangle) continue;
        const NodeIndex a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
        // u must run a->b backwards once both are flipped as decided.
        const bool same_direction = runs_forward(u, a, b);
        const signed char want = static_cast<signed char>(flip[t] ^ (same_direction ? 1 : 0));
        if (flip[u] < 0) {
          flip[u] = want;
          queue.push_back(u);
        } else if (flip[u] != want) {
          throw InputError::in_element(
              source, s.triangle_tags[u],
              "the surface is not orientable (a Moebius-like strip): no consistent quad "
              "orientation exists");
        }
      }
    }
    std::size_t flipped = 0;
    for (std::uint32_t t : component) flipped += static_cast<std::size_t>(flip[t]);
    const bool invert = 2 * flipped > component.size();
    for (std::uint32_t t : component) {
      if ((flip[t] != 0) != invert) {
        std::swap(s.triangles[t][1], s.triangles[t][2]);
        ++s.flipped;
      }
    }
  }
}

}  // namespace

TriangleSurface collect_triangles(const Mesh& mesh, const std::string& source,
                                  std::vector<std::string>& warnings) {
  TriangleSurface s;
  s.coords = mesh.coords;
  s.node_tags = mesh.node_tags;
  collect(mesh, source, s, warnings);
  return s;
}

void validate_triangles(TriangleSurface& s, const std::string& source,
                        std::vector<std::string>& warnings) {
  check_shapes(source, s);
  TriangleTopology topo = build_triangle_topology(s.triangles, s.node_tags.size());
  check_duplicates(source, s, topo);
  check_manifold(source, s, topo);
  orient(source, s, topo);
  // A reversed triangle (a, c, b) holds the edges of (a, b, c) in the order 2, 1, 0.
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    if (topo.triangles[t] != s.triangles[t]) {
      topo.triangles[t] = s.triangles[t];
      std::swap(topo.triangle_edges[t][0], topo.triangle_edges[t][2]);
      std::swap(topo.neighbors[t][0], topo.neighbors[t][2]);
    }
  topo.num_misoriented_edges = 0;
  s.topology = std::move(topo);
  if (s.flipped > 0)
    warnings.push_back(fmt::format(
        "{} triangles were reversed to give each connected surface one orientation", s.flipped));
  for (std::size_t i = 2; i < s.coords.size(); i += 3)
    if (s.coords[i] != s.coords[2]) {
      s.planar = false;
      break;
    }
}

const TriangleTopology& topology_of(const TriangleSurface& s, std::optional<TriangleTopology>& built) {
  return s.topology ? *s.topology : built.emplace(build_triangle_topology(s.triangles, s.node_tags.size()));
}

TriangleSurface prepare_triangles(const Mesh& mesh, const std::string& source,
                                  std::vector<std::string>& warnings) {
  TriangleSurface s = collect_triangles(mesh, source, warnings);
  validate_triangles(s, source, warnings);
  return s;
}

void make_regions_even(TriangleSurface& s) {
  const std::size_t num_regions = s.region_entity.size();
  std::vector<std::size_t> count(num_regions, 0);
  for (std::int32_t r : s.region) ++count[static_cast<std::size_t>(r)];
  std::vector<char> odd(num_regions, 0);
  bool any_odd = false;
  for (std::size_t r = 0; r < num_regions; ++r) {
    odd[r] = count[r] % 2 == 1;
    any_odd = any_odd || odd[r];
  }
  if (!any_odd) return;

  std::optional<TriangleTopology> built;
  const TriangleTopology& topo = topology_of(s, built);
  std::vector<char> has_boundary(num_regions, 0), used(s.triangles.size(), 0);
  for (std::uint32_t e : topo.boundary_edges)
    has_boundary[static_cast<std::size_t>(s.region[topo.edge_triangles[topo.edge_triangle_offsets[e]]])] = 1;
  Tag next_tag = 1;
  for (Tag t : s.node_tags) next_tag = std::max(next_tag, t + 1);
  const std::size_t splits_before = s.odd_splits;
  split_interfaces(s, topo, odd, has_boundary, used, next_tag);
  // Longest boundary edge per region still odd, preferring edges whose end nodes have 3 or
  // more triangles: at a node with two, the halves' neighbours could only form a quad with a
  // flat (180-degree) corner there. (Ranked by the pair, roomy first: a length added to a
  // large bonus was absorbed by it, which made the first roomy edge win, not the longest.)
  std::vector<std::uint32_t> best_edge(num_regions, kNoTriangle);
  std::vector<std::pair<bool, double>> best_rank(num_regions, {false, -1.0});
  for (std::uint32_t e : topo.boundary_edges) {
    const std::uint32_t t = topo.edge_triangles[topo.edge_triangle_offsets[e]];
    const auto r = static_cast<std::size_t>(s.region[t]);
    if (!odd[r] || used[t]) continue;
    const bool roomy = topo.vertex_triangles[topo.edges[e][0]] >= 3 &&
                       topo.vertex_triangles[topo.edges[e][1]] >= 3;
    const std::pair<bool, double> rank{roomy, squared_distance(s.coords, topo.edges[e][0], topo.edges[e][1])};
    if (rank > best_rank[r]) {
      best_rank[r] = rank;
      best_edge[r] = e;
    }
  }
  for (std::size_t r = 0; r < num_regions; ++r) {
    if (!odd[r]) continue;
    const std::uint32_t e = best_edge[r];
    if (e == kNoTriangle) {
      s.odd_regions_left.push_back(static_cast<std::int32_t>(r));
      continue;
    }
    const NodeIndex m = add_midpoint(s, topo.edges[e], next_tag);
    split_at(s, topo, topo.edge_triangles[topo.edge_triangle_offsets[e]], e, m, used);
    ++s.odd_splits;
  }
  if (s.odd_splits > splits_before) s.topology.reset();  // after the loop: `topo` may be it
}

}  // namespace quadval::recombine_detail
