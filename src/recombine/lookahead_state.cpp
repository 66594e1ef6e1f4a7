#include "lookahead_state.hpp"

#include <algorithm>
#include <numeric>

#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

// The edge of t joining nodes u and v (corners k, k+1), or -1.
int edge_of(const std::array<NodeIndex, 3>& t, NodeIndex u, NodeIndex v) {
  for (int k = 0; k < 3; ++k) {
    const NodeIndex x = t[k], y = t[(k + 1) % 3];
    if ((x == u && y == v) || (x == v && y == u)) return k;
  }
  return -1;
}

NodeIndex find_compress(std::vector<NodeIndex>& parent, NodeIndex v) {
  NodeIndex root = v;
  while (parent[root] != root) root = parent[root];
  while (parent[v] != root) {
    const NodeIndex next = parent[v];
    parent[v] = root;
    v = next;
  }
  return root;
}

// Genus-0 check of every dual component: 2 - b - (V - E + F) == 0 with b the boundary loops,
// and every boundary node of a component on exactly two of its boundary edges (manifold).
bool all_components_genus_zero(const LookaheadGraph& g, const std::vector<NodeIndex>& root) {
  const std::uint32_t nt = g.num_triangles;
  std::vector<char> seen(nt, 0);
  std::vector<std::uint32_t> node_stamp(g.num_nodes, 0), boundary_count(g.num_nodes, 0),
      loop_stamp(g.num_nodes, 0);
  std::vector<std::uint32_t> stack, members;
  std::uint32_t component = 0;
  for (std::uint32_t start = 0; start < nt; ++start) {
    if (seen[start]) continue;
    ++component;
    members.clear();
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      members.push_back(t);
      for (std::uint32_t u : g.neighbor[t])
        if (u != kNone && !seen[u]) {
          seen[u] = 1;
          stack.push_back(u);
        }
    }
    long long vertices = 0, boundary_edges = 0, loops = 0;
    for (std::uint32_t t : members)
      for (int k = 0; k < 3; ++k) {
        const NodeIndex v = g.triangles[t][k];
        if (node_stamp[v] != component) {
          node_stamp[v] = component;
          boundary_count[v] = 0;
          ++vertices;
        }
      }
    for (std::uint32_t t : members)
      for (int k = 0; k < 3; ++k) {
        if (g.neighbor[t][k] != kNone) continue;
        ++boundary_edges;
        ++boundary_count[g.triangles[t][k]];
        ++boundary_count[g.triangles[t][(k + 1) % 3]];
      }
    for (std::uint32_t t : members)
      for (int k = 0; k < 3; ++k) {
        const NodeIndex v = g.triangles[t][k];
        if (boundary_count[v] != 0 && boundary_count[v] != 2) return false;
        if (boundary_count[v] == 2 && loop_stamp[root[v]] != component) {
          loop_stamp[root[v]] = component;
          ++loops;
        }
      }
    const long long faces = static_cast<long long>(members.size());
    const long long edges = (3 * faces + boundary_edges) / 2;
    if (2 - loops - (vertices - edges + faces) != 0) return false;
  }
  return true;
}

}  // namespace

