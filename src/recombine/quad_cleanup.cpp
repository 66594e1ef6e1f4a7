#include "quad_cleanup.hpp"

#include <algorithm>
#include <cmath>

#include "smoothing.hpp"

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

// Both operations below push to `not_valid` the elements they leave not valid (possible only
// where one of theirs was not valid before).
bool collapse_doublet(MixedMesh& m, Lists& at, NodeIndex v, std::vector<std::uint32_t>& not_valid) {
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
  const double after = element_score(m, merged, normal);
  if (after < before) return false;
  if (!(after > 0)) not_valid.push_back(e1);
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
                    int first, std::vector<std::uint32_t>& not_valid) {
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
  if (!(best_worst > 0)) not_valid.insert(not_valid.end(), around.begin(), around.end());
  m.alive[q] = 0;
  erase_value(at[a], q);
  erase_value(at[b], q);
  erase_value(at[d], q);
  for (std::uint32_t e : at[c])
    if (e != q) at[a].push_back(e);
  at[c].clear();
  return true;
}

bool holds(const std::array<NodeIndex, 4>& e, NodeIndex v) {
  return std::find(e.begin(), e.end(), v) != e.end();
}

// At corner v of an element (neighbours next and prev): (f x g) . n with f = next - v,
// g = prev - v (positive where the corner turns with the normal), and |f|^2, |g|^2.
struct CornerTurn {
  double cross_normal, ff, gg;
};
CornerTurn corner_turn(const MixedMesh& m, NodeIndex v, NodeIndex next, NodeIndex prev,
                       const std::array<double, 3>& n) {
  const auto x = m.point(v), a = m.point(next), b = m.point(prev);
  const std::array<double, 3> f{a[0] - x[0], a[1] - x[1], a[2] - x[2]};
  const std::array<double, 3> g{b[0] - x[0], b[1] - x[1], b[2] - x[2]};
  return {(f[1] * g[2] - f[2] * g[1]) * n[0] + (f[2] * g[0] - f[0] * g[2]) * n[1] +
              (f[0] * g[1] - f[1] * g[0]) * n[2],
          f[0] * f[0] + f[1] * f[1] + f[2] * f[2], g[0] * g[0] + g[1] * g[1] + g[2] * g[2]};
}

// A cheap filter before element_score (a full scan with it alone took 70 ms on 480k quads):
// true when every corner turns with the normal at a sine above 1e-6, so that the quad is
// convex and its eta (element_score) positive: |cos| <= 1 - 5e-13 there, far from rounding
// to 1 (at a sine of 1e-8 it would). False does not mean the quad is not valid.
bool surely_valid(const MixedMesh& m, std::uint32_t q) {
  const auto& e = m.elements[q];
  const auto& n = m.normal[q];
  const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  for (int k = 0; k < 4; ++k) {
    const CornerTurn t = corner_turn(m, e[k], e[(k + 1) % 4], e[(k + 3) % 4], n);
    if (!(t.cross_normal > 0) || t.cross_normal * t.cross_normal <= 1e-12 * t.ff * t.gg * nn) return false;
  }
  return true;
}

// A frozen corner: it and both its neighbours are fixed (they may only slide along their
// straight side), so no smoothing changes its angle. Stuck: frozen and not strictly convex.
bool frozen_corner(const std::vector<char>& fixed, const std::array<NodeIndex, 4>& q, int k) {
  return fixed[q[k]] && fixed[q[(k + 1) % 4]] && fixed[q[(k + 3) % 4]];
}
bool has_frozen_corner(const std::vector<char>& fixed, const std::array<NodeIndex, 4>& q) {
  for (int k = 0; k < 4; ++k)
    if (frozen_corner(fixed, q, k)) return true;
  return false;
}
bool stuck_corner(const MixedMesh& m, const std::vector<char>& fixed, const std::array<NodeIndex, 4>& q,
                  const std::array<double, 3>& normal) {
  for (int k = 0; k < 4; ++k)
    if (frozen_corner(fixed, q, k) && !(corner_turn(m, q[k], q[(k + 1) % 4], q[(k + 3) % 4], normal).cross_normal > 0))
      return true;
  return false;
}

