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
// and stale queue entries are recognised by recomputing the key when they surface. Ties go
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
#include <deque>
#include <limits>
#include <queue>

#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

constexpr std::int32_t kNone = -1;
constexpr std::uint32_t kNoTree = 0xffffffffu;

struct Event {
  std::int64_t key;
  std::uint32_t id;
  std::uint64_t seq = 0;  // queue order, the tie-break
  bool operator>(const Event& o) const { return key > o.key || (key == o.key && seq > o.seq); }
};
// A priority queue of events by (key, seq), with a FIFO lane for the events queued when
// already due (key == the current "now"): on meshes most grow events are, since whole regions
// of tight edges are absorbed at one dual value, and the lane spares them the heap (measured:
// 2x less time on uniform meshes). Same order as one heap: an event in the heap with the lane's
// key was queued before the dual value reached it, so before every event in the lane.
class EventQueue {
 public:
  void push(const Event& ev, std::int64_t now) {
    if (ev.key == now)
      due_.push_back(ev);
    else
      heap_.push(ev);
  }
  bool empty() const { return due_.empty() && heap_.empty(); }
  const Event& top() const { return from_heap() ? heap_.top() : due_.front(); }
  void pop() {
    if (from_heap())
      heap_.pop();
    else
      due_.pop_front();
  }

 private:
  bool from_heap() const {
    return due_.empty() || (!heap_.empty() && heap_.top().key <= due_.front().key);
  }
  std::priority_queue<Event, std::vector<Event>, std::greater<Event>> heap_;
  std::deque<Event> due_;
};

enum Label : std::int8_t { kFree = 0, kPlus = 1, kMinus = 2 };