LookaheadGraph build_lookahead_graph(const DualGraph& dg,
                                     std::span<const std::array<NodeIndex, 3>> triangles,
                                     std::size_t num_nodes) {
  LookaheadGraph g;
  g.num_triangles = static_cast<std::uint32_t>(triangles.size());
  QV_ASSERT(dg.num_triangles == g.num_triangles, "dual graph of another mesh");
  g.num_nodes = num_nodes;
  g.triangles.assign(triangles.begin(), triangles.end());
  g.neighbor.assign(g.num_triangles, {kNone, kNone, kNone});
  g.pair_at.assign(g.num_triangles, {kNone, kNone, kNone});
  g.pairs.assign(dg.pairs.begin(), dg.pairs.begin() + static_cast<std::ptrdiff_t>(dg.num_real));
  g.reward.resize(g.pairs.size());
  for (std::uint32_t p = 0; p < g.pairs.size(); ++p) {
    const TrianglePair& q = g.pairs[p];
    g.reward[p] = 1.0 - q.cost;
    const auto& t0 = g.triangles[q.t0];
    const int k1 = edge_of(g.triangles[q.t1], t0[q.t0_edge], t0[(q.t0_edge + 1) % 3]);
    QV_ASSERT(k1 >= 0, "pair " << p << " does not share t0's edge");
    g.neighbor[q.t0][q.t0_edge] = q.t1;
    g.pair_at[q.t0][q.t0_edge] = p;
    g.neighbor[q.t1][k1] = q.t0;
    g.pair_at[q.t1][k1] = p;
  }
  g.boundary_node.assign(num_nodes, 0);
  g.initial_parent.resize(num_nodes);
  std::iota(g.initial_parent.begin(), g.initial_parent.end(), NodeIndex{0});
  for (std::uint32_t t = 0; t < g.num_triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      if (g.neighbor[t][k] != kNone) continue;
      const NodeIndex u = g.triangles[t][k], v = g.triangles[t][(k + 1) % 3];
      g.boundary_node[u] = g.boundary_node[v] = 1;
      const NodeIndex ru = find_compress(g.initial_parent, u),
                      rv = find_compress(g.initial_parent, v);
      if (ru != rv) g.initial_parent[std::max(ru, rv)] = std::min(ru, rv);
    }
  for (NodeIndex v = 0; v < num_nodes; ++v) find_compress(g.initial_parent, v);
  g.node_offsets.assign(num_nodes + 1, 0);
  for (const auto& t : g.triangles)
    for (NodeIndex v : t) ++g.node_offsets[v + 1];
  for (std::size_t v = 0; v < num_nodes; ++v) g.node_offsets[v + 1] += g.node_offsets[v];
  g.node_triangles.resize(g.node_offsets.back());
  std::vector<std::uint32_t> fill(g.node_offsets.begin(), g.node_offsets.end() - 1);
  for (std::uint32_t t = 0; t < g.num_triangles; ++t)
    for (NodeIndex v : g.triangles[t]) g.node_triangles[fill[v]++] = t;
  g.planar_rule = all_components_genus_zero(g, g.initial_parent);
  return g;
}

std::array<NodeIndex, 4> lookahead_quad(const LookaheadGraph& g, std::uint32_t p) {
  const TrianglePair& q = g.pairs[p];
  return quad_of_pair(g.triangles[q.t0], q.t0_edge, g.triangles[q.t1]);
}

LookaheadState::LookaheadState(const LookaheadGraph& g)
    : g_(&g),
      free_(g.num_triangles, 1),
      quads_at_(g.num_nodes, 0),
      parent_(g.initial_parent),
      size_(g.num_nodes, 1),
      tentative_(g.num_nodes, 0),
      stamp_(g.num_triangles, 0),
      owner_(g.num_triangles, 0) {
  for (NodeIndex v = 0; v < g.num_nodes; ++v)
    if (parent_[v] != v) ++size_[parent_[v]];
}

NodeIndex LookaheadState::find(NodeIndex v) noexcept {
  // Settled links first, up to a root of the settled forest (a root, or a node linked
  // tentatively), compressing them; then the few tentative links (at most 3 per merge
  // applied since the last settle).
  NodeIndex r = v;
  while (parent_[r] != r && !tentative_[r]) r = parent_[r];
  while (v != r) {
    const NodeIndex next = parent_[v];
    parent_[v] = r;
    v = next;
  }
  while (parent_[r] != r) r = parent_[r];
  return r;
}

void LookaheadState::unite(NodeIndex a, NodeIndex b) {
  NodeIndex ra = find(a), rb = find(b);
  if (ra == rb) return;
  if (size_[ra] < size_[rb]) std::swap(ra, rb);
  parent_[rb] = ra;
  size_[ra] += size_[rb];
  tentative_[rb] = 1;
  union_log_.push_back(rb);
  ++unions_per_apply_.back();
}

int LookaheadState::free_neighbors(std::uint32_t t) const noexcept {
  int n = 0;
  for (std::uint32_t u : g_->neighbor[t]) n += (u != kNone && free_[u]) ? 1 : 0;
  return n;
}