// The other splits of the hexagon that quad q and a quad q' across one of its edges form:
// h0..h5 around it, q = h0 h1 h2 h5 and q' = h5 h2 h3 h4 sharing h2-h5, which two quads can
// also cover along h0-h3 or h1-h4. Calls f(q', a, b, normal) for each such pair of quads
// (a, b) without a stuck corner whose new diagonal joins no other element.
template <class F>
void for_each_resplit(const MixedMesh& m, const Lists& at, const std::vector<char>& fixed, std::uint32_t q, F&& f) {
  for (int k = 0; k < 4; ++k) {
    const auto el = starting_at(m.elements[q], m.elements[q][(k + 2) % 4]);  // (h2, h5, h0, h1)
    const NodeIndex h2 = el[0], h5 = el[1], h0 = el[2], h1 = el[3];
    for (std::uint32_t o : at[h2]) {
      if (o == q || !m.alive[o] || !m.is_quad(o) || m.region[o] != m.region[q]) continue;
      const auto& oe = m.elements[o];
      if (!holds(oe, h5)) continue;
      const int i = corner_of(oe, h5);
      if (oe[(i + 1) % 4] != h2) continue;  // q' must run h5 -> h2
      const NodeIndex h3 = oe[(i + 2) % 4], h4 = oe[(i + 3) % 4];
      const std::array<NodeIndex, 6> h{h0, h1, h2, h3, h4, h5};
      bool distinct = true;
      for (int a = 0; a < 6; ++a)
        for (int b = a + 1; b < 6; ++b) distinct = distinct && h[a] != h[b];
      if (!distinct) continue;
      std::array<double, 3> normal;
      for (int d = 0; d < 3; ++d) normal[d] = m.normal[q][d] + m.normal[o][d];
      for (int s = 0; s < 2; ++s) {  // diagonal h_s - h_{s+3}
        const NodeIndex from = h[s], to = h[s + 3];
        bool edge_elsewhere = false;
        for (std::uint32_t e : at[from])
          edge_elsewhere = edge_elsewhere || (e != q && e != o && holds(m.elements[e], to));
        if (edge_elsewhere) continue;
        const std::array<NodeIndex, 4> a{h[s], h[s + 1], h[s + 2], h[s + 3]};
        const std::array<NodeIndex, 4> b{h[s + 3], h[(s + 4) % 6], h[(s + 5) % 6], h[s]};
        if (stuck_corner(m, fixed, a, normal) || stuck_corner(m, fixed, b, normal)) continue;
        f(o, a, b, normal);
      }
    }
  }
}

// Replaces quads q and o by a and b (both with the given normal), keeping `at` in step.
void resplit(MixedMesh& m, Lists& at, std::uint32_t q, std::uint32_t o, const std::array<NodeIndex, 4>& a,
             const std::array<NodeIndex, 4>& b, const std::array<double, 3>& normal) {
  for (std::uint32_t e : {q, o})
    for (NodeIndex v : m.elements[e]) erase_value(at[v], e);
  m.elements[q] = a;
  m.elements[o] = b;
  m.normal[q] = m.normal[o] = normal;
  for (std::uint32_t e : {q, o})
    for (NodeIndex v : m.elements[e]) at[v].push_back(e);
}

// Diagonal swap of a quad q that is not valid: takes the split of for_each_resplit whose
// worse quad scores higher, if both its quads are valid, or, where q has a stuck corner,
// even if not (smoothing then opens the rest: its corners can move). No node moves and the
// hexagon's outline stays. The case that needs it: a boundary node in two triangles that
// the matching paired makes a flat corner on a straight boundary, which no node position can
// mend.
bool swap_diagonal(MixedMesh& m, Lists& at, const std::vector<char>& fixed, std::uint32_t q) {
  if (element_score(m, q) > 0) return false;
  const bool stuck = stuck_corner(m, fixed, m.elements[q], m.normal[q]);
  bool found = false;
  double best = 0;
  std::uint32_t best_other = 0;
  std::array<NodeIndex, 4> best_a{}, best_b{};
  std::array<double, 3> best_normal{};
  for_each_resplit(m, at, fixed, q, [&](std::uint32_t o, const auto& a, const auto& b, const auto& normal) {
    const double worst = std::min(element_score(m, a, normal), element_score(m, b, normal));
    if (!found || worst > best) {
      found = true;
      best = worst;
      best_other = o;
      best_a = a;
      best_b = b;
      best_normal = normal;
    }
  });
  if (!found || !(best > 0 || stuck)) return false;
  resplit(m, at, q, best_other, best_a, best_b, best_normal);
  return true;
}

