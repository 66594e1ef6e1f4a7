// Edmonds' blossom algorithm for min-cost perfect matching, Blossom V style (see the header).
//
// LP and duals (the "inside" form of Edmonds' odd-set constraints): vertex duals y_v (free
// sign) and blossom duals z_B >= 0; the reduced cost of an edge between two different
// top-level nodes is c_e - y_u - y_v (no blossom contains both ends), and the edges inside a
// blossom stay tight because z_B moves by twice the change of its vertices' duals.
//
// Integrality: costs are doubled on input and every root starts with an even dual. Then the
// dual of every vertex in a tree is congruent to eps (the running dual offset) mod 2: a vertex
// joins a tree through a tight edge of even cost, so with the parity of its neighbour, and
// "+" and "-" move by +-delta, the same parity. So every "+"-"+" slack is even and the step
// that closes it (half the slack) is an integer.
//
// Trees: every free vertex after the greedy start roots a tree; all trees grow together by
// the same dual step (Blossom V's "multiple trees, fixed delta"). Lazy duals: a node in a tree
// stores `join` = eps when it got its label; its true dual is the stored one plus (eps - join)
// for "+" and minus that for "-". Stored values are brought up to date ("settled") when a node
// leaves the top level (shrink, expand) or its tree dissolves after an augmentation. Event keys
// are then constants while they stay valid:
//   grow   ("+" to a node in no tree):         at eps = eps_now + slack
//   "+"-"+" (shrink in one tree, else augment): at 2 eps = 2 eps_now + slack
//   expand (a "-" blossom whose z reaches 0):   at eps = eps_now + z/2
// and stale queue entries are recognised by recomputing the key when they surface. An entry
// surfaces no later than its edge becomes tight, since a slack falls by at most 1 per unit of
// eps at a free end and 2 between "+" ends; so a surfacing "+"-free edge whose key is stale is
// queued again with its current key, and a "+"-"+" entry whose other end has been freed
// becomes that edge's grow event (dissolve relies on both). Ties go
// first to "+"-"+" events, then in the order queued (breadth first): on meshes, where many
// edges become tight at once, this keeps trees small (measured: 3x less work than by edge id).
//
// Vertex groups make settling O(1) and shrinking O(smaller children) (union by size), and
// per-group boundary lists make queueing a big blossom's edges cost its boundary, not its size.
//
// The blossom bookkeeping (children cycle with its connecting edge endpoints, base at child 0,
// the matching inside a blossom on children (1,2), (3,4), ...; labels by the endpoint through
// which a node was reached) follows Edmonds' algorithm as described by Galil (1986),
// "Efficient algorithms for finding maximum matching in graphs", ACM Comput. Surv. 18(1).
#include "blossom_solver.hpp"

#include <algorithm>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>

#include "event_queue.hpp"
#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

constexpr std::int32_t kNone = -1;
constexpr std::uint32_t kNoTree = 0xffffffffu;

enum Label : std::int8_t { kFree = 0, kPlus = 1, kMinus = 2 };

