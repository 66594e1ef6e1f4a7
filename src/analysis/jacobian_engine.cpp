// Best-first adaptive subdivision (Paper III §4.2, Algorithm 3), in floating point with a
// carried error bound per subdomain, and in exact rationals.
//
// Bounds per subdomain (eqs. 16-17, 21-22): min J >= min_i b_i (convex hull), and
// min J <= b_v for every vertex coefficient b_v (a value of J). With |b~ - b| <= err:
// lower = min b~ - err and upper = min_v b~_v + err, rounded outward.
// A child of a subdomain (one bisection, bezier/bernstein_bisection.hpp) has err_child =
// err + halving_rounding * max|b~| (averages never exceed their inputs, so old errors do
// not grow). The exact refinement below uses the exact midpoint subdivision matrices.
#include "analysis/jacobian_engine.hpp"

#include <algorithm>
#include <cmath>
#include <queue>

#include "bezier/bezier_exact.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "bezier/rational_rounding.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double down(double x) { return next_down(x); }
double up(double x) { return next_up(x); }

// Min-heap on lower (std heap functions are max-heaps: invert the comparison).
bool heap_less(const BoundsWorkspace::Impl::Leaf& a, const BoundsWorkspace::Impl::Leaf& b) {
  return a.lower > b.lower;
}

// Applies per-factor exact matrices along each axis (see BezierBasis::apply_factors).
template <class MatrixOf>
std::vector<mpq_class> apply_exact(const BezierBasis& b, std::vector<mpq_class> in,
                                   MatrixOf matrix_of) {
  const auto size = static_cast<std::size_t>(b.size());
  std::size_t stride = 1;
  std::vector<mpq_class> out(size);
  for (std::size_t f = 0; f < b.factors().size(); ++f) {
    const auto s = static_cast<std::size_t>(b.factors()[f]->size());
    const std::size_t outer = size / (s * stride);
    const std::vector<mpq_class>& m = matrix_of(f);
    for (std::size_t o = 0; o < outer; ++o)
      for (std::size_t a = 0; a < s; ++a)
        for (std::size_t i = 0; i < stride; ++i) {
          mpq_class sum = 0;
          for (std::size_t j = 0; j < s; ++j) {
            const mpq_class& w = m[a * s + j];
            if (sgn(w) != 0) sum += w * in[o * s * stride + j * stride + i];
          }
          out[o * s * stride + a * stride + i] = sum;
        }
    in.swap(out);
    stride *= s;
  }
  return in;
}

std::vector<mpq_class> exact_subdivide(const BezierBasis& b, const std::vector<mpq_class>& in,
                                       int child) {
  const auto digits = b.child_digits(child);
  return apply_exact(b, in, [&](std::size_t f) -> const std::vector<mpq_class>& {
    // one child's block of the factor's subdivision matrices
    thread_local std::vector<mpq_class> block;
    const BernsteinSimplex& fac = *b.factors()[f];
    const auto n = static_cast<std::size_t>(fac.size()) * static_cast<std::size_t>(fac.size());
    const auto& all = fac.exact().subdivision;
    block.assign(all.begin() + static_cast<std::ptrdiff_t>(n * static_cast<std::size_t>(digits[f])),
                 all.begin() + static_cast<std::ptrdiff_t>(n * (static_cast<std::size_t>(digits[f]) + 1)));
    return block;
  });
}

}  // namespace

