#include "leftover_paths.hpp"

#include <algorithm>
#include <cstdint>
#include <queue>
#include <vector>

namespace quadval::recombine_detail {

namespace {

// The triangle of pair p that is not t.
std::uint32_t other_triangle(const DualGraph& g, std::uint32_t p, std::uint32_t t) {
  return g.pairs[p].t0 == t ? g.pairs[p].t1 : g.pairs[p].t0;
}

// A search step: an "outer" triangle to expand (pair == kUnmatched), or the end of a path,
// from outer triangle `triangle` by pair `pair` to a free one. Cheapest first, then oldest.
struct Step {
  double cost;
  std::uint64_t order;
  std::uint32_t triangle, pair;
  bool operator>(const Step& o) const { return cost != o.cost ? cost > o.cost : order > o.order; }
};

// From each free triangle in increasing index, a best-first search for the cheapest
// augmenting path (pairs gained minus pairs given up), labelling each triangle once and
// stopping after max_visits triangles; the path found is swapped at once.
std::size_t paths(const DualGraph& g, std::vector<std::uint32_t>& mate, std::size_t max_visits) {
  const std::uint32_t n = g.num_triangles;
  const auto other = [&](std::uint32_t p, std::uint32_t t) { return other_triangle(g, p, t); };
  // Per triangle: the search that labelled it, and for an "inner" one (reached by a pair not
  // in the matching, its mate then "outer") that pair.
  std::vector<std::uint32_t> labelled(n, 0), reached_by(n, kUnmatched);
  std::uint32_t search = 0;
  std::size_t paired = 0;
  for (std::uint32_t root = 0; root < n; ++root) {
    if (mate[root] != kUnmatched) continue;
    ++search;
    labelled[root] = search;
    std::priority_queue<Step, std::vector<Step>, std::greater<>> queue;
    std::uint64_t order = 0;
    queue.push({0.0, order++, root, kUnmatched});
    std::size_t visits = 0;
    while (!queue.empty()) {
      const Step s = queue.top();
      queue.pop();
      if (s.pair != kUnmatched) {
        // Swap along the path: s.pair joins s.triangle to the free end; back to the root, each
        // outer triangle's pair is given up for the pair that reached its inner partner.
        std::uint32_t x = s.triangle, gained = s.pair;
        mate[other(gained, x)] = gained;
        while (true) {
          const std::uint32_t given_up = mate[x];
          mate[x] = gained;
          if (x == root) break;
          const std::uint32_t y = other(given_up, x);
          gained = reached_by[y];
          mate[y] = gained;
          x = other(gained, y);
        }
        paired += 2;
        break;
      }
      if (++visits > max_visits) break;
      const std::uint32_t x = s.triangle;
      for (std::uint32_t i = g.offsets[x]; i < g.offsets[x + 1]; ++i) {
        const std::uint32_t p = g.incident[i];
        if (g.pairs[p].kind != PairKind::real || p == mate[x]) continue;
        const std::uint32_t y = other(p, x);
        if (labelled[y] == search) continue;
        const double cost = s.cost + g.pairs[p].cost;
        if (mate[y] == kUnmatched) {
          queue.push({cost, order++, x, p});
          continue;
        }
        const std::uint32_t z = other(mate[y], y);
        if (labelled[z] == search) continue;
        labelled[y] = labelled[z] = search;
        reached_by[y] = p;
        queue.push({cost - g.pairs[mate[y]].cost, order++, z, kUnmatched});
      }
    }
  }
  return paired;
}

// The free triangles' neighbourhoods (within `radius` pairs, plus the partners of the paired
// triangles reached), each connected piece re-paired by an exact minimum-cost perfect
// matching of its real pairs where one exists; a piece without one keeps its pairs. The
// alternating searches (paths() above, trees_together() below) cannot go through an odd
// cycle of pairs (a blossom); this can.
// Returns the number of triangles paired.
std::size_t neighbourhoods(const DualGraph& g, std::vector<std::uint32_t>& mate, int radius) {
  const std::uint32_t n = g.num_triangles;
  const auto other = [&](std::uint32_t p, std::uint32_t t) { return other_triangle(g, p, t); };
  const auto usable = [&](std::uint32_t p) { return g.pairs[p].kind == PairKind::real; };
  std::vector<int> depth(n, -1);
  std::vector<std::uint32_t> queue;
  for (std::uint32_t t = 0; t < n; ++t)
    if (mate[t] == kUnmatched) {
      depth[t] = 0;
      queue.push_back(t);
    }
  if (queue.empty()) return 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t t = queue[head];
    if (depth[t] >= radius) continue;
    const auto reach = [&](std::uint32_t u) {
      if (depth[u] >= 0) return;
      depth[u] = depth[t] + 1;
      queue.push_back(u);
    };
    for (std::uint32_t i = g.offsets[t]; i < g.offsets[t + 1]; ++i) {
      const std::uint32_t p = g.incident[i];
      if (!usable(p)) continue;
      const std::uint32_t u = other(p, t);
      reach(u);
      if (mate[u] != kUnmatched) reach(other(mate[u], u));  // pairs stay whole
    }
  }
  // Pieces: connected sets of the marked triangles by usable pairs, in order of their lowest.
  std::vector<std::uint32_t> piece_of(n, kUnmatched), members;
  std::size_t paired = 0;
  std::sort(queue.begin(), queue.end());
  for (std::uint32_t seed : queue) {
    if (piece_of[seed] != kUnmatched) continue;
    members.assign(1, seed);
    piece_of[seed] = seed;
    std::size_t unpaired = 0;
    for (std::size_t head = 0; head < members.size(); ++head) {
      const std::uint32_t t = members[head];
      unpaired += mate[t] == kUnmatched;
      for (std::uint32_t i = g.offsets[t]; i < g.offsets[t + 1]; ++i) {
        const std::uint32_t p = g.incident[i], u = other(p, t);
        if (usable(p) && depth[u] >= 0 && piece_of[u] == kUnmatched) {
          piece_of[u] = seed;
          members.push_back(u);
        }
      }
    }
    if (unpaired == 0 || members.size() % 2 != 0) continue;
    std::sort(members.begin(), members.end());
    const auto local = [&](std::uint32_t t) {
      return static_cast<std::uint32_t>(std::lower_bound(members.begin(), members.end(), t) - members.begin());
    };
    std::vector<CostEdge> edges;
    std::vector<std::uint32_t> pair_of;
    for (std::uint32_t t : members)
      for (std::uint32_t i = g.offsets[t]; i < g.offsets[t + 1]; ++i) {
        const std::uint32_t p = g.incident[i];
        if (usable(p) && g.pairs[p].t0 == t && piece_of[g.pairs[p].t1] == seed) {
          edges.push_back({local(t), local(g.pairs[p].t1), -matching_weight(g.pairs[p].cost)});
          pair_of.push_back(p);
        }
      }
    std::vector<char> matched;
    if (!min_cost_perfect_matching(static_cast<std::uint32_t>(members.size()), edges, matched)) continue;
    for (std::size_t k = 0; k < edges.size(); ++k)
      if (matched[k]) mate[g.pairs[pair_of[k]].t0] = mate[g.pairs[pair_of[k]].t1] = pair_of[k];
    paired += unpaired;
  }
  return paired;
}

// Alternating trees grown from all free triangles at once, breadth first (one sweep of the
// graph per round): where two trees meet, the path from one root through the meeting pair
// to the other is swapped, and both trees stop for the round, so the round's paths share no
// triangle. For partners far apart, where a search from each free triangle would cover an
// area each; the paths are the fewest pairs, not the cheapest. Rounds go on while one pairs.
std::size_t trees_together(const DualGraph& g, std::vector<std::uint32_t>& mate, int max_rounds) {
  const std::uint32_t n = g.num_triangles;
  const auto other = [&](std::uint32_t p, std::uint32_t t) { return other_triangle(g, p, t); };
  std::size_t paired = 0;
  std::vector<std::uint32_t> tree(n), reached_by(n), queue;
  std::vector<char> inner(n), done;  // per tree (its root): augmented this round
  for (int round = 0; round < max_rounds; ++round) {
    std::fill(tree.begin(), tree.end(), kUnmatched);
    std::fill(inner.begin(), inner.end(), 0);
    done.assign(n, 0);
    queue.clear();
    for (std::uint32_t t = 0; t < n; ++t)
      if (mate[t] == kUnmatched) {
        tree[t] = t;
        queue.push_back(t);
      }
    // Swaps the path from x back to its root, x taking pair `gained` (as paths() does).
    const auto swap_to_root = [&](std::uint32_t x, std::uint32_t gained) {
      while (true) {
        const std::uint32_t given_up = mate[x];
        mate[x] = gained;
        if (given_up == kUnmatched) return;
        const std::uint32_t y = other(given_up, x);
        gained = reached_by[y];
        mate[y] = gained;
        x = other(gained, y);
      }
    };
    const std::size_t before = paired;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t x = queue[head];
      if (done[tree[x]]) continue;
      for (std::uint32_t i = g.offsets[x]; i < g.offsets[x + 1] && !done[tree[x]]; ++i) {
        const std::uint32_t p = g.incident[i];
        if (g.pairs[p].kind != PairKind::real || p == mate[x]) continue;
        const std::uint32_t y = other(p, x);
        if (tree[y] == kUnmatched) {  // matched, in no tree yet: y inner, its mate outer
          const std::uint32_t z = other(mate[y], y);
          if (tree[z] != kUnmatched) continue;
          tree[y] = tree[z] = tree[x];
          inner[y] = 1;
          reached_by[y] = p;
          queue.push_back(z);
        } else if (tree[y] != tree[x] && !done[tree[y]] && !inner[y]) {
          // y is outer in another live tree (its root, or an inner's mate): meet.
          done[tree[x]] = done[tree[y]] = 1;
          swap_to_root(x, p);
          swap_to_root(y, p);
          paired += 2;
        }
      }
    }
    if (paired == before) break;
  }
  return paired;
}