class Solver {
 public:
  Solver(std::uint32_t n, std::span<const CostEdge> edges, const MatchingProgress& progress)
      : n_(n), edges_(edges.begin(), edges.end()), progress_(progress) {
    std::vector<std::uint32_t> degree(n + 1, 0);
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const CostEdge& ce = edges[e];
      QV_ASSERT(ce.cost <= kMaxMatchingCost && ce.cost >= -kMaxMatchingCost,
                "edge cost " << ce.cost);
      edges_[e].cost = 2 * ce.cost;
      ++degree[ce.u + 1];
      ++degree[ce.v + 1];
    }
    offsets_.assign(n + 1, 0);
    for (std::uint32_t v = 0; v < n; ++v) offsets_[v + 1] = offsets_[v] + degree[v + 1];
    incident_.resize(offsets_[n]);
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::uint32_t e = 0; e < edges.size(); ++e) {
      incident_[fill[edges[e].u]++] = {static_cast<std::int32_t>(2 * e), edges[e].v};
      incident_[fill[edges[e].v]++] = {static_cast<std::int32_t>(2 * e + 1), edges[e].u};
    }
    slot_.resize(n);
    num_groups_ = num_nodes_ = n;
    group_of_.resize(n);
    for (std::uint32_t v = 0; v < n; ++v) slot_[v].group = slot_[v].top = group_of_[v] = v;
    boundary_.resize(n);
    listed_in_.assign(n, kNoTree);
    size_.assign(n, 1);
    big_child_.assign(n, 0);
    for (std::uint32_t v = 0; v < n; ++v) slot_[v].base = v;
    z_.assign(n, 0);
    mark_.assign(n, 0);
  }

  /// The greedy start and one tree per vertex it leaves free; false when no perfect matching
  /// can exist (odd count, an isolated vertex). Then finish() solves.
  bool start() {
    if (n_ % 2 != 0) return false;
    const std::vector<std::uint32_t> visit = breadth_first_visit();
    if (!greedy_init(visit)) return false;
    eps_ = 0;
    for (std::uint32_t r : visit) {
      if (slot_[r].mate != kNone) continue;
      const auto t = static_cast<std::uint32_t>(tree_end_.size());
      tree_end_.push_back(0);
      ended_.push_back(0);
      parked_.emplace_back();
      ++alive_trees_;
      assign_plus(r, kNone, t);
    }
    free_at_start_ = alive_trees_;
    if (progress_) progress_(0, free_at_start_);
    return true;
  }
  /// false when the graph has no perfect matching.
  bool finish() { return grow_trees(); }
  std::uint32_t free_at_start() const { return free_at_start_; }

  void read(std::vector<char>& matched) const {
    matched.assign(edges_.size(), 0);
    for (std::uint32_t v = 0; v < n_; ++v)
      if (slot_[v].mate != kNone) matched[static_cast<std::uint32_t>(slot_[v].mate) >> 1] = 1;
  }

 private:
  // Empties a list whose id will be reused, keeping its memory unless it is large. On
  // uniform meshes, freeing and growing again the lists of the groups and blossoms that
  // shrinks and expands make and drop took a tenth of the solver's time in malloc and free
  // (perf); uniform-100k-a6's matching 6.5 -> 5.4 s (medians of 5 alternating runs),
  // square-hole-1M 9.0 -> 8.7 s (within the noise), the same matching.
  template <class T>
  static void recycle(std::vector<T>& list) {
    constexpr std::size_t kKeep = 256;
    if (list.capacity() > kKeep)
      std::vector<T>().swap(list);
    else
      list.clear();
  }

  // --- Graph ---
  std::uint32_t vertex(std::int32_t p) const {
    const CostEdge& e = edges_[static_cast<std::uint32_t>(p) >> 1];
    return (p & 1) ? e.v : e.u;
  }
  // v's mate is the vertex of endpoint p (partner = vertex(p), when the caller knows it).
  void set_mate(std::uint32_t v, std::int32_t p, std::uint32_t partner) {
    slot_[v].mate = p;
    slot_[v].mate_vertex = partner;
  }
  void set_mate(std::uint32_t v, std::int32_t p) { set_mate(v, p, vertex(p)); }
  static std::int32_t endpoint(std::uint32_t e, std::uint32_t from_vertex, const CostEdge& ce) {
    return static_cast<std::int32_t>(2 * e + (ce.u == from_vertex ? 0 : 1));
  }
  bool is_blossom(std::uint32_t b) const { return b >= n_; }

  // --- Vertex groups and lazy duals ---
  std::uint32_t outer(std::uint32_t v) const { return slot_[slot_[v].group].top; }
  std::int64_t dual(std::uint32_t v) const { return slot_[v].y + slot_[slot_[v].group].offset; }
  void adopt_groups(std::uint32_t b, const std::vector<std::uint32_t>& children) {
    std::uint32_t big = children[0];
    size_[b] = 0;
    for (std::uint32_t c : children) {
      size_[b] += size_[c];
      if (size_[c] > size_[big]) big = c;
    }
    const std::uint32_t g = group_of_[big];
    for (std::uint32_t c : children) {
      if (c == big) continue;
      const std::uint32_t gc = group_of_[c];
      const std::int64_t shift = slot_[gc].offset - slot_[g].offset;
      for_leaves(c, [&](std::uint32_t v) {
        slot_[v].y += shift;
        slot_[v].group = g;
        listed_in_[v] = kNoTree;  // its old group's list is dropped (and the id reused)
      });
      recycle(boundary_[gc]);
      free_groups_.push_back(gc);
    }
    if (!is_blossom(big) && crosses(big)) list_boundary(big, g);
    for (std::uint32_t c : children)
      if (c != big)
        for_leaves(c, [&](std::uint32_t v) {
          if (crosses(v)) list_boundary(v, g);
        });
    slot_[g].top = b;
    group_of_[b] = g;
    big_child_[b] = big;
  }
  void split_groups(std::uint32_t b, const std::vector<std::uint32_t>& children) {
    const std::uint32_t g = group_of_[b];
    for (std::uint32_t c : children) {
      if (c == big_child_[b]) {
        slot_[g].top = c;
        group_of_[c] = g;
        continue;
      }
      std::uint32_t gc;
      if (!free_groups_.empty()) {
        gc = free_groups_.back();
        free_groups_.pop_back();
      } else {
        gc = num_groups_++;
        if (slot_.size() < num_groups_) slot_.emplace_back();
        boundary_.emplace_back();
      }
      slot_[gc].offset = slot_[g].offset;
      slot_[gc].top = c;
      group_of_[c] = gc;
      for_leaves(c, [&](std::uint32_t v) {
        slot_[v].group = gc;
        listed_in_[v] = kNoTree;  // gc may be a reused id whose old list is gone
      });
    }
    // The new groups list their boundary; the big child's list gains its vertices next to them.
    for (std::uint32_t c : children) {
      if (c == big_child_[b]) continue;
      for_leaves(c, [&](std::uint32_t v) {
        if (crosses(v)) list_boundary(v, slot_[v].group);
        for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
          const std::uint32_t w = incident_[i].other;
          if (slot_[w].group == g) list_boundary(w, g);
        }
      });
    }
  }
  // Boundary lists: each group lists (at least) its vertices with an edge leaving the group, so
  // that queueing a big blossom's edges costs its boundary, not its size. Entries that stopped
  // qualifying are dropped when the list is next walked.
  bool crosses(std::uint32_t v) const {
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i)
      if (slot_[incident_[i].other].group != slot_[v].group) return true;
    return false;
  }
  void list_boundary(std::uint32_t v, std::uint32_t g) {
    if (listed_in_[v] == g) return;
    listed_in_[v] = g;
    boundary_[g].push_back(v);
  }
  template <class F>
  void for_boundary(std::uint32_t b, F&& f) {
    if (!is_blossom(b)) {
      f(b);  // a vertex's group is the vertex: no list
      return;
    }
    const std::uint32_t g = group_of_[b];
    std::vector<std::uint32_t>& list = boundary_[g];
    std::size_t keep = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::uint32_t v = list[i];
      if (slot_[v].group != g || listed_in_[v] != g) continue;  // moved away, or a stale copy
      if (!crosses(v)) {
        listed_in_[v] = kNoTree;
        continue;
      }
      list[keep++] = v;
    }
    list.resize(keep);
    for (std::uint32_t v : list) f(v);
  }
  // The dual change node b has pending since it joined its tree: up to now, or up to the
  // augmentation that ended its tree (whose nodes keep their labels, see dissolve).
  std::int64_t lazy(std::uint32_t b) const {
    const Slot& s = slot_[b];
    if (s.label == kFree) return 0;
    const std::int64_t now = ended(s.tree) ? tree_end_[s.tree] : eps_;
    return s.label == kPlus ? now - s.join : s.join - now;
  }
  // b's label; free where its tree has ended.
  Label label_of(std::uint32_t b) const {
    const Slot& s = slot_[b];
    return s.label != kFree && ended(s.tree) ? kFree : s.label;
  }
  // A node of an ended tree leaves it: its pending dual change written into the stored duals.
  void retire(std::uint32_t b) {
    QV_ASSERT(ended(slot_[b].tree), "node " << b << " of a live tree joins another");
    settle(b);
    slot_[b].label = kFree;
    slot_[b].labelend = kNone;
    slot_[b].tree = kNoTree;
  }
  // The slack of edge e = (v, w), whose outer nodes b = outer(v) and other = outer(w) the
  // caller has found already.
  std::int64_t slack(std::uint32_t e, std::uint32_t v, std::uint32_t b, std::uint32_t w,
                     std::uint32_t other) const {
    return edges_[e].cost - dual(v) - dual(w) - lazy(b) - lazy(other);
  }
  template <class F>
  void for_leaves(std::uint32_t b, F&& f) {
    if (!is_blossom(b)) {
      f(b);
      return;
    }
    stack_.clear();
    stack_.push_back(b);
    while (!stack_.empty()) {
      const std::uint32_t t = stack_.back();
      stack_.pop_back();
      if (!is_blossom(t)) {
        f(t);
        continue;
      }
      for (std::uint32_t c : kids(t)) stack_.push_back(c);
    }
  }
  // Writes the node's pending dual change into the stored duals (its vertices and itself).
  void settle(std::uint32_t b) {
    const std::int64_t d = lazy(b);
    if (d != 0) {
      slot_[group_of_[b]].offset += d;
      if (is_blossom(b)) z_[b] += 2 * d;
    }
    slot_[b].join = eps_;
  }

  // The vertices in breadth-first order (from the lowest unvisited vertex of each component):
  // the order in which the greedy start visits them and the trees are made. The memory keeps
  // the caller's order (see component_order), but the visiting order sets which vertices the
  // start leaves free and the order of the events, hence how much work follows. Counted by
  // cachegrind, against visiting in memory order: uniform-100k 8.80G -> 7.59G instructions,
  // L1 data misses 146M -> 125M; square-hole-1M the same within 1% (its 72M last-level
  // misses, a 32 MiB cache simulated, unchanged).
  std::vector<std::uint32_t> breadth_first_visit() const {
    std::vector<std::uint32_t> visit;
    visit.reserve(n_);
    std::vector<char> seen(n_, 0);
    for (std::uint32_t s = 0; s < n_; ++s) {
      if (seen[s]) continue;
      seen[s] = 1;
      const std::size_t first = visit.size();
      visit.push_back(s);
      for (std::size_t head = first; head < visit.size(); ++head) {
        const std::uint32_t v = visit[head];
        for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
          const std::uint32_t w = incident_[i].other;
          if (!seen[w]) {
            seen[w] = 1;
            visit.push_back(w);
          }
        }
      }
    }
    return visit;
  }

  // --- Initialisation (after Blossom V §5.1): y_v = min c / 2; then each free vertex v in
  // turn rises to its tightest edge and is matched there when the other end is free, or by a
  // tight three-edge path to a free vertex; else its dual stays (fewer tight edges into the
  // matched region keep the trees smaller: measured). ---
  bool greedy_init(const std::vector<std::uint32_t>& visit) {
    for (std::uint32_t v = 0; v < n_; ++v) {
      if (offsets_[v] == offsets_[v + 1]) return false;  // isolated: no perfect matching
      std::int64_t lo = edges_[incident_[offsets_[v]].edge()].cost;
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i)
        lo = std::min(lo, edges_[incident_[i].edge()].cost);
      slot_[v].y = lo / 2;
    }
    for (std::uint32_t v : visit) {
      if (slot_[v].mate != kNone) continue;
      std::int64_t best = 0;
      std::uint32_t best_edge = 0;
      bool found = false;
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
        const std::uint32_t e = incident_[i].edge();
        const CostEdge& ce = edges_[e];
        const std::int64_t s = edges_[e].cost - slot_[ce.u].y - slot_[ce.v].y;
        // The smallest slack sets how far y_v can rise; among equals prefer a free end.
        const std::uint32_t w = ce.u == v ? ce.v : ce.u;
        if (!found || s < best || (s == best && slot_[w].mate == kNone)) {
          best = s;
          best_edge = e;
          found = true;
        }
      }
      const CostEdge& ce = edges_[best_edge];
      const std::uint32_t w = ce.u == v ? ce.v : ce.u;
      if (slot_[w].mate == kNone) {
        slot_[v].y += best;
        set_mate(v, endpoint(best_edge, w, ce), w);
        set_mate(w, endpoint(best_edge, v, ce), v);
      } else {
        // Raised to its tightest edge, v may reach a free vertex by a tight path of three
        // edges v-w=x-z (w=x matched): swap that pair. Otherwise v's dual stays put, so
        // that fewer tight edges lead a tree into the matched region.
        slot_[v].y += best;
        if (!augment_short(v)) slot_[v].y -= best;
      }
    }
    // Every root's dual even (lowering a dual keeps all slacks >= 0): then the duals of all
    // tree vertices stay congruent to eps mod 2 and every "+"-"+" slack is even.
    for (std::uint32_t v = 0; v < n_; ++v)
      if (slot_[v].mate == kNone && (slot_[v].y & 1)) --slot_[v].y;
    return true;
  }

  bool augment_short(std::uint32_t v) {
    auto tight = [&](std::uint32_t e) {
      return edges_[e].cost == slot_[edges_[e].u].y + slot_[edges_[e].v].y;
    };
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
      const std::uint32_t e1 = incident_[i].edge(), w = incident_[i].other;
      if (!tight(e1)) continue;
      if (slot_[w].mate == kNone) continue;
      const std::uint32_t x = slot_[w].mate_vertex;
      for (std::uint32_t k = offsets_[x]; k < offsets_[x + 1]; ++k) {
        const std::uint32_t e2 = incident_[k].edge(), z = incident_[k].other;
        if (z == v || slot_[z].mate != kNone || !tight(e2)) continue;
        set_mate(v, endpoint(e1, w, edges_[e1]), w);
        set_mate(w, endpoint(e1, v, edges_[e1]), v);
        set_mate(x, endpoint(e2, z, edges_[e2]), z);
        set_mate(z, endpoint(e2, x, edges_[e2]), x);
        return true;
      }
    }
    return false;
  }

  // --- Tree growth ---
  // Queues the edges from vertex v of the "+" node b to other "+" nodes and to free nodes.
  void push_edges_of_plus_vertex(std::uint32_t v, std::uint32_t b) {
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
      const Incidence in = incident_[i];
      const std::uint32_t e = in.edge(), w = in.other;
      const std::uint32_t other = outer(w);
      if (other == b) continue;
      const Label lo = label_of(other);
      if (lo == kPlus)
        shrink_queue_.push(2 * eps_ + slack(e, v, b, w, other), e, 2 * eps_, in.u(v), in.v(v));
      else if (lo == kFree)
        grow_queue_.push(eps_ + slack(e, v, b, w, other), e, eps_, in.u(v), in.v(v));
      else if (slot_[other].tree != slot_[b].tree)
        parked_[slot_[other].tree].push_back(e);
    }
  }
  void push_edges_of_plus(std::uint32_t b) {
    for_boundary(b, [&](std::uint32_t v) { push_edges_of_plus_vertex(v, b); });
  }
  // Edges from a node that has just left the tree (expand) to the tree's "+" nodes.
  void push_edges_to_plus(std::uint32_t b) {
    for_boundary(b, [&](std::uint32_t v) {
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
        const Incidence in = incident_[i];
        const std::uint32_t e = in.edge(), w = in.other;
        const std::uint32_t other = outer(w);
        if (label_of(other) == kPlus)
          grow_queue_.push(eps_ + slack(e, v, b, w, other), e, eps_, in.u(v), in.v(v));
      }
    });
  }

  void enter_tree(std::uint32_t b, Label label, std::int32_t p, std::uint32_t t) {
    if (slot_[b].label != kFree) retire(b);
    slot_[b].label = label;
    slot_[b].labelend = p;
    slot_[b].join = eps_;
    slot_[b].tree = t;
  }
  void assign_plus(std::uint32_t b, std::int32_t p, std::uint32_t t) {
    enter_tree(b, kPlus, p, t);
    push_edges_of_plus(b);
  }
  // Labels b "-" (reached through endpoint p, whose vertex is in the parent), then its mate "+".
  void assign_minus(std::uint32_t b, std::int32_t p, std::uint32_t t) {
    enter_tree(b, kMinus, p, t);
    if (is_blossom(b)) expand_queue_.push(eps_ + z_[b] / 2, b, eps_);
    const Slot& base = slot_[slot_[b].base];
    QV_ASSERT(base.mate != kNone, "a '-' node without a mate");
    assign_plus(outer(base.mate_vertex), base.mate ^ 1, t);
  }

  // Drops stale entries from the top of each queue (their key no longer matches the state).
  void clean_grow() {
    while (!grow_queue_.empty()) {
      const EventQueue::Event ev = grow_queue_.top();
      const std::uint32_t a = outer(ev.u), b = outer(ev.v);
      const Label la = label_of(a), lb = label_of(b);
      if (a != b && ((la == kPlus && lb == kFree) || (la == kFree && lb == kPlus))) {
        const std::int64_t key = eps_ + slack(ev.id, ev.u, a, ev.v, b);
        if (key == ev.key) return;
        grow_queue_.pop();
        grow_queue_.push(key, ev.id, eps_, ev.u, ev.v);
        continue;
      }
      grow_queue_.pop();
      if (a != b) park(a, b, ev.id);
    }
  }
  void clean_shrink() {
    while (!shrink_queue_.empty()) {
      const EventQueue::Event ev = shrink_queue_.top();
      const std::uint32_t a = outer(ev.u), b = outer(ev.v);
      if (a != b && label_of(a) == kPlus && label_of(b) == kPlus &&
          2 * eps_ + slack(ev.id, ev.u, a, ev.v, b) == ev.key)
        return;
      shrink_queue_.pop();
      if (a == b) continue;
      const Label la = label_of(a), lb = label_of(b);
      if ((la == kPlus && lb == kFree) || (la == kFree && lb == kPlus))
        grow_queue_.push(eps_ + slack(ev.id, ev.u, a, ev.v, b), ev.id, eps_, ev.u, ev.v);
      else
        park(a, b, ev.id);
    }
  }
  // Parks edge e between a "+" node and a "-" node of another tree with the "-" node's tree,
  // whose dissolution turns it into a grow event. Every such edge is parked, or has an event
  // queued that parks it when it surfaces: the edge is found either by the scan of the node
  // that became "+" (push_edges_of_plus_vertex) or by its queued grow or "+"-"+" event, once
  // the other end has joined a tree as "-". This replaced a walk over all edges of the
  // dissolved nodes, which on uniform meshes mostly met the same tree's nodes (uniform-100k:
  // 13.6M nodes dissolved, 22% of the time).
  void park(std::uint32_t a, std::uint32_t b, std::uint32_t e) {
    if (label_of(a) == kMinus) std::swap(a, b);
    if (label_of(a) == kPlus && label_of(b) == kMinus && slot_[a].tree != slot_[b].tree)
      parked_[slot_[b].tree].push_back(e);
  }
  void clean_expand() {
    while (!expand_queue_.empty()) {
      const EventQueue::Event ev = expand_queue_.top();
      const std::uint32_t b = ev.id;
      if (b < num_nodes_ && alive(b) && slot_[b].parent == kNone && label_of(b) == kMinus &&
          eps_ + (z_[b] + 2 * lazy(b)) / 2 == ev.key)
        return;
      expand_queue_.pop();
    }
  }
  bool alive(std::uint32_t b) const { return !is_blossom(b) || !kids(b).empty(); }
  std::vector<std::uint32_t>& kids(std::uint32_t b) { return childs_[b - n_]; }
  const std::vector<std::uint32_t>& kids(std::uint32_t b) const { return childs_[b - n_]; }
  std::vector<std::int32_t>& ends(std::uint32_t b) { return endps_[b - n_]; }

  // All trees grow together by the same dual step (Blossom V's "multiple trees, fixed
  // delta"): two trees that touch augment and dissolve; the others keep going.
  bool grow_trees() {
    while (alive_trees_ > 0) {
      clean_grow();
      clean_shrink();
      clean_expand();
      constexpr std::int64_t kInf = std::numeric_limits<std::int64_t>::max();
      const std::int64_t t_grow = grow_queue_.empty() ? kInf : grow_queue_.top().key;
      std::int64_t t_shrink = kInf;
      if (!shrink_queue_.empty()) {
        QV_ASSERT(shrink_queue_.top().key % 2 == 0, "odd '+'-'+' slack: duals not integral");
        t_shrink = shrink_queue_.top().key / 2;
      }
      const std::int64_t t_expand = expand_queue_.empty() ? kInf : expand_queue_.top().key;
      const std::int64_t t = std::min({t_grow, t_shrink, t_expand});
      if (t == kInf) return false;  // no tree can grow: no perfect matching
      QV_ASSERT(t >= eps_, "dual step " << t - eps_ << " is negative");
      eps_ = t;
      // At equal keys, "+"-"+" events (augment, shrink) go first: growing a tree further
      // through tight edges when it already touches another tree only makes it bigger.
      if (t == t_shrink) {
        const EventQueue::Event ev = shrink_queue_.top();
        shrink_queue_.pop();
        const std::uint32_t e = ev.id;
        const std::uint32_t ta = slot_[outer(ev.u)].tree;
        const std::uint32_t tb = slot_[outer(ev.v)].tree;
        if (ta == tb) {
          shrink(static_cast<std::int32_t>(2 * e));
        } else {
          augment(static_cast<std::int32_t>(2 * e));
          dissolve(ta, tb);
          if (progress_) progress_(free_at_start_ - alive_trees_, free_at_start_);
        }
      } else if (t == t_grow) {
        const EventQueue::Event ev = grow_queue_.top();
        grow_queue_.pop();
        const bool u_plus = label_of(outer(ev.u)) == kPlus;
        const std::uint32_t in = u_plus ? ev.u : ev.v, out = u_plus ? ev.v : ev.u;
        // vertex(p) = in, vertex(p ^ 1) = out (ev.u is the edge's u)
        const std::int32_t p = static_cast<std::int32_t>(2 * ev.id + (u_plus ? 0 : 1));
        const std::uint32_t w = outer(out);
        assign_minus(w, p, slot_[outer(in)].tree);
      } else {
        const std::uint32_t b = expand_queue_.top().id;
        expand_queue_.pop();
        expand(b);
      }
    }
    return true;
  }

  // After an augmentation between trees ta and tb: the trees end, and their nodes count as
  // free from now on (label_of), their duals frozen at this eps (lazy); each node settles
  // them and leaves only when another tree reaches it (enter_tree -> retire), which loads
  // its record anyway. This replaced a walk over the trees' nodes here, a cache miss each:
  // on uniform-100k-a6 (13.6M nodes dissolved) a fifth of the solver's time (perf). Counted
  // by cachegrind (whole runs, one thread, a 4-lane build, 32 MiB last-level cache), the
  // same output: uniform-100k-a6 L1 data misses 256M -> 220M, instructions +1.4%;
  // square-hole-1M L1 misses -2.1%, last-level misses 132.9M -> 126.4M, instructions +0.1%;
  // square-hole-100k L1 misses -2.2%, instructions the same. Wall time, alternating runs,
  // within these machines' noise: uniform-100k-a6's matching 3.83 -> 3.83 s (medians of
  // 11), square-hole-1M 6.64 -> 6.59 s (of 5). With the ended flag read from the 8-byte eps
  // array instead of the bytes of ended_: uniform-100k-a6 5.64 -> 5.31 and 5.39 -> 5.05 s,
  // but square-hole-1M 6.67 -> 6.96 s.
  // The edges from the ended trees to the other trees' "+" nodes become grow events without
  // a walk over their edges (see park): from "-" nodes through the trees' parked lists, from
  // "+" nodes as their "+"-"+" events surface (clean_shrink).
  void dissolve(std::uint32_t ta, std::uint32_t tb) {
    for (std::uint32_t t : {ta, tb}) {
      tree_end_[t] = eps_;
      ended_[t] = 1;
      --alive_trees_;
    }
    for (std::uint32_t t : {ta, tb}) {
      for (std::uint32_t e : parked_[t]) {
        const CostEdge& ce = edges_[e];
        const std::uint32_t a = outer(ce.u), b = outer(ce.v);
        const Label la = label_of(a), lb = label_of(b);
        if ((la == kPlus && lb == kFree) || (la == kFree && lb == kPlus))
          grow_queue_.push(eps_ + slack(e, ce.u, a, ce.v, b), e, eps_, ce.u, ce.v);
      }
      std::vector<std::uint32_t>().swap(parked_[t]);
    }
  }

  // --- Shrink: the edge of endpoint p joins two "+" nodes of the tree; the cycle through
  // their nearest common "+" ancestor becomes a blossom. ---
  std::uint32_t common_base(std::uint32_t a, std::uint32_t b) {
    ++stamp_;
    // Walks up from both sides in turn; the first node seen twice is the base.
    std::uint32_t sides[2] = {a, b};
    bool done[2] = {false, false};
    for (int s = 0;; s ^= 1) {
      if (done[s]) continue;
      const std::uint32_t x = sides[s];
      if (mark_[x] == stamp_) return x;
      mark_[x] = stamp_;
      if (slot_[x].labelend == kNone) {
        done[s] = true;  // reached the root
        continue;
      }
      const std::uint32_t minus = outer(vertex(slot_[x].labelend));
      sides[s] = outer(vertex(slot_[minus].labelend));
    }
  }

  std::uint32_t new_blossom() {
    std::uint32_t b;
    if (!free_ids_.empty()) {
      b = free_ids_.back();
      free_ids_.pop_back();
    } else {
      b = num_nodes_++;
      if (slot_.size() <= b) slot_.emplace_back();
      z_.push_back(0);
      group_of_.push_back(0);
      size_.push_back(0);
      big_child_.push_back(0);
      childs_.emplace_back();
      endps_.emplace_back();
      mark_.push_back(0);
    }
    slot_[b].parent = kNone;
    z_[b] = 0;
    return b;
  }

  void shrink(std::int32_t p) {
    const std::uint32_t v = vertex(p), w = vertex(p ^ 1);
    const std::uint32_t bv0 = outer(v), bw0 = outer(w);
    const std::uint32_t bb = common_base(bv0, bw0);
    const std::uint32_t b = new_blossom();
    std::vector<std::uint32_t>& path = kids(b);
    std::vector<std::int32_t>& endps = ends(b);
    path.clear();
    endps.clear();
    for (std::uint32_t bv = bv0; bv != bb;) {
      path.push_back(bv);
      endps.push_back(slot_[bv].labelend);
      bv = outer(vertex(slot_[bv].labelend));
    }
    path.push_back(bb);
    std::reverse(path.begin(), path.end());
    std::reverse(endps.begin(), endps.end());
    endps.push_back(p);
    for (std::uint32_t bw = bw0; bw != bb;) {
      path.push_back(bw);
      endps.push_back(slot_[bw].labelend ^ 1);
      bw = outer(vertex(slot_[bw].labelend));
    }
    QV_ASSERT(path.size() % 2 == 1 && path.size() >= 3, "blossom of " << path.size());
    slot_[b].base = slot_[bb].base;
    enter_tree(b, kPlus, slot_[bb].labelend, slot_[bb].tree);
    // Settle the children (their duals freeze inside b), then adopt their vertices.
    minus_vertices_.clear();
    for (std::uint32_t c : path) {
      if (slot_[c].label == kMinus)
        for_boundary(c, [&](std::uint32_t x) { minus_vertices_.push_back(x); });
      settle(c);
      slot_[c].label = kFree;
      slot_[c].labelend = kNone;
      slot_[c].tree = kNoTree;
      slot_[c].parent = static_cast<std::int32_t>(b);
    }
    adopt_groups(b, path);
    // The former "-" children now grow with b: queue their edges. Those of the former "+"
    // children keep their keys (settling moves y by exactly the offset the key included).
    for (std::uint32_t x : minus_vertices_) push_edges_of_plus_vertex(x, b);
  }

  // --- Expand a "-" blossom whose dual reached zero: its children become top-level; the
  // even path from the child the tree enters by to the base child stays in the tree. ---
  void expand(std::uint32_t b) {
    settle(b);
    QV_ASSERT(z_[b] == 0, "expanding a blossom with z = " << z_[b]);
    // Copied out, so that b's own lists keep their memory for the next blossom with its id.
    std::vector<std::uint32_t>& children = expanded_children_;
    std::vector<std::int32_t>& links = expanded_links_;
    children.assign(kids(b).begin(), kids(b).end());
    links.assign(ends(b).begin(), ends(b).end());
    recycle(kids(b));
    recycle(ends(b));
    for (std::uint32_t c : children) slot_[c].parent = kNone;
    split_groups(b, children);
    const std::int32_t k = static_cast<std::int32_t>(children.size());
    auto at = [k](std::int32_t j) { return static_cast<std::size_t>(((j % k) + k) % k); };
    const std::int32_t entry_p = slot_[b].labelend;
    const std::uint32_t entry = outer(vertex(entry_p ^ 1));
    std::int32_t j = static_cast<std::int32_t>(
        std::find(children.begin(), children.end(), entry) - children.begin());
    std::int32_t jstep, endptrick;
    if (j & 1) {
      j -= k;
      jstep = 1;
      endptrick = 0;
    } else {
      jstep = -1;
      endptrick = 1;
    }
    const std::uint32_t tree = slot_[b].tree;
    slot_[b].label = kFree;
    slot_[b].labelend = kNone;
    slot_[b].tree = kNoTree;
    std::int32_t p = entry_p;
    while (j != 0) {
      assign_minus(outer(vertex(p ^ 1)), p, tree);  // and its mate, the next child, "+"
      j += jstep;
      p = links[at(j - endptrick)] ^ endptrick;
      j += jstep;
    }
    const std::uint32_t base_child = children[0];
    enter_tree(base_child, kMinus, p, tree);
    if (is_blossom(base_child))
      expand_queue_.push(eps_ + z_[base_child] / 2, base_child, eps_);
    for (std::uint32_t c : children)
      if (slot_[c].label == kFree) push_edges_to_plus(c);
    free_ids_.push_back(b);
  }

  // --- Augment along the tree path(s) through the edge of endpoint p ("+" side first). ---
  void augment(std::int32_t p0) {
    const std::int32_t starts[2][2] = {{static_cast<std::int32_t>(vertex(p0)), p0 ^ 1},
                                       {static_cast<std::int32_t>(vertex(p0 ^ 1)), p0}};
    for (const auto& start : starts) {
      std::uint32_t s = static_cast<std::uint32_t>(start[0]);
      std::int32_t p = start[1];
      while (true) {
        const std::uint32_t bs = outer(s);
        if (is_blossom(bs)) augment_blossom(bs, s);
        set_mate(s, p);
        if (slot_[bs].label != kPlus || slot_[bs].labelend == kNone) break;
        const std::uint32_t t = vertex(slot_[bs].labelend);
        const std::uint32_t bt = outer(t);
        QV_ASSERT(slot_[bt].label == kMinus, "augmenting path through a non '-' node");
        s = vertex(slot_[bt].labelend);
        const std::uint32_t jv = vertex(slot_[bt].labelend ^ 1);
        if (is_blossom(bt)) augment_blossom(bt, jv);
        set_mate(jv, slot_[bt].labelend);
        p = slot_[bt].labelend ^ 1;
      }
    }
  }

  // Rematches blossom b0 so that vertex v0 becomes its base (v0's own mate is set by the
  // caller). Iterative, since blossoms nest thousands deep on large meshes: the sub-blossoms
  // to rematch are independent (each touches only the mates inside itself), so they go on a
  // work list; each item walks from its vertex up to its blossom once and rematches every
  // blossom on that chain.
  void augment_blossom(std::uint32_t b0, std::uint32_t v0) {
    work_.clear();
    work_.push_back({b0, v0});
    while (!work_.empty()) {
      const auto [b, v] = work_.back();
      work_.pop_back();
      std::uint32_t inner = v;
      for (std::uint32_t x = static_cast<std::uint32_t>(slot_[v].parent);;
           x = static_cast<std::uint32_t>(slot_[x].parent)) {
        rematch_cycle(x, inner, v);
        if (x == b) break;
        inner = x;
      }
    }
  }
  // One level: child t of b holds v; rotate b's cycle so that t is its base child and rematch
  // the children on the even path from t to the old base (their inner rematches go on work_).
  void rematch_cycle(std::uint32_t b, std::uint32_t t, std::uint32_t v) {
    std::vector<std::uint32_t>& cycle = kids(b);
    std::vector<std::int32_t>& links = ends(b);
    const std::int32_t k = static_cast<std::int32_t>(cycle.size());
    auto at = [k](std::int32_t j) { return static_cast<std::size_t>(((j % k) + k) % k); };
    const std::int32_t i =
        static_cast<std::int32_t>(std::find(cycle.begin(), cycle.end(), t) - cycle.begin());
    std::int32_t j = i, jstep, endptrick;
    if (i & 1) {
      j -= k;
      jstep = 1;
      endptrick = 0;
    } else {
      jstep = -1;
      endptrick = 1;
    }
    while (j != 0) {
      j += jstep;
      std::uint32_t c = cycle[at(j)];
      const std::int32_t p = links[at(j - endptrick)] ^ endptrick;
      if (is_blossom(c)) work_.push_back({c, vertex(p)});
      j += jstep;
      c = cycle[at(j)];
      if (is_blossom(c)) work_.push_back({c, vertex(p ^ 1)});
      set_mate(vertex(p), p ^ 1);
      set_mate(vertex(p ^ 1), p);
    }
    std::rotate(cycle.begin(), cycle.begin() + i, cycle.end());
    std::rotate(links.begin(), links.begin() + i, links.end());
    slot_[b].base = v;
  }

  std::uint32_t n_;
  std::vector<CostEdge> edges_;  // costs doubled
  const MatchingProgress& progress_;
  std::uint32_t free_at_start_ = 0;
  // Per vertex v, its edges [offsets_[v], offsets_[v + 1]) with their far ends beside them:
  // growing a tree then reaches the far end's record without loading the edge first (one
  // dependent load fewer: uniform-100k-a6's matching 6.2 -> 5.6 s, medians of 7 alternating
  // runs; square-hole-100k and -1M within the noise), and the events it queues carry the
  // edge's ends (event_queue.hpp).
  struct Incidence {
    std::int32_t end;     // the edge's endpoint at this vertex (vertex(end) is the vertex)
    std::uint32_t other;  // the edge's other vertex
    std::uint32_t edge() const { return static_cast<std::uint32_t>(end) >> 1; }
    // The edge's u and v (CostEdge), given the vertex whose incidence this is.
    std::uint32_t u(std::uint32_t self) const { return (end & 1) ? other : self; }
    std::uint32_t v(std::uint32_t self) const { return (end & 1) ? self : other; }
  };
  std::vector<std::uint32_t> offsets_;
  std::vector<Incidence> incident_;
  // What growing a tree reads of an edge's far end, in one cache line (the solver waits on
  // memory; square-hole-1M's matching: 19.4 -> 15.1 s, medians of 5, against one array per
  // field). Record k holds vertex k's fields (k < n), group k's and node k's: the three
  // numberings share indices, and a vertex outside every blossom is its own group and node.
  //
  // Vertex groups: the vertices of one top-level node form one group, whose offset is added
  // to their stored duals (settling a node is then O(1)). A shrink keeps the largest child's
  // group and moves the others' vertices into it; an expand gives the other children new groups
  // with the same offset (union by size: each vertex moves O(log n) times per nesting).
  struct alignas(64) Slot {
    std::int64_t y = 0;             // vertex: stored dual
    std::int64_t offset = 0;        // group: added to its vertices' stored duals
    std::int64_t join = 0;          // node: eps when it got its label
    std::uint32_t group = 0;        // vertex: its group
    std::uint32_t top = 0;          // group: its top-level node
    std::uint32_t tree = kNoTree;   // node: its tree, or kNoTree
    Label label = kFree;            // node
    std::int32_t mate = kNone;      // vertex: endpoint at the partner, or kNone
    std::uint32_t mate_vertex = 0;  // vertex: the partner (vertex(mate)), where mate != kNone
    std::int32_t labelend = kNone;  // node: endpoint in the parent through which it was reached
    std::int32_t parent = kNone;    // node: the blossom containing it, or kNone
    std::uint32_t base = 0;         // node: its base vertex
  };
  static_assert(sizeof(Slot) == 64, "one cache line per record");
  std::vector<Slot> slot_;
  std::uint32_t num_groups_ = 0, num_nodes_ = 0;
  std::vector<std::uint32_t> free_groups_;
  std::vector<std::uint32_t> group_of_, size_, big_child_;  // per node (top-level: its group)
  // Per node: vertices 0..n-1, blossoms from n on.
  std::vector<std::int64_t> z_;
  std::vector<std::vector<std::uint32_t>> childs_;  // blossoms: the odd cycle, base first
  std::vector<std::vector<std::int32_t>> endps_;    // edge i joins childs i and i + 1
  // Per tree: whether an augmentation ended it (a byte each, so that the test mostly stays
  // in cache: 68 KiB for square-hole-1M's 69,544 trees) and the dual value eps then.
  bool ended(std::uint32_t t) const { return ended_[t] != 0; }
  std::vector<std::uint8_t> ended_;
  std::vector<std::int64_t> tree_end_;
  std::vector<std::vector<std::uint32_t>> parked_;  // per tree: edges parked with it (see park)
  std::uint32_t alive_trees_ = 0;
  std::vector<std::uint32_t> mark_, free_ids_, stack_, minus_vertices_;
  std::vector<std::vector<std::uint32_t>> boundary_;  // per group (blossom groups only)
  std::vector<std::uint32_t> listed_in_;              // per vertex: the group listing it
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work_;
  std::vector<std::uint32_t> expanded_children_;  // expand's copy of the blossom's cycle
  std::vector<std::int32_t> expanded_links_;
  std::uint32_t stamp_ = 0;
  std::int64_t eps_ = 0;
  EventQueue grow_queue_, shrink_queue_, expand_queue_;
};

