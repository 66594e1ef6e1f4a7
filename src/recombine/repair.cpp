#include "repair.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V3 unit(const V3& a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? V3{a[0] / n, a[1] / n, a[2] / n} : V3{0, 0, 0};
}

// The elements strictly between `start` and `target` walking counter-clockwise around v
// (across start's edge v-prev(v)), or nullopt if the walk leaves the region or loops.
std::optional<std::vector<std::uint32_t>> fan_between(
    const MixedMesh& m, const std::vector<std::vector<std::uint32_t>>& at, std::uint32_t start,
    std::uint32_t target, NodeIndex v) {
  std::vector<std::uint32_t> fan;
  std::uint32_t cur = start;
  NodeIndex across = prev_corner(m.elements[cur], corner_of(m.elements[cur], v));
  for (std::size_t steps = 0; steps <= at[v].size(); ++steps) {
    std::uint32_t next = 0xffffffffu;
    for (std::uint32_t f : at[v]) {
      if (f == cur || !m.alive[f] || m.region[f] != m.region[start]) continue;
      if (next_corner(m.elements[f], corner_of(m.elements[f], v)) == across) next = f;
    }
    if (next == 0xffffffffu) return std::nullopt;
    if (next == target) return fan;
    if (next == start) return std::nullopt;
    fan.push_back(next);
    cur = next;
    across = prev_corner(m.elements[cur], corner_of(m.elements[cur], v));
  }
  return std::nullopt;
}

void erase_value(std::vector<std::uint32_t>& list, std::uint32_t value) {
  list.erase(std::remove(list.begin(), list.end(), value), list.end());
}

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

}  // namespace