void LookaheadState::apply(std::uint32_t p) {
  QV_ASSERT(available(p), "pair " << p << " is not available");
  const TrianglePair& q = g_->pairs[p];
  free_[q.t0] = free_[q.t1] = 0;
  const auto quad = lookahead_quad(*g_, p);
  for (NodeIndex v : quad) ++quads_at_[v];
  unions_per_apply_.push_back(0);
  unite(quad[0], quad[1]);
  unite(quad[0], quad[2]);
  unite(quad[0], quad[3]);
  applied_.push_back(p);
  quality_ += g_->reward[p];
}

void LookaheadState::undo() {
  QV_ASSERT(applied_.size() > settled_, "nothing to undo");
  const std::uint32_t p = applied_.back();
  applied_.pop_back();
  for (int i = unions_per_apply_.back(); i > 0; --i) {
    const NodeIndex child = union_log_.back();
    union_log_.pop_back();
    size_[parent_[child]] -= size_[child];
    parent_[child] = child;
    tentative_[child] = 0;
  }
  unions_per_apply_.pop_back();
  for (NodeIndex v : lookahead_quad(*g_, p)) --quads_at_[v];
  const TrianglePair& q = g_->pairs[p];
  free_[q.t0] = free_[q.t1] = 1;
  quality_ -= g_->reward[p];
}

void LookaheadState::settle() {
  for (NodeIndex child : union_log_) tentative_[child] = 0;
  union_log_.clear();
  unions_per_apply_.clear();
  settled_ = applied_.size();
}

int LookaheadState::allowed_options(std::uint32_t t, std::array<std::uint32_t, 3>* out) {
  int n = 0;
  for (std::uint32_t p : g_->pair_at[t])
    if (p != kNone && allowed(p)) {
      if (out) (*out)[n] = p;
      ++n;
    }
  return n;
}

bool LookaheadState::allowed(std::uint32_t p) {
  if (!available(p)) return false;
  const TrianglePair& q = g_->pairs[p];
  const auto& t0 = g_->triangles[q.t0];
  const auto& t1 = g_->triangles[q.t1];
  const int k = q.t0_edge;
  const NodeIndex a = t0[k], b = t0[(k + 1) % 3], c = t0[(k + 2) % 3];
  NodeIndex d = t1[0];
  for (NodeIndex v : t1)
    if (v != a && v != b) d = v;
  // Around Q = (a, d, b, c): corner i, then edge (corner i, corner i+1).
  const std::array<NodeIndex, 4> corner{a, d, b, c};
  const std::array<std::uint32_t, 4> across{
      g_->neighbor[q.t1][edge_of(t1, a, d)], g_->neighbor[q.t1][edge_of(t1, d, b)],
      g_->neighbor[q.t0][(k + 1) % 3], g_->neighbor[q.t0][(k + 2) % 3]};
  std::array<char, 8> closed{};
  int start = -1;
  for (int i = 0; i < 4; ++i) {
    closed[2 * i] = closed_corner(corner[i]) ? 1 : 0;
    closed[2 * i + 1] = (across[i] == kNone || !free_[across[i]]) ? 1 : 0;
  }
  // Start at the first item of a closed run (a corner: a closed edge closes its ends).
  for (int pos = 0; pos < 8 && start < 0; pos += 2)
    if (closed[pos] && !closed[(pos + 7) % 8]) start = pos;
  if (start < 0) return true;  // nothing closed, or everything: Q touches one component
  std::array<NodeIndex, 4> run_component{};   // closed run i
  std::array<std::uint32_t, 4> seed{};        // arc i: between closed runs i and i+1
  int runs = 0;
  bool in_closed = false;
  for (int j = 0; j < 8; ++j) {
    const int pos = (start + j) % 8;
    if (closed[pos]) {
      if (!in_closed) {
        run_component[runs++] = find(corner[pos / 2]);  // pos even: the run starts at a corner
        QV_ASSERT(pos % 2 == 0, "closed run starting at an edge");
        in_closed = true;
      }
    } else {
      if (in_closed) seed[runs - 1] = kNone;
      in_closed = false;
      if (pos % 2 == 1 && seed[runs - 1] == kNone) seed[runs - 1] = across[pos / 2];
    }
  }
  if (runs <= 1) return true;  // (a)
  std::array<int, 4> group{0, 1, 2, 3};
  if (g_->planar_rule) {  // (b)
    bool shared = false;
    for (int i = 0; i < runs; ++i)
      for (int j = i + 1; j < runs; ++j) shared |= run_component[i] == run_component[j];
    if (!shared) return true;
    // Arcs i < j are separated iff runs i+1..j and runs j+1..i (cyclic) share a component.
    for (int i = 0; i < runs; ++i)
      for (int j = i + 1; j < runs; ++j) {
        bool separated = false;
        for (int r = i + 1; r <= j && !separated; ++r)
          for (int s = j + 1; s <= i + runs && !separated; ++s)
            separated = run_component[r] == run_component[s % runs];
        if (!separated) {
          const int from = group[j], to = group[i];
          for (int m = 0; m < runs; ++m)
            if (group[m] == from) group[m] = to;
        }
      }
    bool one = true;
    for (int i = 1; i < runs; ++i) one &= group[i] == group[0];
    if (one) return true;
  }
  return !odd_part(seed, group, runs, q.t0, q.t1);  // (c)
}

