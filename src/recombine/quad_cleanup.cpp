#include "quad_cleanup.hpp"

#include <algorithm>

namespace quadval::recombine_detail {

namespace {

using Lists = std::vector<std::vector<std::uint32_t>>;

void erase_value(std::vector<std::uint32_t>& list, std::uint32_t value) {
  list.erase(std::remove(list.begin(), list.end(), value), list.end());
}

bool all_quads(const MixedMesh& m, const std::vector<std::uint32_t>& list) {
  for (std::uint32_t e : list)
    if (!m.is_quad(e)) return false;
  return true;
}

// Rotates a quad so that it starts at v.
std::array<NodeIndex, 4> starting_at(const std::array<NodeIndex, 4>& q, NodeIndex v) {
  const int i = corner_of(q, v);
  return {q[i], q[(i + 1) % 4], q[(i + 2) % 4], q[(i + 3) % 4]};
}

bool collapse_doublet(MixedMesh& m, Lists& at, NodeIndex v) {
  if (at[v].size() != 2 || !all_quads(m, at[v])) return false;
  const std::uint32_t e1 = at[v][0], e2 = at[v][1];
  const auto q1 = starting_at(m.elements[e1], v), q2 = starting_at(m.elements[e2], v);
  // q1 = (v, a, x, b) and q2 = (v, b, y, a).
  const NodeIndex a = q1[1], x = q1[2], b = q1[3], y = q2[2];
  if (q2[1] != b || q2[3] != a || x == y) return false;
  const std::array<NodeIndex, 4> merged{a, x, b, y};
  std::array<double, 3> normal;
  for (int d = 0; d < 3; ++d) normal[d] = m.normal[e1][d] + m.normal[e2][d];
  const double before = std::min(element_score(m, e1), element_score(m, e2));
  if (element_score(m, merged, normal) < before) return false;
  m.elements[e1] = merged;
  m.normal[e1] = normal;
  m.alive[e2] = 0;
  erase_value(at[a], e2);
  erase_value(at[b], e2);
  erase_value(at[y], e2);
  at[y].push_back(e1);
  at[v].clear();
  return true;
}

bool merge_diagonal(MixedMesh& m, Lists& at, const std::vector<char>& fixed, std::uint32_t q,
                    int first) {
  const auto& el = m.elements[q];
  const NodeIndex a = el[first], b = el[(first + 1) % 4], c = el[(first + 2) % 4],
                  d = el[(first + 3) % 4];
  if (fixed[a] || fixed[c] || at[a].size() != 3 || at[c].size() != 3) return false;
  const std::size_t min_b = fixed[b] ? 3 : 4, min_d = fixed[d] ? 3 : 4;
  if (at[b].size() < min_b || at[d].size() < min_d) return false;
  if (!all_quads(m, at[a]) || !all_quads(m, at[c])) return false;
  for (std::uint32_t e : at[a])
    if (e != q && std::find(at[c].begin(), at[c].end(), e) != at[c].end()) return false;

  double before = 2.0;
  for (std::uint32_t e : at[a]) before = std::min(before, element_score(m, e));
  for (std::uint32_t e : at[c]) before = std::min(before, element_score(m, e));
  std::vector<std::uint32_t> around;  // the four quads around the merged node
  for (std::uint32_t e : at[a]) if (e != q) around.push_back(e);
  for (std::uint32_t e : at[c]) if (e != q) around.push_back(e);
  std::vector<std::array<NodeIndex, 4>> changed;
  for (std::uint32_t e : around) {
    auto el2 = m.elements[e];
    for (auto& x : el2)
      if (x == c) x = a;
    changed.push_back(el2);
  }
  const std::array<double, 3> xa = m.point(a), xc = m.point(c);
  auto worst_at = [&](const std::array<double, 3>& p) {
    for (int k = 0; k < 3; ++k) m.coords[3 * std::size_t{a} + k] = p[k];
    double worst = 2.0;
    for (std::size_t i = 0; i < around.size(); ++i)
      worst = std::min(worst, element_score(m, changed[i], m.normal[around[i]]));
    return worst;
  };
  std::array<double, 3> mid{0.5 * (xa[0] + xc[0]), 0.5 * (xa[1] + xc[1]), 0.5 * (xa[2] + xc[2])};
  std::array<double, 3> mean{0, 0, 0};
  int count = 0;
  for (const auto& el2 : changed) {
    const int i = corner_of(el2, a);
    for (NodeIndex j : {el2[(i + 1) % 4], el2[(i + 3) % 4]}) {
      const auto p = m.point(j);
      for (int k = 0; k < 3; ++k) mean[k] += p[k];
      ++count;
    }
  }
  for (auto& x : mean) x /= count;
  std::array<double, 3> best = mid;
  double best_worst = worst_at(mid);
  if (const double w = worst_at(mean); w > best_worst) {
    best = mean;
    best_worst = w;
  }
  if (!(best_worst > 0 || best_worst >= before)) {
    for (int k = 0; k < 3; ++k) m.coords[3 * std::size_t{a} + k] = xa[k];
    return false;
  }
  for (int k = 0; k < 3; ++k) m.coords[3 * std::size_t{a} + k] = best[k];
  for (std::size_t i = 0; i < around.size(); ++i) m.elements[around[i]] = changed[i];
  m.alive[q] = 0;
  erase_value(at[a], q);
  erase_value(at[b], q);
  erase_value(at[d], q);
  for (std::uint32_t e : at[c])
    if (e != q) at[a].push_back(e);
  at[c].clear();
  return true;
}

}  // namespace

CleanupCounts cleanup_quads(MixedMesh& m, const std::vector<char>& fixed, int max_passes) {
  CleanupCounts counts;
  if (max_passes <= 0) return counts;
  Lists at = node_elements(m);
  for (int pass = 0; pass < max_passes; ++pass) {
    std::size_t changes = 0;
    for (NodeIndex v = 0; v < m.num_nodes(); ++v)
      if (!fixed[v] && collapse_doublet(m, at, v)) {
        ++counts.doublet_collapses;
        ++changes;
      }
    for (std::uint32_t q = 0; q < m.elements.size(); ++q) {
      if (!m.alive[q] || !m.is_quad(q)) continue;
      for (int first = 0; first < 2; ++first)
        if (merge_diagonal(m, at, fixed, q, first)) {
          ++counts.vertex_merges;
          ++changes;
          break;
        }
    }
    if (changes == 0) break;
  }
  return counts;
}

}  // namespace quadval::recombine_detail