RepairCounts repair_extra_pairs(MixedMesh& m, const std::vector<ExtraPair>& pairs, Tag& next_tag) {
  RepairCounts counts;
  if (pairs.empty()) return counts;
  auto at = node_elements(m);
  for (const ExtraPair& pair : pairs) {
    const NodeIndex v = pair.v;
    std::uint32_t start = pair.e0, target = pair.e1;
    auto fan = fan_between(m, at, start, target, v);
    if (!fan) {
      std::swap(start, target);
      fan = fan_between(m, at, start, target, v);
    }
    if (!fan || fan->empty()) {
      ++counts.failed;
      continue;
    }
    const auto s_el = m.elements[start], t_el = m.elements[target];
    const NodeIndex a = next_corner(s_el, corner_of(s_el, v));
    const NodeIndex p1 = prev_corner(s_el, corner_of(s_el, v));
    const NodeIndex pk = next_corner(t_el, corner_of(t_el, v));
    const NodeIndex b = prev_corner(t_el, corner_of(t_el, v));
    V3 n = add(m.normal[start], m.normal[target]);
    for (std::uint32_t f : *fan) n = add(n, m.normal[f]);

    // Edge swap (Fig. 8): one quad (v, p1, r, pk) between the two triangles.
    std::optional<std::array<std::array<NodeIndex, 4>, 2>> swapped;
    bool swap_convex = false;
    if (fan->size() == 1 && m.is_quad(fan->front())) {
      const auto& q = m.elements[fan->front()];
      const int i = corner_of(q, v);
      const NodeIndex r = q[(i + 2) % 4];
      const std::array<NodeIndex, 4> qa{v, a, p1, r}, qb{v, r, pk, b};
      const std::array<NodeIndex, 4> ta{v, p1, r, kNoNode}, tb{v, r, pk, kNoNode};
      if (element_score(m, ta, n) > 0 && element_score(m, tb, n) > 0) {
        swapped = std::array<std::array<NodeIndex, 4>, 2>{qa, qb};
        swap_convex = element_score(m, qa, n) > 0 && element_score(m, qb, n) > 0;
      }
    }
    auto apply_swap = [&]() {
      const std::uint32_t q = fan->front();
      const NodeIndex r = (*swapped)[0][3];
      m.elements[start] = (*swapped)[0];
      m.elements[target] = (*swapped)[1];
      m.normal[start] = add(m.normal[start], m.normal[q]);
      m.normal[target] = add(m.normal[target], m.normal[q]);
      m.alive[q] = 0;
      for (NodeIndex x : {v, p1, pk, r}) erase_value(at[x], q);
      at[r].push_back(start);
      at[r].push_back(target);
      ++counts.edge_swaps;
    };
    if (swapped && swap_convex) {
      apply_swap();
      continue;
    }

    // Vertex duplication (Fig. 9). Angles around v in its tangent plane, from a.
    const V3 xv = m.point(v);
    const V3 nn = unit(n);
    auto tangent = [&](NodeIndex x) {
      const V3 d = sub(m.point(x), xv);
      const double h = dot(d, nn);
      return V3{d[0] - h * nn[0], d[1] - h * nn[1], d[2] - h * nn[2]};
    };
    const V3 u = unit(tangent(a));
    const V3 w = cross(nn, u);
    auto angle = [&](NodeIndex x) {
      const V3 d = tangent(x);
      double t = std::atan2(dot(d, w), dot(d, u));
      return t < 0 ? t + 2 * std::numbers::pi : t;
    };
    const double phi1 = angle(p1), phik = angle(pk), theta = angle(b);
    double lo = std::max(phi1, theta - std::numbers::pi);
    double hi = std::min(phik, std::numbers::pi);
    if (!(lo < hi)) {
      lo = phi1;
      hi = phik;
    }
    const double psi = 0.5 * (lo + hi);
    const V3 dir{std::cos(psi) * u[0] + std::sin(psi) * w[0],
                 std::cos(psi) * u[1] + std::sin(psi) * w[1],
                 std::cos(psi) * u[2] + std::sin(psi) * w[2]};
    double reach = INFINITY;
    for (std::uint32_t f : *fan)
      for (int i = 0; i < MixedMesh::size(m.elements[f]); ++i)
        if (m.elements[f][i] != v) reach = std::min(reach, std::sqrt(dot(tangent(m.elements[f][i]), tangent(m.elements[f][i]))));
    const NodeIndex vd = m.add_node(xv, next_tag++);
    at.emplace_back();
    const std::array<NodeIndex, 4> qa{v, a, p1, vd}, qb{v, vd, pk, b};
    std::vector<std::array<NodeIndex, 4>> moved;
    for (std::uint32_t f : *fan) {
      auto el = m.elements[f];
      el[corner_of(el, v)] = vd;
      moved.push_back(el);
    }
    auto all_valid = [&]() {
      if (element_score(m, qa, n) <= 0 || element_score(m, qb, n) <= 0) return false;
      for (std::size_t i = 0; i < fan->size(); ++i)
        if (element_score(m, moved[i], m.normal[(*fan)[i]]) <= 0) return false;
      return true;
    };
    double step = 0.5 * reach;
    bool valid = false;
    for (int tries = 0; tries < 30 && !valid; ++tries, step *= 0.5) {
      for (int i = 0; i < 3; ++i) m.coords[3 * std::size_t{vd} + i] = xv[i] + step * dir[i];
      valid = all_valid();
    }
    if (!valid && swapped) {  // the swap keeps simple (if non-convex) quads: prefer it
      m.coords.resize(m.coords.size() - 3);
      m.node_tags.pop_back();
      at.pop_back();
      --next_tag;
      apply_swap();
      continue;
    }
    m.elements[start] = qa;
    m.elements[target] = qb;
    for (std::size_t i = 0; i < fan->size(); ++i) {
      m.elements[(*fan)[i]] = moved[i];
      erase_value(at[v], (*fan)[i]);
      at[vd].push_back((*fan)[i]);
    }
    at[vd].push_back(start);
    at[vd].push_back(target);
    ++counts.vertex_duplications;
  }
  return counts;
}

}  // namespace quadval::recombine_detail