class Solver {
 public:
  Solver(std::uint32_t n, std::span<const CostEdge> edges, const MatchingProgress& progress)
      : n_(n), edges_(edges), progress_(progress) {
    cost_.resize(edges.size());
    std::vector<std::uint32_t> degree(n + 1, 0);
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const CostEdge& ce = edges[e];
      QV_ASSERT(ce.cost <= kMaxMatchingCost && ce.cost >= -kMaxMatchingCost,
                "edge cost " << ce.cost);
      cost_[e] = 2 * ce.cost;
      ++degree[ce.u + 1];
      ++degree[ce.v + 1];
    }
    offsets_.assign(n + 1, 0);
    for (std::uint32_t v = 0; v < n; ++v) offsets_[v + 1] = offsets_[v] + degree[v + 1];
    incident_.resize(offsets_[n]);
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::uint32_t e = 0; e < edges.size(); ++e) {
      incident_[fill[edges[e].u]++] = e;
      incident_[fill[edges[e].v]++] = e;
    }
    y_.assign(n, 0);
    mate_.assign(n, kNone);
    group_.resize(n);
    group_top_.resize(n);
    group_of_.resize(n);
    for (std::uint32_t v = 0; v < n; ++v) group_[v] = group_top_[v] = group_of_[v] = v;
    offset_.assign(n, 0);
    boundary_.resize(n);
    listed_in_.assign(n, kNoTree);
    size_.assign(n, 1);
    big_child_.assign(n, 0);
    parent_.assign(n, kNone);
    base_.resize(n);
    for (std::uint32_t v = 0; v < n; ++v) base_[v] = v;
    label_.assign(n, kFree);
    labelend_.assign(n, kNone);
    join_.assign(n, 0);
    z_.assign(n, 0);
    mark_.assign(n, 0);
    tree_of_.assign(n, kNoTree);
  }

  bool run() {
    if (n_ % 2 != 0) return false;
    if (!greedy_init()) return false;
    eps_ = 0;
    for (std::uint32_t r = 0; r < n_; ++r) {
      if (mate_[r] != kNone) continue;
      const auto t = static_cast<std::uint32_t>(trees_.size());
      trees_.emplace_back();
      ++alive_trees_;
      assign_plus(r, kNone, t);
    }
    free_at_start_ = alive_trees_;
    if (progress_) progress_(0, free_at_start_);
    return grow_trees();
  }

  void read(std::vector<char>& matched) const {
    matched.assign(edges_.size(), 0);
    for (std::uint32_t v = 0; v < n_; ++v)
      if (mate_[v] != kNone) matched[static_cast<std::uint32_t>(mate_[v]) >> 1] = 1;
  }

 private:
  // --- Graph ---
  std::uint32_t vertex(std::int32_t p) const {
    const CostEdge& e = edges_[static_cast<std::uint32_t>(p) >> 1];
    return (p & 1) ? e.v : e.u;
  }
  static std::int32_t endpoint(std::uint32_t e, std::uint32_t from_vertex, const CostEdge& ce) {
    return static_cast<std::int32_t>(2 * e + (ce.u == from_vertex ? 0 : 1));
  }
  bool is_blossom(std::uint32_t b) const { return b >= n_; }

  // --- Vertex groups and lazy duals ---
  std::uint32_t outer(std::uint32_t v) const { return group_top_[group_[v]]; }
  std::int64_t dual(std::uint32_t v) const { return y_[v] + offset_[group_[v]]; }
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
      const std::int64_t shift = offset_[gc] - offset_[g];
      for_leaves(c, [&](std::uint32_t v) {
        y_[v] += shift;
        group_[v] = g;
        listed_in_[v] = kNoTree;  // its old group's list is dropped (and the id reused)
      });
      std::vector<std::uint32_t>().swap(boundary_[gc]);
      free_groups_.push_back(gc);
    }
    if (!is_blossom(big) && crosses(big)) list_boundary(big, g);
    for (std::uint32_t c : children)
      if (c != big)
        for_leaves(c, [&](std::uint32_t v) {
          if (crosses(v)) list_boundary(v, g);
        });
    group_top_[g] = b;
    group_of_[b] = g;
    big_child_[b] = big;
  }
  void split_groups(std::uint32_t b, const std::vector<std::uint32_t>& children) {
    const std::uint32_t g = group_of_[b];
    for (std::uint32_t c : children) {
      if (c == big_child_[b]) {
        group_top_[g] = c;
        group_of_[c] = g;
        continue;
      }
      std::uint32_t gc;
      if (!free_groups_.empty()) {
        gc = free_groups_.back();
        free_groups_.pop_back();
      } else {
        gc = static_cast<std::uint32_t>(group_top_.size());
        group_top_.push_back(0);
        offset_.push_back(0);
        boundary_.emplace_back();
      }
      offset_[gc] = offset_[g];
      group_top_[gc] = c;
      group_of_[c] = gc;
      for_leaves(c, [&](std::uint32_t v) {
        group_[v] = gc;
        listed_in_[v] = kNoTree;  // gc may be a reused id whose old list is gone
      });
    }
    // The new groups list their boundary; the big child's list gains its vertices next to them.
    for (std::uint32_t c : children) {
      if (c == big_child_[b]) continue;
      for_leaves(c, [&](std::uint32_t v) {
        if (crosses(v)) list_boundary(v, group_[v]);
        for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
          const std::uint32_t w = other_end(incident_[i], v);
          if (group_[w] == g) list_boundary(w, g);
        }
      });
    }
  }
  // Boundary lists: each group lists (at least) its vertices with an edge leaving the group, so
  // that queueing a big blossom's edges costs its boundary, not its size. Entries that stopped
  // qualifying are dropped when the list is next walked.
  std::uint32_t other_end(std::uint32_t e, std::uint32_t v) const {
    return edges_[e].u == v ? edges_[e].v : edges_[e].u;
  }
  bool crosses(std::uint32_t v) const {
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i)
      if (group_[other_end(incident_[i], v)] != group_[v]) return true;
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
      if (group_[v] != g || listed_in_[v] != g) continue;  // moved away, or a stale copy
      if (!crosses(v)) {
        listed_in_[v] = kNoTree;
        continue;
      }
      list[keep++] = v;
    }
    list.resize(keep);
    for (std::uint32_t v : list) f(v);
  }
  std::int64_t lazy(std::uint32_t b) const {
    if (label_[b] == kPlus) return eps_ - join_[b];
    if (label_[b] == kMinus) return join_[b] - eps_;
    return 0;
  }
  std::int64_t slack(std::uint32_t e) const {
    const CostEdge& ce = edges_[e];
    return cost_[e] - dual(ce.u) - dual(ce.v) - lazy(outer(ce.u)) - lazy(outer(ce.v));
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
      offset_[group_of_[b]] += d;
      if (is_blossom(b)) z_[b] += 2 * d;
    }
    join_[b] = eps_;
  }

  // --- Initialisation (after Blossom V §5.1): y_v = min c / 2; then each free vertex v in
  // turn rises to its tightest edge and is matched there when the other end is free, or by a
  // tight three-edge path to a free vertex; else its dual stays (fewer tight edges into the
  // matched region keep the trees smaller: measured). ---
  bool greedy_init() {
    for (std::uint32_t v = 0; v < n_; ++v) {
      if (offsets_[v] == offsets_[v + 1]) return false;  // isolated: no perfect matching
      std::int64_t lo = cost_[incident_[offsets_[v]]];
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i)
        lo = std::min(lo, cost_[incident_[i]]);
      y_[v] = lo / 2;
    }
    for (std::uint32_t v = 0; v < n_; ++v) {
      if (mate_[v] != kNone) continue;
      std::int64_t best = 0;
      std::uint32_t best_edge = 0;
      bool found = false;
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
        const std::uint32_t e = incident_[i];
        const CostEdge& ce = edges_[e];
        const std::int64_t s = cost_[e] - y_[ce.u] - y_[ce.v];
        // The smallest slack sets how far y_v can rise; among equals prefer a free end.
        const std::uint32_t w = ce.u == v ? ce.v : ce.u;
        if (!found || s < best || (s == best && mate_[w] == kNone)) {
          best = s;
          best_edge = e;
          found = true;
        }
      }
      const CostEdge& ce = edges_[best_edge];
      const std::uint32_t w = ce.u == v ? ce.v : ce.u;
      if (mate_[w] == kNone) {
        y_[v] += best;
        mate_[v] = endpoint(best_edge, w, ce);
        mate_[w] = endpoint(best_edge, v, ce);
      } else {
        // Raised to its tightest edge, v may reach a free vertex by a tight path of three
        // edges v-w=x-z (w=x matched): swap that pair. Otherwise v's dual stays put, so
        // that fewer tight edges lead a tree into the matched region.
        y_[v] += best;
        if (!augment_short(v)) y_[v] -= best;
      }
    }
    // Every root's dual even (lowering a dual keeps all slacks >= 0): then the duals of all
    // tree vertices stay congruent to eps mod 2 and every "+"-"+" slack is even.
    for (std::uint32_t v = 0; v < n_; ++v)
      if (mate_[v] == kNone && (y_[v] & 1)) --y_[v];
    return true;
  }

  bool augment_short(std::uint32_t v) {
    auto tight = [&](std::uint32_t e) {
      return cost_[e] == y_[edges_[e].u] + y_[edges_[e].v];
    };
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
      const std::uint32_t e1 = incident_[i];
      if (!tight(e1)) continue;
      const std::uint32_t w = other_end(e1, v);
      if (mate_[w] == kNone) continue;
      const std::uint32_t x = vertex(mate_[w]);
      for (std::uint32_t k = offsets_[x]; k < offsets_[x + 1]; ++k) {
        const std::uint32_t e2 = incident_[k];
        const std::uint32_t z = other_end(e2, x);
        if (z == v || mate_[z] != kNone || !tight(e2)) continue;
        mate_[v] = endpoint(e1, w, edges_[e1]);
        mate_[w] = endpoint(e1, v, edges_[e1]);
        mate_[x] = endpoint(e2, z, edges_[e2]);
        mate_[z] = endpoint(e2, x, edges_[e2]);
        return true;
      }
    }
    return false;
  }

  // --- Tree growth ---
  // Queues the edges from vertex v of the "+" node b to other "+" nodes and to free nodes.
  void push_edges_of_plus_vertex(std::uint32_t v, std::uint32_t b) {
    for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
      const std::uint32_t e = incident_[i];
      const std::uint32_t other = outer(other_end(e, v));
      if (other == b) continue;
      if (label_[other] == kPlus)
        shrink_queue_.push({2 * eps_ + slack(e), e, seq_++}, 2 * eps_);
      else if (label_[other] == kFree)
        grow_queue_.push({eps_ + slack(e), e, seq_++}, eps_);
    }
  }
  void push_edges_of_plus(std::uint32_t b) {
    for_boundary(b, [&](std::uint32_t v) { push_edges_of_plus_vertex(v, b); });
  }
  // Edges from a node that has just left the tree (expand) to the tree's "+" nodes.
  void push_edges_to_plus(std::uint32_t b) {
    for_boundary(b, [&](std::uint32_t v) {
      for (std::uint32_t i = offsets_[v]; i < offsets_[v + 1]; ++i) {
        const std::uint32_t e = incident_[i];
        const CostEdge& ce = edges_[e];
        if (label_[outer(ce.u == v ? ce.v : ce.u)] == kPlus)
          grow_queue_.push({eps_ + slack(e), e, seq_++}, eps_);
      }
    });
  }

  void enter_tree(std::uint32_t b, Label label, std::int32_t p, std::uint32_t t) {
    label_[b] = label;
    labelend_[b] = p;
    join_[b] = eps_;
    tree_of_[b] = t;
    trees_[t].push_back(b);
  }
  void assign_plus(std::uint32_t b, std::int32_t p, std::uint32_t t) {
    enter_tree(b, kPlus, p, t);
    push_edges_of_plus(b);
  }
  // Labels b "-" (reached through endpoint p, whose vertex is in the parent), then its mate "+".
  void assign_minus(std::uint32_t b, std::int32_t p, std::uint32_t t) {
    enter_tree(b, kMinus, p, t);
    if (is_blossom(b)) expand_queue_.push({eps_ + z_[b] / 2, b, seq_++}, eps_);
    const std::int32_t q = mate_[base_[b]];
    QV_ASSERT(q != kNone, "a '-' node without a mate");
    assign_plus(outer(vertex(q)), q ^ 1, t);
  }

  // Drops stale entries from the top of each queue (their key no longer matches the state).
  void clean_grow() {
    while (!grow_queue_.empty()) {
      const Event ev = grow_queue_.top();
      const CostEdge& ce = edges_[ev.id];
      const std::uint32_t a = outer(ce.u), b = outer(ce.v);
      const bool one_plus_one_free = (label_[a] == kPlus && label_[b] == kFree) ||
                                     (label_[a] == kFree && label_[b] == kPlus);
      if (a != b && one_plus_one_free && eps_ + slack(ev.id) == ev.key) return;
      grow_queue_.pop();
    }
  }
  void clean_shrink() {
    while (!shrink_queue_.empty()) {
      const Event ev = shrink_queue_.top();
      const CostEdge& ce = edges_[ev.id];
      const std::uint32_t a = outer(ce.u), b = outer(ce.v);
      if (a != b && label_[a] == kPlus && label_[b] == kPlus &&
          2 * eps_ + slack(ev.id) == ev.key)
        return;
      shrink_queue_.pop();
    }
  }
  void clean_expand() {
    while (!expand_queue_.empty()) {
      const Event ev = expand_queue_.top();
      const std::uint32_t b = ev.id;
      if (b < parent_.size() && alive(b) && parent_[b] == kNone && label_[b] == kMinus &&
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
        const std::uint32_t e = shrink_queue_.top().id;
        shrink_queue_.pop();
        const std::uint32_t ta = tree_of_[outer(edges_[e].u)];
        const std::uint32_t tb = tree_of_[outer(edges_[e].v)];
        if (ta == tb) {
          shrink(static_cast<std::int32_t>(2 * e));
        } else {
          augment(static_cast<std::int32_t>(2 * e));
          dissolve(ta, tb);
          if (progress_) progress_(free_at_start_ - alive_trees_, free_at_start_);
        }
      } else if (t == t_grow) {
        const std::uint32_t e = grow_queue_.top().id;
        grow_queue_.pop();
        const CostEdge& ce = edges_[e];
        const bool u_plus = label_[outer(ce.u)] == kPlus;
        const std::uint32_t in = u_plus ? ce.u : ce.v, out = u_plus ? ce.v : ce.u;
        const std::int32_t p = endpoint(e, in, ce);  // vertex(p) = in, vertex(p ^ 1) = out
        const std::uint32_t w = outer(out);
        QV_ASSERT(mate_[base_[w]] != kNone, "a free node outside every tree");
        assign_minus(w, p, tree_of_[outer(in)]);
      } else {
        const std::uint32_t b = expand_queue_.top().id;
        expand_queue_.pop();
        expand(b);
      }
    }
    return true;
  }

  // After an augmentation between trees ta and tb: their nodes settle their duals and leave;
  // the edges from them to the other trees' "+" nodes become grow events.
  void dissolve(std::uint32_t ta, std::uint32_t tb) {
    dissolved_.clear();
    for (std::uint32_t t : {ta, tb}) {
      for (std::uint32_t b : trees_[t]) {
        if (!alive(b) || parent_[b] != kNone || label_[b] == kFree || tree_of_[b] != t) continue;
        settle(b);
        label_[b] = kFree;
        labelend_[b] = kNone;
        tree_of_[b] = kNoTree;
        dissolved_.push_back(b);
      }
      std::vector<std::uint32_t>().swap(trees_[t]);
      --alive_trees_;
    }
    for (std::uint32_t b : dissolved_) push_edges_to_plus(b);
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
      if (labelend_[x] == kNone) {
        done[s] = true;  // reached the root
        continue;
      }
      const std::uint32_t minus = outer(vertex(labelend_[x]));
      sides[s] = outer(vertex(labelend_[minus]));
    }
  }

  std::uint32_t new_blossom() {
    std::uint32_t b;
    if (!free_ids_.empty()) {
      b = free_ids_.back();
      free_ids_.pop_back();
    } else {
      b = static_cast<std::uint32_t>(parent_.size());
      parent_.push_back(kNone);
      base_.push_back(0);
      label_.push_back(kFree);
      labelend_.push_back(kNone);
      join_.push_back(0);
      z_.push_back(0);
      tree_of_.push_back(kNoTree);
      group_of_.push_back(0);
      size_.push_back(0);
      big_child_.push_back(0);
      childs_.emplace_back();
      endps_.emplace_back();
      mark_.push_back(0);
    }
    parent_[b] = kNone;
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
      endps.push_back(labelend_[bv]);
      bv = outer(vertex(labelend_[bv]));
    }
    path.push_back(bb);
    std::reverse(path.begin(), path.end());
    std::reverse(endps.begin(), endps.end());
    endps.push_back(p);
    for (std::uint32_t bw = bw0; bw != bb;) {
      path.push_back(bw);
      endps.push_back(labelend_[bw] ^ 1);
      bw = outer(vertex(labelend_[bw]));
    }
    QV_ASSERT(path.size() % 2 == 1 && path.size() >= 3, "blossom of " << path.size());
    base_[b] = base_[bb];
    enter_tree(b, kPlus, labelend_[bb], tree_of_[bb]);
    // Settle the children (their duals freeze inside b), then adopt their vertices.
    minus_vertices_.clear();
    for (std::uint32_t c : path) {
      if (label_[c] == kMinus)
        for_boundary(c, [&](std::uint32_t x) { minus_vertices_.push_back(x); });
      settle(c);
      label_[c] = kFree;
      labelend_[c] = kNone;
      tree_of_[c] = kNoTree;
      parent_[c] = static_cast<std::int32_t>(b);
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
    std::vector<std::uint32_t> children = std::move(kids(b));
    std::vector<std::int32_t> links = std::move(ends(b));
    kids(b).clear();
    ends(b).clear();
    for (std::uint32_t c : children) parent_[c] = kNone;
    split_groups(b, children);
    const std::int32_t k = static_cast<std::int32_t>(children.size());
    auto at = [k](std::int32_t j) { return static_cast<std::size_t>(((j % k) + k) % k); };
    const std::int32_t entry_p = labelend_[b];
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
    const std::uint32_t tree = tree_of_[b];
    label_[b] = kFree;
    labelend_[b] = kNone;
    tree_of_[b] = kNoTree;
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
      expand_queue_.push({eps_ + z_[base_child] / 2, base_child, seq_++}, eps_);
    for (std::uint32_t c : children)
      if (label_[c] == kFree) push_edges_to_plus(c);
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
        mate_[s] = p;
        if (label_[bs] != kPlus || labelend_[bs] == kNone) break;
        const std::uint32_t t = vertex(labelend_[bs]);
        const std::uint32_t bt = outer(t);
        QV_ASSERT(label_[bt] == kMinus, "augmenting path through a non '-' node");
        s = vertex(labelend_[bt]);
        const std::uint32_t jv = vertex(labelend_[bt] ^ 1);
        if (is_blossom(bt)) augment_blossom(bt, jv);
        mate_[jv] = labelend_[bt];
        p = labelend_[bt] ^ 1;
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
      for (std::uint32_t x = static_cast<std::uint32_t>(parent_[v]);;
           x = static_cast<std::uint32_t>(parent_[x])) {
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
      mate_[vertex(p)] = p ^ 1;
      mate_[vertex(p ^ 1)] = p;
    }
    std::rotate(cycle.begin(), cycle.begin() + i, cycle.end());
    std::rotate(links.begin(), links.begin() + i, links.end());
    base_[b] = v;
  }

  std::uint32_t n_;
  std::span<const CostEdge> edges_;
  const MatchingProgress& progress_;
  std::uint32_t free_at_start_ = 0;
  std::vector<std::int64_t> cost_;  // doubled
  std::vector<std::uint32_t> offsets_, incident_;
  // Per vertex.
  std::vector<std::int64_t> y_;
  std::vector<std::int32_t> mate_;  // endpoint at the partner, or kNone
  // Vertex groups: the vertices of one top-level node form one group, whose offset is added
  // to their stored duals (settling a node is then O(1)). A shrink keeps the largest child's
  // group and moves the others' vertices into it; an expand gives the other children new groups
  // with the same offset (union by size: each vertex moves O(log n) times per nesting).
  std::vector<std::uint32_t> group_;      // per vertex
  std::vector<std::uint32_t> group_top_;  // per group: its top-level node
  std::vector<std::int64_t> offset_;      // per group
  std::vector<std::uint32_t> free_groups_;
  std::vector<std::uint32_t> group_of_, size_, big_child_;  // per node (top-level: its group)
  // Per node: vertices 0..n-1, blossoms from n on.
  std::vector<std::int32_t> parent_;
  std::vector<std::uint32_t> base_;
  std::vector<Label> label_;
  std::vector<std::int32_t> labelend_;  // endpoint in the parent through which it was reached
  std::vector<std::int64_t> join_, z_;
  std::vector<std::vector<std::uint32_t>> childs_;  // blossoms: the odd cycle, base first
  std::vector<std::vector<std::int32_t>> endps_;    // edge i joins childs i and i + 1
  std::vector<std::uint32_t> tree_of_;                // per node: its tree, or kNoTree
  std::vector<std::vector<std::uint32_t>> trees_;     // per tree: the nodes it labelled
  std::uint32_t alive_trees_ = 0;
  std::vector<std::uint32_t> mark_, free_ids_, stack_, minus_vertices_, dissolved_;
  std::vector<std::vector<std::uint32_t>> boundary_;  // per group (blossom groups only)
  std::vector<std::uint32_t> listed_in_;              // per vertex: the group listing it
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work_;
  std::uint32_t stamp_ = 0;
  std::int64_t eps_ = 0;
  std::uint64_t seq_ = 0;
  EventQueue grow_queue_, shrink_queue_, expand_queue_;
};