// The graph renumbered by connected component (components in the order of their lowest
// vertex; inside one, the vertices keep their order), edges bucketed by their lower new
// endpoint: each component is then a range of vertices and a range of edges. The solver is
// bound by memory latency, so the caller's order matters: recombine's triangles come in
// Z-order (node_order.hpp), where the vertices a tree grows over sit close together in memory.
// Measured against a breadth-first renumbering (which had gained 0.77 -> 0.55 s on
// square-hole-100k over Gmsh's numbering), square-hole-1M, the solver alone: 11.0-12.2 ->
// 9.8-10.7 s (three alternating runs); counted by cachegrind with a 32 MiB last-level cache,
// its misses 80.7M -> 76.2M and L1 data misses 281M -> 268M.
struct LocalGraph {
  std::vector<CostEdge> edges;           // renumbered
  std::vector<std::uint32_t> edge_from;  // original index of each renumbered edge
  // Connected component c holds the vertices [component_start[c], component_start[c + 1])
  // and, since edges are bucketed by their lower end, a contiguous range of edges too.
  std::vector<std::uint32_t> component_start;
};
LocalGraph component_order(std::uint32_t n, std::span<const CostEdge> edges) {
  std::vector<std::uint32_t> offsets(std::size_t{n} + 1, 0), adjacent(2 * edges.size());
  for (const CostEdge& e : edges) {
    ++offsets[e.u + 1];
    ++offsets[e.v + 1];
  }
  for (std::uint32_t v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (const CostEdge& e : edges) {
      adjacent[fill[e.u]++] = e.v;
      adjacent[fill[e.v]++] = e.u;
    }
  }
  // Components by breadth-first search from each lowest unvisited vertex, then counted.
  constexpr std::uint32_t kUnseen = 0xffffffffu;
  std::vector<std::uint32_t> component(n, kUnseen), queue, size;
  queue.reserve(n);
  for (std::uint32_t s = 0; s < n; ++s) {
    if (component[s] != kUnseen) continue;
    const auto c = static_cast<std::uint32_t>(size.size());
    queue.clear();
    queue.push_back(s);
    component[s] = c;
    for (std::size_t head = 0; head < queue.size(); ++head)
      for (std::uint32_t i = offsets[queue[head]]; i < offsets[queue[head] + 1]; ++i)
        if (component[adjacent[i]] == kUnseen) {
          component[adjacent[i]] = c;
          queue.push_back(adjacent[i]);
        }
    size.push_back(static_cast<std::uint32_t>(queue.size()));
  }
  LocalGraph g;
  g.component_start.assign(size.size() + 1, 0);
  for (std::size_t c = 0; c < size.size(); ++c) g.component_start[c + 1] = g.component_start[c] + size[c];
  std::vector<std::uint32_t> new_id(n), next(g.component_start.begin(), g.component_start.end() - 1);
  for (std::uint32_t v = 0; v < n; ++v) new_id[v] = next[component[v]]++;
  // Edges bucketed by their lower new endpoint (a counting sort, stable).
  std::fill(offsets.begin(), offsets.end(), 0);
  for (const CostEdge& e : edges) ++offsets[std::min(new_id[e.u], new_id[e.v]) + 1];
  for (std::uint32_t v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  g.edges.resize(edges.size());
  g.edge_from.resize(edges.size());
  for (std::uint32_t i = 0; i < edges.size(); ++i) {
    const CostEdge& e = edges[i];
    const std::uint32_t k = offsets[std::min(new_id[e.u], new_id[e.v])]++;
    g.edges[k] = {new_id[e.u], new_id[e.v], e.cost};
    g.edge_from[k] = i;
  }
  return g;
}

// Sums the progress of the chunks' solvers for the caller's callback (MatchingProgress's
// contract: the second number fixed once every chunk has started).
class ProgressSum {
 public:
  ProgressSum(const MatchingProgress& user, std::size_t chunks) : user_(user), paired_(chunks, 0) {}
  MatchingProgress of_chunk(std::size_t c) {
    if (!user_) return {};
    return [this, c](std::uint32_t paired, std::uint32_t) {
      const std::lock_guard<std::mutex> lock(mutex_);
      paired_[c] = paired;
      if (total_free_ == kUnknown) return;  // chunks still starting
      std::uint32_t sum = 0;
      for (std::uint32_t p : paired_) sum += p;
      user_(sum, total_free_);
    };
  }
  void all_started(std::uint32_t total_free) {
    if (!user_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    total_free_ = total_free;
    user_(0, total_free_);
  }

 private:
  static constexpr std::uint32_t kUnknown = 0xffffffffu;
  const MatchingProgress& user_;
  std::mutex mutex_;
  std::vector<std::uint32_t> paired_;
  std::uint32_t total_free_ = kUnknown;
};

}  // namespace

bool min_cost_perfect_matching(std::uint32_t num_nodes, std::span<const CostEdge> edges,
                               std::vector<char>& matched, const MatchingProgress& progress) {
  // Checked here, in the caller's numbering (the solver sees the renumbered graph).
  QV_ASSERT(edges.size() < (std::size_t{1} << 30),
            edges.size() << " edges: the endpoints 2e + 1 must fit 32 bits");
  for (std::size_t e = 0; e < edges.size(); ++e)
    QV_ASSERT(edges[e].u < num_nodes && edges[e].v < num_nodes && edges[e].u != edges[e].v,
              "edge " << e << " (" << edges[e].u << ", " << edges[e].v << ") in a graph of "
                      << num_nodes);
  const LocalGraph local = component_order(num_nodes, edges);
  // Chunks: runs of whole components, each solved by a solver of its own (on the threads
  // there are): a surface of several faces, as CAD models give, has one component per face.
  // Small components are grouped, so that a chunk has at least `least` vertices.
  const std::uint32_t least = std::max<std::uint32_t>(4096, num_nodes / 32);
  std::vector<std::uint32_t> chunk_start{0};
  for (std::size_t c = 1; c + 1 < local.component_start.size(); ++c)
    if (local.component_start[c] - chunk_start.back() >= least) chunk_start.push_back(local.component_start[c]);
  chunk_start.push_back(num_nodes);
  const std::size_t chunks = chunk_start.size() - 1;
  // The edges of chunk k: [edge_start[k], edge_start[k + 1]).
  std::vector<std::size_t> edge_start(chunks + 1, local.edges.size());
  for (std::size_t k = 0, e = 0; k < chunks; ++k) {
    edge_start[k] = e;
    while (e < local.edges.size() && std::min(local.edges[e].u, local.edges[e].v) < chunk_start[k + 1]) ++e;
  }

  ProgressSum sum(progress, chunks);
  std::vector<MatchingProgress> chunk_progress(chunks);
  std::vector<std::unique_ptr<Solver>> solvers(chunks);
  std::uint32_t total_free = 0;
  for (std::size_t k = 0; k < chunks; ++k) {
    const std::uint32_t first = chunk_start[k];
    std::vector<CostEdge> part;  // the chunk's edges, renumbered from its first vertex
    if (chunks > 1) {
      part.assign(local.edges.begin() + static_cast<std::ptrdiff_t>(edge_start[k]),
                  local.edges.begin() + static_cast<std::ptrdiff_t>(edge_start[k + 1]));
      for (CostEdge& e : part) {
        e.u -= first;
        e.v -= first;
      }
    }
    chunk_progress[k] = chunks == 1 ? progress : sum.of_chunk(k);
    solvers[k] = std::make_unique<Solver>(chunk_start[k + 1] - first,
                                          chunks == 1 ? std::span<const CostEdge>(local.edges) : part,
                                          chunk_progress[k]);
    if (!solvers[k]->start()) return false;
    total_free += solvers[k]->free_at_start();
  }
  if (chunks > 1) sum.all_started(total_free);

  // Largest chunks first, so that the threads finish together.
  std::vector<std::size_t> order(chunks);
  for (std::size_t k = 0; k < chunks; ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return chunk_start[a + 1] - chunk_start[a] > chunk_start[b + 1] - chunk_start[b];
  });
  std::vector<char> solved(chunks, 0);
  std::vector<std::exception_ptr> failure(chunks);
  const auto jobs = static_cast<std::ptrdiff_t>(chunks);
#pragma omp parallel for schedule(dynamic, 1) if (chunks > 1)
  for (std::ptrdiff_t i = 0; i < jobs; ++i) {
    const std::size_t k = order[static_cast<std::size_t>(i)];
    try {
      solved[k] = solvers[k]->finish() ? 1 : 0;
    } catch (...) {
      failure[k] = std::current_exception();  // an exception may not leave the parallel loop
    }
  }
  for (const std::exception_ptr& f : failure)
    if (f) std::rethrow_exception(f);
  if (std::find(solved.begin(), solved.end(), 0) != solved.end()) return false;

  matched.assign(edges.size(), 0);
  std::vector<char> part_matched;
  for (std::size_t k = 0; k < chunks; ++k) {
    solvers[k]->read(part_matched);
    for (std::size_t j = 0; j < part_matched.size(); ++j)
      matched[local.edge_from[edge_start[k] + j]] = part_matched[j];
    solvers[k].reset();
  }
  return true;
}

}  // namespace quadval::recombine_detail