MinRefinement refine_minimum(const BezierBasis& basis, const double* coeffs, double err,
                             bool need_sign, double tol, int max_subdivisions,
                             BoundsWorkspace::Impl& ws) {
  const auto size = static_cast<std::size_t>(basis.size());
  const auto vertices = basis.vertex_indices();
  // Best-first, the subdomain with the least bound is halved (one edge bisection,
  // BernsteinBisection::halve), `levels` halvings counting as one subdivision. Against
  // BezierBasis's 2^dim midpoint children, one thread: quadval_bench BM_CheckCurvedTetP3
  // (1M cubic tetrahedra, 17% invalid, 12% subdivided) 3.33 -> 1.19 s; --measure jacobian
  // on warped_tetrahedron_o3 50 -> 18 ms, hex_box 13 -> 7 ms; the small meshes within noise.
  const BernsteinBisection* bisection = nullptr;  // on the first halving
  int levels = 1;
  long halvings = 0;
  ws.pool.clear();
  ws.free_slots.clear();
  ws.heap.clear();
  ws.scratch.resize(2 * size);

  MinRefinement r;
  r.upper = kInf;
  double floor = kInf;  // min lower bound of subdomains dropped from the heap

  const auto bounds_of = [&](const double* b, double e, double& lower, double& upper,
                             double& max_abs) {
    const double lo = least_value(b, size), big = largest_magnitude(b, size);
    double hi = kInf;
    for (int v : vertices) hi = std::min(hi, b[v]);
    lower = down(lo - e);
    upper = up(hi + e);
    max_abs = big;
  };
  const auto new_slot = [&]() {
    if (!ws.free_slots.empty()) {
      const int s = ws.free_slots.back();
      ws.free_slots.pop_back();
      return s;
    }
    const int s = static_cast<int>(ws.pool.size() / size);
    ws.pool.resize(ws.pool.size() + size);
    return s;
  };
  const auto done = [&](double lower) {
    const bool sign_ok = !need_sign || lower > 0 || r.upper <= 0;
    return sign_ok && (r.upper - lower <= tol);
  };

  {
    double lower, upper, big;
    bounds_of(coeffs, err, lower, upper, big);
    r.upper = upper;
    const int slot = new_slot();
    std::copy(coeffs, coeffs + size, ws.pool.begin() + static_cast<std::ptrdiff_t>(slot * size));
    ws.heap.push_back({lower, err, slot, 0, BisectionState{}});
  }

  for (;;) {
    const double lower = std::min(floor, ws.heap.empty() ? kInf : ws.heap.front().lower);
    r.lower = lower;
    if (done(lower)) {
      r.settled = true;
      break;
    }
    if (ws.heap.empty() || halvings >= static_cast<long>(max_subdivisions) * levels) break;
    if (bisection == nullptr) {
      // Same factors and coefficient layout as the basis.
      if (ws.bisection_basis != &basis) {
        std::vector<FactorDegree> factors;
        for (const BernsteinSimplex* f : basis.factors()) factors.push_back({f->dim(), f->degree()});
        ws.bisection = &bernstein_bisection(factors);
        ws.bisection_basis = &basis;
      }
      bisection = ws.bisection;
      levels = bisection->levels();
      ws.heap.front().state = bisection->root_state();  // the root, the only leaf so far
    }
    std::pop_heap(ws.heap.begin(), ws.heap.end(), heap_less);
    const BoundsWorkspace::Impl::Leaf leaf = ws.heap.back();
    ws.heap.pop_back();
    ++halvings;
    r.subdivisions = static_cast<int>((halvings + levels - 1) / levels);

    const double* parent = ws.pool.data() + static_cast<std::size_t>(leaf.slot) * size;
    const double parent_min = least_value(parent, size), parent_max_abs = largest_magnitude(parent, size);
    if (std::abs(parent_min) <= 8 * leaf.err) r.rounding_limited = true;
    // Averages never exceed their inputs: the parent's error plus the halving's rounding.
    const double child_err =
        up((leaf.err + bisection->halving_rounding_relative() * parent_max_abs + bisection->halving_rounding_absolute()) *
           (1 + 1e-12));
    BisectionState states[2];
    bisection->halve(parent, 1, leaf.state, ws.scratch.data(), states);
    ws.free_slots.push_back(leaf.slot);
    for (int q = 0; q < 2; ++q) {
      const int slot = new_slot();
      double* child = ws.pool.data() + static_cast<std::size_t>(slot) * size;
      std::copy(ws.scratch.begin() + static_cast<std::ptrdiff_t>(q * size),
                ws.scratch.begin() + static_cast<std::ptrdiff_t>((q + 1) * size), child);
      double lo, hi, big;
      bounds_of(child, child_err, lo, hi, big);
      r.upper = std::min(r.upper, hi);
      const int depth = (states[q].step + levels - 1) / levels;
      r.depth = std::max(r.depth, depth);
      // Dropped: proven positive while settling the sign, or unable to lower the
      // minimum by more than the tolerance. Either way its lower bound is kept in floor.
      const bool proven_positive = need_sign && !std::isfinite(tol) && lo > 0;
      const bool within_tol = std::isfinite(tol) && lo >= r.upper - tol &&
                              (!need_sign || lo > 0 || r.upper <= 0);
      if (proven_positive || within_tol) {
        floor = std::min(floor, lo);
        ws.free_slots.push_back(slot);
      } else {
        ws.heap.push_back({lo, child_err, slot, depth, states[q]});
        std::push_heap(ws.heap.begin(), ws.heap.end(), heap_less);
      }
    }
  }
  return r;
}

std::vector<mpq_class> exact_to_bezier(const BezierBasis& basis, std::vector<mpq_class> samples) {
  return apply_exact(basis, std::move(samples), [&](std::size_t f) -> const std::vector<mpq_class>& {
    return basis.factors()[f]->exact().to_bezier;
  });
}

ExactRefinement exact_validity(const BezierBasis& basis, std::vector<mpq_class> coeffs,
                               int max_subdivisions) {
  struct Node {
    mpq_class lower;
    std::vector<mpq_class> c;
    int depth;
  };
  const auto cmp = [](const Node* a, const Node* b) { return a->lower > b->lower; };
  std::priority_queue<Node*, std::vector<Node*>, decltype(cmp)> heap(cmp);
  std::vector<std::unique_ptr<Node>> owned;
  ExactRefinement r;
  const auto vertices = basis.vertex_indices();
  bool have_upper = false;
  mpq_class floor;
  bool have_floor = false;
  const auto push = [&](std::vector<mpq_class> c, int depth) {
    mpq_class lo = *std::min_element(c.begin(), c.end());
    for (int v : vertices) {
      if (!have_upper || c[static_cast<std::size_t>(v)] < r.upper) {
        r.upper = c[static_cast<std::size_t>(v)];
        have_upper = true;
      }
    }
    if (lo > 0) {  // proven positive here: keep only its bound
      if (!have_floor || lo < floor) floor = lo;
      have_floor = true;
      return;
    }
    owned.push_back(std::make_unique<Node>(Node{lo, std::move(c), depth}));
    heap.push(owned.back().get());
  };
  push(std::move(coeffs), 0);
  for (;;) {
    if (heap.empty()) {
      r.lower = floor;
      r.validity = Validity::valid;
      return r;
    }
    r.lower = heap.top()->lower;
    if (have_floor && floor < r.lower) r.lower = floor;
    if (r.upper <= 0) {
      r.validity = Validity::invalid;
      return r;
    }
    if (r.subdivisions >= max_subdivisions) return r;
    Node* n = heap.top();
    heap.pop();
    ++r.subdivisions;
    for (int q = 0; q < basis.num_children(); ++q) {
      r.depth = std::max(r.depth, n->depth + 1);
      push(exact_subdivide(basis, n->c, q), n->depth + 1);
    }
    n->c.clear();
    n->c.shrink_to_fit();
  }
}

}  // namespace quadval