// The graph renumbered breadth first (vertices in the order a BFS from the lowest unvisited
// vertex reaches them; edges by their lower new endpoint), so that the vertices a tree grows
// over, and their edges, sit close together in memory. The solver is bound by memory latency:
// on square-hole-100k/300k (nearly the same events and the same matching) CPU time went
// 0.77 -> 0.55 s and 3.43 -> 2.60 s (medians of 3). The greedy start, which visits vertices in
// index order, also leaves fewer vertices free in this order (uniform-100k: 4,238 -> 1,312
// free, 7.95 -> 4.15 s).
struct LocalGraph {
  std::vector<CostEdge> edges;           // renumbered
  std::vector<std::uint32_t> edge_from;  // original index of each renumbered edge
};
LocalGraph breadth_first_order(std::uint32_t n, std::span<const CostEdge> edges) {
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
  constexpr std::uint32_t kUnseen = 0xffffffffu;
  std::vector<std::uint32_t> new_id(n, kUnseen), queue;
  queue.reserve(n);
  for (std::uint32_t s = 0; s < n; ++s) {
    if (new_id[s] != kUnseen) continue;
    new_id[s] = static_cast<std::uint32_t>(queue.size());
    queue.push_back(s);
    for (std::size_t head = queue.size() - 1; head < queue.size(); ++head)
      for (std::uint32_t i = offsets[queue[head]]; i < offsets[queue[head] + 1]; ++i)
        if (new_id[adjacent[i]] == kUnseen) {
          new_id[adjacent[i]] = static_cast<std::uint32_t>(queue.size());
          queue.push_back(adjacent[i]);
        }
  }
  // Edges bucketed by their lower new endpoint (a counting sort, stable).
  std::fill(offsets.begin(), offsets.end(), 0);
  for (const CostEdge& e : edges) ++offsets[std::min(new_id[e.u], new_id[e.v]) + 1];
  for (std::uint32_t v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  LocalGraph g;
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

}  // namespace

bool min_cost_perfect_matching(std::uint32_t num_nodes, std::span<const CostEdge> edges,
                               std::vector<char>& matched, const MatchingProgress& progress) {
  // Checked here, in the caller's numbering (the solver sees the renumbered graph).
  for (std::size_t e = 0; e < edges.size(); ++e)
    QV_ASSERT(edges[e].u < num_nodes && edges[e].v < num_nodes && edges[e].u != edges[e].v,
              "edge " << e << " (" << edges[e].u << ", " << edges[e].v << ") in a graph of "
                      << num_nodes);
  const LocalGraph local = breadth_first_order(num_nodes, edges);
  Solver solver(num_nodes, local.edges, progress);
  if (!solver.run()) return false;
  std::vector<char> local_matched;
  solver.read(local_matched);
  matched.assign(edges.size(), 0);
  for (std::size_t k = 0; k < local_matched.size(); ++k)
    matched[local.edge_from[k]] = local_matched[k];
  return true;
}

}  // namespace quadval::recombine_detail