// Per triangle: its pair in m, or kUnmatched.
std::vector<std::uint32_t> mates_of(const DualGraph& g, const Matching& m) {
  std::vector<std::uint32_t> mate(g.num_triangles, kUnmatched);
  for (std::uint32_t p : m.pairs) mate[g.pairs[p].t0] = mate[g.pairs[p].t1] = p;
  return mate;
}

// m rebuilt from the mates (pairs ascending, their cost summed in that order).
void set_matching(const DualGraph& g, const std::vector<std::uint32_t>& mate, Matching& m) {
  m.pairs.clear();
  for (std::uint32_t t = 0; t < g.num_triangles; ++t)
    if (mate[t] != kUnmatched && g.pairs[mate[t]].t0 == t) m.pairs.push_back(mate[t]);
  std::sort(m.pairs.begin(), m.pairs.end());
  m.cost = 0.0;
  for (std::uint32_t p : m.pairs) m.cost += g.pairs[p].cost;
  m.perfect = 2 * m.pairs.size() == g.num_triangles;
}

}  // namespace

std::size_t pair_along_paths(const DualGraph& g, Matching& m, std::size_t max_visits) {
  std::vector<std::uint32_t> mate = mates_of(g, m);
  const std::size_t paired = paths(g, mate, max_visits);
  if (paired > 0) set_matching(g, mate, m);
  return paired;
}

std::size_t pair_in_neighbourhoods(const DualGraph& g, Matching& m, int radius) {
  std::vector<std::uint32_t> mate = mates_of(g, m);
  const std::size_t paired = neighbourhoods(g, mate, radius);
  if (paired > 0) set_matching(g, mate, m);
  return paired;
}

std::size_t pair_by_trees(const DualGraph& g, Matching& m, int max_rounds) {
  std::vector<std::uint32_t> mate = mates_of(g, m);
  const std::size_t paired = trees_together(g, mate, max_rounds);
  if (paired > 0) set_matching(g, mate, m);
  return paired;
}

std::size_t pair_leftovers(const DualGraph& g, Matching& m) {
  std::vector<std::uint32_t> mate = mates_of(g, m);
  const std::size_t paired = paths(g, mate, 256) + neighbourhoods(g, mate, 4) + trees_together(g, mate, 32) +
                             neighbourhoods(g, mate, 16) + neighbourhoods(g, mate, 64);
  if (paired > 0) set_matching(g, mate, m);
  return paired;
}

}  // namespace quadval::recombine_detail