// The worst score of the elements at node v.
double worst_at(const MixedMesh& m, const Lists& at, NodeIndex v) {
  double worst = 2.0;
  for (std::uint32_t e : at[v]) worst = std::min(worst, element_score(m, e));
  return worst;
}

// A few sweeps over the free nodes `nodes`: each moves to the mean of its edge neighbours, or
// half way, when that raises the worst score of its elements (as smooth() does).
void relax(MixedMesh& m, const Lists& at, const std::vector<NodeIndex>& nodes) {
  for (int sweep = 0; sweep < 2; ++sweep)
    for (NodeIndex v : nodes) {
      std::array<double, 3> mean{0, 0, 0};
      int count = 0;
      for (std::uint32_t e : at[v]) {
        const int i = corner_of(m.elements[e], v);
        for (NodeIndex j : {next_corner(m.elements[e], i), prev_corner(m.elements[e], i)}) {
          const auto p = m.point(j);
          for (int d = 0; d < 3; ++d) mean[d] += p[d];
          ++count;
        }
      }
      const auto x = m.point(v);
      double* c = &m.coords[3 * std::size_t{v}];
      double best = worst_at(m, at, v);
      std::array<double, 3> keep = x;
      for (const double t : {1.0, 0.5}) {
        for (int d = 0; d < 3; ++d) c[d] = x[d] + t * (mean[d] / count - x[d]);
        if (const double w = worst_at(m, at, v); w > best) {
          best = w;
          keep = {c[0], c[1], c[2]};
        }
      }
      for (int d = 0; d < 3; ++d) c[d] = keep[d];
    }
}

// Diagonal swap of a valid quad q (with a frozen corner, whose angle no smoothing changes,
// e.g. at a boundary node on a curve that only q holds: nearly 180 degrees; or one of the
// worst, see swap_worst): each split of for_each_resplit is tried with the free nodes of its
// hexagon relaxed, and the one whose worst element around the hexagon scores highest is
// kept if that beats the worst there before; otherwise nothing changes.
bool swap_if_better(MixedMesh& m, Lists& at, const std::vector<char>& fixed, std::uint32_t q) {
  if (!(element_score(m, q) > 0)) return false;
  struct Trial {
    std::uint32_t o;
    std::array<NodeIndex, 4> a, b;
    std::array<double, 3> normal;
  };
  std::vector<Trial> trials;
  for_each_resplit(m, at, fixed, q, [&](std::uint32_t o, const auto& a, const auto& b, const auto& normal) {
    trials.push_back({o, a, b, normal});
  });
  bool found = false;
  double best_gain = 0;
  Trial best{};
  std::vector<std::pair<NodeIndex, std::array<double, 3>>> best_coords;
  for (const Trial& t : trials) {
    std::vector<NodeIndex> free;
    std::vector<std::uint32_t> around;  // the elements whose shape the trial can change
    for (const auto& e : {m.elements[q], m.elements[t.o]})
      for (NodeIndex v : e) {
        if (!fixed[v] && std::find(free.begin(), free.end(), v) == free.end()) free.push_back(v);
        for (std::uint32_t x : at[v])
          if (std::find(around.begin(), around.end(), x) == around.end()) around.push_back(x);
      }
    const auto worst_around = [&] {
      double w = 2.0;
      for (std::uint32_t e : around) w = std::min(w, element_score(m, e));
      return w;
    };
    const double before = worst_around();
    std::vector<std::pair<NodeIndex, std::array<double, 3>>> saved;
    for (NodeIndex v : free) saved.push_back({v, m.point(v)});
    const std::array<NodeIndex, 4> old_q = m.elements[q], old_o = m.elements[t.o];
    const std::array<double, 3> normal_q = m.normal[q], normal_o = m.normal[t.o];
    resplit(m, at, q, t.o, t.a, t.b, t.normal);
    relax(m, at, free);
    const double after = worst_around();
    if (after > 0 && after > before && (!found || after - before > best_gain)) {
      found = true;
      best_gain = after - before;
      best = t;
      best_coords.clear();
      for (NodeIndex v : free) best_coords.push_back({v, m.point(v)});
    }
    resplit(m, at, q, t.o, old_q, old_o, normal_q);  // undo
    m.normal[t.o] = normal_o;
    for (const auto& [v, x] : saved)
      for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d];
  }
  if (!found) return false;
  resplit(m, at, q, best.o, best.a, best.b, best.normal);
  for (const auto& [v, x] : best_coords)
    for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d];
  return true;
}

}  // namespace