bool LookaheadState::odd_part(const std::array<std::uint32_t, 4>& seeds, std::array<int, 4> group,
                              int arcs, std::uint32_t t0, std::uint32_t t1) {
  if (++epoch_ == 0) {  // wrapped: clear the stamps
    std::fill(stamp_.begin(), stamp_.end(), 0u);
    epoch_ = 1;
  }
  const auto root = [&](int i) {
    while (group[i] != i) i = group[i];
    return i;
  };
  // Groups from (b) as a forest: each arc points at the lowest arc with its label.
  const std::array<int, 4> label = group;
  for (int i = 0; i < arcs; ++i) {
    group[i] = i;
    for (int j = 0; j < i; ++j)
      if (label[j] == label[i]) {
        group[i] = j;
        break;
      }
  }
  std::array<std::size_t, 4> head{}, count{};
  std::array<char, 4> finished{};
  for (int i = 0; i < arcs; ++i) queue_[i].clear();
  for (int i = 0; i < arcs; ++i) {
    const std::uint32_t s = seeds[i];
    if (stamp_[s] == epoch_) {
      const int a = root(owner_[s]), b = root(i);
      if (a != b) group[std::max(a, b)] = std::min(a, b);
      continue;
    }
    stamp_[s] = epoch_;
    owner_[s] = static_cast<std::uint8_t>(i);
    queue_[i].push_back(s);
    ++count[i];
  }
  while (true) {
    int alive = 0;
    for (int r = 0; r < arcs; ++r) {
      if (root(r) != r || finished[r]) continue;
      bool open = false;
      std::size_t total = 0;
      for (int i = 0; i < arcs; ++i)
        if (root(i) == r) {
          open |= head[i] < queue_[i].size();
          total += count[i];
        }
      if (open) {
        ++alive;
      } else {
        finished[r] = 1;
        if (total % 2 == 1) return true;
      }
    }
    if (alive <= 1) return false;
    for (int i = 0; i < arcs; ++i) {
      if (head[i] >= queue_[i].size()) continue;
      const std::uint32_t t = queue_[i][head[i]++];
      ++search_steps_;
      for (std::uint32_t u : g_->neighbor[t]) {
        if (u == kNone || !free_[u] || u == t0 || u == t1) continue;
        if (stamp_[u] == epoch_) {
          const int a = root(owner_[u]), b = root(i);
          if (a != b) group[std::max(a, b)] = std::min(a, b);
          continue;
        }
        stamp_[u] = epoch_;
        owner_[u] = static_cast<std::uint8_t>(i);
        queue_[i].push_back(u);
        ++count[i];
      }
    }
  }
}

}  // namespace quadval::recombine_detail
