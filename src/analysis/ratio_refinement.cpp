#include "analysis/ratio_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"

namespace quadval {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Leaf {
  double lower;
  double err_b, err_c;
  int slot;
  long id;  // creation order: a deterministic tie-break
  bool operator>(const Leaf& o) const { return lower != o.lower ? lower > o.lower : id > o.id; }
};

// The quotient's lower bound on one subdomain (-inf when some c_i is not proven positive).
double leaf_lower(const double* b, double eb, const double* c, double ec, std::size_t n) {
  double lower = kInf;
  for (std::size_t i = 0; i < n; ++i) {
    const double c_lo = next_down(c[i] - ec), c_hi = next_up(c[i] + ec);
    if (!(c_lo > 0)) return -kInf;
    const double b_lo = next_down(b[i] - eb);
    lower = std::min(lower, next_down(b_lo / (b_lo >= 0 ? c_hi : c_lo)));
  }
  return lower;
}

// The least vertex value, rounded up (+inf when no vertex has c proven positive).
double vertex_upper(const BezierBasis& basis, const double* b, double eb, const double* c, double ec) {
  double upper = kInf;
  for (int v : basis.vertex_indices()) {
    const auto i = static_cast<std::size_t>(v);
    const double c_lo = next_down(c[i] - ec), c_hi = next_up(c[i] + ec);
    if (!(c_lo > 0)) continue;
    const double b_hi = next_up(b[i] + eb);
    upper = std::min(upper, next_up(b_hi / (b_hi >= 0 ? c_lo : c_hi)));
  }
  return upper;
}

}  // namespace

RatioRefinement refine_ratio_minimum(const BezierBasis& basis, const double* b, double err_b,
                                     const double* c, double err_c, double abs_tol,
                                     double rel_tol, int max_subdivisions) {
  const auto s = static_cast<std::size_t>(basis.size());
  RatioRefinement out;
  // Slots of 2 s doubles: b then c (contiguous, for subdivide_many). Per-thread scratch,
  // reused from element to element (no allocation once warm).
  thread_local std::vector<double> pool, parent, scratch;
  thread_local std::vector<int> free_slots;
  pool.assign(b, b + s);
  pool.insert(pool.end(), c, c + s);
  parent.resize(2 * s);
  scratch.resize(2 * s);
  free_slots.clear();
  std::priority_queue<Leaf, std::vector<Leaf>, std::greater<>> heap;
  long next_id = 0;
  double upper = vertex_upper(basis, b, err_b, c, err_c);
  const double root_lower = leaf_lower(b, err_b, c, err_c, s);
  if (root_lower == -kInf && upper == kInf) {
    out.positive = false;
    out.lower = -kInf;
    out.upper = kInf;
    return out;
  }
  heap.push({root_lower, err_b, err_c, 0, next_id++});
  const auto met = [&](double lower) {
    return next_up(upper - lower) <= std::max(abs_tol, rel_tol * std::abs(upper));
  };
  while (!met(heap.top().lower) && out.subdivisions < max_subdivisions) {
    const Leaf top = heap.top();
    heap.pop();
    ++out.subdivisions;
    const auto off = static_cast<std::size_t>(top.slot) * 2 * s;
    std::copy(pool.begin() + static_cast<std::ptrdiff_t>(off),
              pool.begin() + static_cast<std::ptrdiff_t>(off + 2 * s), parent.begin());
    free_slots.push_back(top.slot);
    const double max_b = largest_magnitude(parent.data(), s), max_c = largest_magnitude(parent.data() + s, s);
    const double eb = next_up((top.err_b + basis.subdivision_rounding() * max_b) * (1 + 1e-12));
    const double ec = next_up((top.err_c + basis.subdivision_rounding() * max_c) * (1 + 1e-12));
    for (int q = 0; q < basis.num_children(); ++q) {
      int slot;
      if (!free_slots.empty()) {
        slot = free_slots.back();
        free_slots.pop_back();
      } else {
        slot = static_cast<int>(pool.size() / (2 * s));
        pool.resize(pool.size() + 2 * s);
      }
      double* child = pool.data() + static_cast<std::size_t>(slot) * 2 * s;
      basis.subdivide_many(q, parent.data(), 2, child, scratch.data());
      upper = std::min(upper, vertex_upper(basis, child, eb, child + s, ec));
      heap.push({leaf_lower(child, eb, child + s, ec, s), eb, ec, slot, next_id++});
    }
  }
  out.lower = heap.top().lower;
  out.upper = upper;
  out.tolerance_met = met(out.lower);
  return out;
}

}  // namespace quadval
