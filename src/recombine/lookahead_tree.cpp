#include "lookahead_tree.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <queue>
#include <random>

#include "quadval/error.hpp"

namespace quadval::recombine_detail {

namespace {

using Rng = std::mt19937_64;

// The tie-break order of the uniform tree: a random permutation of the pairs, drawn first
// from the run's stream (the same draw for both implementations below).
std::vector<std::uint32_t> tie_break_order(std::size_t num_pairs, Rng& rng) {
  std::vector<std::uint32_t> order(num_pairs);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

// Uniform tree, horizon 1: the best allowed pair first. A pair found forbidden is dropped for
// good (forbidden is forever), so this is the uniform tree of horizon 1 exactly, ties
// included: among equal rewards the pair earlier in the tie-break order wins, as in
// UniformTree.
void uniform_greedy(LookaheadState& s, Rng& rng) {
  const LookaheadGraph& g = s.graph();
  const std::vector<std::uint32_t> order = tie_break_order(g.pairs.size(), rng);
  std::vector<std::uint32_t> rank(g.pairs.size());  // rank[p]: position of p in the order
  for (std::uint32_t i = 0; i < order.size(); ++i) rank[order[i]] = i;
  auto worse = [&](std::uint32_t a, std::uint32_t b) {
    if (g.reward[a] != g.reward[b]) return g.reward[a] < g.reward[b];
    return rank[a] > rank[b];
  };
  std::vector<std::uint32_t> all(g.pairs.size());
  std::iota(all.begin(), all.end(), 0u);
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, decltype(worse)> heap(
      worse, std::move(all));
  while (!heap.empty()) {
    const std::uint32_t p = heap.top();
    heap.pop();
    if (s.allowed(p)) {
      s.apply(p);
      s.settle();
    }
  }
}

// Uniform tree, any horizon: every allowed pair at every node.
class UniformTree {
 public:
  UniformTree(LookaheadState& s, int horizon, Rng& rng)
      : s_(s), horizon_(horizon), order_(tie_break_order(s.graph().pairs.size(), rng)) {}
  void run() {
    while (true) {
      std::uint32_t best_p = kNone;
      double best = -1.0;
      for (std::uint32_t p : order_) {
        if (!s_.allowed(p)) continue;
        const double v = value_after(p, 1);
        if (v > best) best = v, best_p = p;
      }
      if (best_p == kNone) return;
      s_.apply(best_p);
      s_.settle();
    }
  }

 private:
  double value_after(std::uint32_t p, int depth) {
    s_.apply(p);
    double best = 0.0;
    if (depth < horizon_)
      for (std::uint32_t q : order_)
        if (s_.allowed(q)) best = std::max(best, value_after(q, depth + 1));
    s_.undo();
    return s_.graph().reward[p] + best;
  }
  LookaheadState& s_;
  int horizon_;
  std::vector<std::uint32_t> order_;
};

class SelectiveTree {
 public:
  SelectiveTree(LookaheadState& s, int horizon, Rng& rng)
      : s_(s), g_(s.graph()), horizon_(horizon), rng_(rng), key_(g_.num_triangles, 0),
        slot_(g_.num_triangles, 0), mark_(g_.num_triangles, 0) {
    for (std::uint32_t t = 0; t < g_.num_triangles; ++t) place(t, s_.allowed_options(t));
  }

  void run() {
    while (true) {
      std::array<std::uint32_t, 3> options;
      const std::uint32_t t = pick_global(true, options);
      if (t == kNone) return;
      const int n = options_count_;
      std::shuffle(options.begin(), options.begin() + n, rng_);
      std::uint32_t best_p = options[0];
      if (n > 1 && horizon_ > 1) {
        double best = -1.0;
        for (int i = 0; i < n; ++i) {
          made_.assign(1, options[i]);
          const double v = value_after(options[i], 1);
          if (v > best) best = v, best_p = options[i];
        }
      }
      commit(best_p);
    }
  }

 private:
  // Buckets 1..3 of free triangles by cached allowed-option count (an upper bound).
  void place(std::uint32_t t, int k) {
    if (key_[t] == k) return;
    if (key_[t] != 0) {
      auto& b = bucket_[key_[t]];
      const std::uint32_t last = b.back();
      b[slot_[t]] = last;
      slot_[last] = slot_[t];
      b.pop_back();
    }
    key_[t] = static_cast<std::uint8_t>(k);
    if (k != 0) {
      slot_[t] = static_cast<std::uint32_t>(bucket_[k].size());
      bucket_[k].push_back(t);
    }
  }

  // A free triangle with the fewest allowed options (>= 1), its options in `options` and
  // their number in options_count_; kNone if none. mutate: the committed state, where stale
  // entries are fixed; otherwise inside the tree, read-only.
  std::uint32_t pick_global(bool mutate, std::array<std::uint32_t, 3>& options) {
    for (int k = 1; k <= 3; ++k) {
      auto& b = bucket_[k];
      for (int tries = 0; !b.empty() && tries < 16; ++tries) {
        const std::uint32_t t = b[rng_() % b.size()];
        const int a = s_.is_free(t) ? s_.allowed_options(t, &options) : 0;
        if (a == k || (!mutate && a >= 1)) {
          options_count_ = a;
          return t;
        }
        if (mutate) place(t, a);
      }
    }
    // Rare (sampling missed): scan.
    for (int k = 1; k <= 3; ++k) {
      auto& b = bucket_[k];
      for (std::size_t i = 0; i < b.size();) {
        const std::uint32_t t = b[i];
        const int a = s_.is_free(t) ? s_.allowed_options(t, &options) : 0;
        if (a >= 1 && (a == k || !mutate)) {
          options_count_ = a;
          return t;
        }
        if (mutate) {
          place(t, a);  // moved out of this slot (a != k): look at slot i again
        } else {
          ++i;
        }
      }
    }
    return kNone;
  }

  // N(y) of §5: free triangles next to the quads made along the branch; the first non-empty
  // P_k ∩ N, random among them.
  std::uint32_t pick_near(std::array<std::uint32_t, 3>& options) {
    ++stamp_;
    std::uint32_t chosen = kNone;
    int fewest = 4, ties = 0;
    std::array<std::uint32_t, 3> o;
    for (std::uint32_t p : made_)
      for (std::uint32_t q : {g_.pairs[p].t0, g_.pairs[p].t1})
        for (std::uint32_t t : g_.neighbor[q]) {
          if (t == kNone || !s_.is_free(t) || mark_[t] == stamp_) continue;
          mark_[t] = stamp_;
          const int a = s_.allowed_options(t, &o);
          if (a == 0 || a > fewest) continue;
          if (a < fewest) fewest = a, ties = 0;
          if (rng_() % static_cast<std::uint64_t>(++ties) == 0) chosen = t, options = o;
        }
    options_count_ = chosen == kNone ? 0 : fewest;
    return chosen;
  }

  double value_after(std::uint32_t p, int depth) {
    s_.apply(p);
    double best = 0.0;
    if (depth < horizon_) {
      std::array<std::uint32_t, 3> options;
      std::uint32_t t = pick_near(options);
      if (t == kNone) t = pick_global(false, options);
      if (t != kNone) {
        const int n = options_count_;
        for (int i = 0; i < n; ++i) {
          made_.push_back(options[i]);
          best = std::max(best, value_after(options[i], depth + 1));
          made_.pop_back();
        }
      }
    }
    s_.undo();
    return g_.reward[p] + best;
  }

  void commit(std::uint32_t p) {
    s_.apply(p);
    s_.settle();
    place(g_.pairs[p].t0, 0);
    place(g_.pairs[p].t1, 0);
    // Counts change through the corners of the new quad: re-count the free triangles at its
    // nodes and their neighbours (further changes only lower counts: re-checked when drawn).
    ++stamp_;
    for (NodeIndex v : lookahead_quad(g_, p))
      for (std::uint32_t i = g_.node_offsets[v]; i < g_.node_offsets[v + 1]; ++i) {
        const std::uint32_t t = g_.node_triangles[i];
        recount(t);
        for (std::uint32_t u : g_.neighbor[t])
          if (u != kNone) recount(u);
      }
  }
  void recount(std::uint32_t t) {
    if (mark_[t] == stamp_) return;
    mark_[t] = stamp_;
    place(t, s_.is_free(t) ? s_.allowed_options(t) : 0);
  }

  LookaheadState& s_;
  const LookaheadGraph& g_;
  int horizon_;
  Rng& rng_;
  std::vector<std::uint8_t> key_;
  std::vector<std::uint32_t> slot_;
  std::vector<std::uint32_t> bucket_[4];
  std::vector<std::uint32_t> mark_;
  std::uint32_t stamp_ = 0;
  std::vector<std::uint32_t> made_;
  int options_count_ = 0;
};

}  // namespace

namespace {

LookaheadOutcome outcome_of(const LookaheadGraph& g, const LookaheadState& s, std::uint64_t seed,
                            std::chrono::steady_clock::time_point start) {
  LookaheadOutcome out;
  out.pairs = s.applied();
  out.run.seed = seed;
  // Summed afresh: the state's running sum carries the rounding of every apply/undo.
  for (std::uint32_t p : out.pairs) out.run.quality += g.reward[p];
  out.run.quads = s.quads();
  out.run.triangles_left = g.num_triangles - 2 * s.quads();
  out.run.search_steps = s.search_steps();
  out.run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

LookaheadOutcome lookahead_run(const LookaheadGraph& g, const LookaheadOptions& options,
                               std::uint64_t seed) {
  QV_ASSERT(options.horizon >= 1, "horizon " << options.horizon);
  const auto start = std::chrono::steady_clock::now();
  Rng rng(seed);
  LookaheadState s(g);
  if (options.tree == LookaheadTree::uniform && options.horizon == 1) {
    uniform_greedy(s, rng);
  } else if (options.tree == LookaheadTree::uniform) {
    UniformTree(s, options.horizon, rng).run();
  } else {
    SelectiveTree(s, options.horizon, rng).run();
  }
  return outcome_of(g, s, seed, start);
}

LookaheadOutcome uniform_enumeration_run(const LookaheadGraph& g, int horizon,
                                         std::uint64_t seed) {
  QV_ASSERT(horizon >= 1, "horizon " << horizon);
  const auto start = std::chrono::steady_clock::now();
  Rng rng(seed);
  LookaheadState s(g);
  UniformTree(s, horizon, rng).run();
  return outcome_of(g, s, seed, start);
}

LookaheadBest lookahead_best_of(const LookaheadGraph& g, const LookaheadOptions& options) {
  QV_ASSERT(options.runs >= 1, "runs " << options.runs);
  LookaheadBest best;
  best.runs.resize(static_cast<std::size_t>(options.runs));
  bool have = false;
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < options.runs; ++i) {
    LookaheadOutcome o = lookahead_run(g, options, options.seed + static_cast<std::uint64_t>(i));
    best.runs[static_cast<std::size_t>(i)] = o.run;
#pragma omp critical(quadval_lookahead_best)
    {
      const auto index = static_cast<std::size_t>(i);
      if (!have || o.run.quality > best.best.run.quality ||
          (o.run.quality == best.best.run.quality && index < best.best_run)) {
        best.best = std::move(o);
        best.best_run = index;
        have = true;
      }
    }
  }
  return best;
}

}  // namespace quadval::recombine_detail