CleanupCounts cleanup_quads(MixedMesh& m, const std::vector<char>& fixed, int max_passes) {
  CleanupCounts counts;
  if (max_passes <= 0) return counts;
  Lists at = node_elements(m);
  // The quads to try a diagonal swap on, found once: those that are not valid or have a
  // frozen corner. The collapses and merges add the quads they leave not valid (they can only
  // where one of theirs was already) and make no frozen corner (they move no fixed node).
  std::vector<std::uint32_t> to_swap;
  for (std::uint32_t q = 0; q < m.elements.size(); ++q)
    if (m.alive[q] && m.is_quad(q) &&
        (has_frozen_corner(fixed, m.elements[q]) || (!surely_valid(m, q) && !(element_score(m, q) > 0))))
      to_swap.push_back(q);
  for (int pass = 0; pass < max_passes; ++pass) {
    std::size_t changes = 0;
    for (NodeIndex v = 0; v < m.num_nodes(); ++v)
      if (!fixed[v] && collapse_doublet(m, at, v, to_swap)) {
        ++counts.doublet_collapses;
        ++changes;
      }
    std::erase_if(to_swap, [&m](std::uint32_t q) { return !m.alive[q] || !m.is_quad(q); });
    for (std::uint32_t q : to_swap)
      if (swap_diagonal(m, at, fixed, q) ||
          (has_frozen_corner(fixed, m.elements[q]) && swap_if_better(m, at, fixed, q))) {
        ++counts.diagonal_swaps;
        ++changes;
      }
    for (std::uint32_t q = 0; q < m.elements.size(); ++q) {
      if (!m.alive[q] || !m.is_quad(q)) continue;
      for (int first = 0; first < 2; ++first)
        if (merge_diagonal(m, at, fixed, q, first, to_swap)) {
          ++counts.vertex_merges;
          ++changes;
          break;
        }
    }
    if (changes == 0) break;
  }
  return counts;
}

std::size_t swap_worst(MixedMesh& m, const std::vector<char>& fixed, double share, int rounds,
                       std::vector<char>* near) {
  Lists at = node_elements(m);
  std::size_t swaps = 0;
  for (int round = 0; round < rounds; ++round) {
    // The quads' scores on the threads, listed in element order.
    const auto ne = static_cast<std::ptrdiff_t>(m.elements.size());
    std::vector<double> score(m.elements.size());
#pragma omp parallel for schedule(static) if (ne > 16384)
    for (std::ptrdiff_t i = 0; i < ne; ++i) {
      const auto q = static_cast<std::size_t>(i);
      if (!m.alive[q] || !m.is_quad(q)) continue;
      const auto& n = m.normal[q];
      score[q] = smoothing_score(m.coords, m.elements[q], n, std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
    std::vector<std::pair<double, std::uint32_t>> scores;
    for (std::uint32_t q = 0; q < m.elements.size(); ++q)
      if (m.alive[q] && m.is_quad(q)) scores.push_back({score[q], q});
    const auto worst = std::min(scores.size(), std::max<std::size_t>(16, static_cast<std::size_t>(share * static_cast<double>(scores.size()))));
    std::partial_sort(scores.begin(), scores.begin() + static_cast<std::ptrdiff_t>(worst), scores.end());
    std::size_t made = 0;
    for (std::size_t i = 0; i < worst; ++i) {
      const std::uint32_t q = scores[i].second;
      if (!swap_if_better(m, at, fixed, q)) continue;
      ++made;
      if (!near) continue;
      near->resize(m.num_nodes(), 0);
      for (NodeIndex v : m.elements[q])  // q and its partner share a node: their rings cover both
        for (std::uint32_t e : at[v])
          for (int k = 0; k < MixedMesh::size(m.elements[e]); ++k) (*near)[m.elements[e][k]] = 1;
    }
    swaps += made;
    if (made == 0) break;
  }
  return swaps;
}

}  // namespace quadval::recombine_detail
