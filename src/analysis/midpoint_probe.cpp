#include "analysis/midpoint_probe.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include "analysis/outward_rounding.hpp"
#include "analysis/product_tables.hpp"
#include "bezier/multi_index_table.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

// A table as midpoint_probe_upper reads it: generated at build time or built here.
struct ProbeRows {
  std::span<const int> first, index;
  std::span<const double> weight;
  double gamma = 0;
};

// One factor's points: its vertices and edge midpoints, each as (factor index, weight)
// terms, and whether it is a vertex.
struct FactorPoint {
  std::vector<std::pair<int, double>> terms;
  bool vertex = false;
};

std::vector<FactorPoint> factor_points(const BernsteinSimplex& f) {
  const int d = f.dim(), n = f.degree();
  const auto alphas = f.multi_indices();
  const MultiIndexTable table({alphas.begin(), alphas.end()}, n);
  const auto index_of = [&](const std::array<int, 4>& a) {
    const int i = table(a);
    QV_ASSERT(i >= 0, "multi-index outside the factor");
    return i;
  };
  std::vector<FactorPoint> out;
  for (int a = 0; a <= d; ++a) {
    std::array<int, 4> alpha{};
    alpha[static_cast<std::size_t>(a)] = n;
    out.push_back({{{index_of(alpha), 1.0}}, true});
  }
  const double scale = std::ldexp(1.0, -n);
  for (int a = 0; a <= d; ++a)
    for (int b = a + 1; b <= d; ++b) {
      FactorPoint p;
      double binomial = 1;  // C(n, k), exact in double at the degrees supported
      for (int k = 0; k <= n; ++k) {
        std::array<int, 4> alpha{};
        alpha[static_cast<std::size_t>(a)] = k;
        alpha[static_cast<std::size_t>(b)] = n - k;
        p.terms.emplace_back(index_of(alpha), binomial * scale);
        binomial = binomial * (n - k) / (k + 1);
      }
      out.push_back(std::move(p));
    }
  return out;
}

}  // namespace

MidpointProbeTable build_midpoint_probe_table(const BezierBasis& basis) {
  MidpointProbeTable t;
  // Partial tensor points: (terms over the factors so far, all of them vertices so far).
  std::vector<std::pair<std::vector<std::pair<int, double>>, bool>> partial{{{{0, 1.0}}, true}};
  int stride = 1;
  for (const BernsteinSimplex* f : basis.factors()) {
    std::vector<std::pair<std::vector<std::pair<int, double>>, bool>> next;
    for (const auto& [terms, vertex] : partial)
      for (const FactorPoint& p : factor_points(*f)) {
        std::vector<std::pair<int, double>> combined;
        for (const auto& [i, w] : terms)
          for (const auto& [j, v] : p.terms) combined.emplace_back(i + stride * j, w * v);
        next.emplace_back(std::move(combined), vertex && p.vertex);
      }
    partial = std::move(next);
    stride *= f->size();
  }
  std::size_t longest = 0;
  for (const auto& [terms, vertex] : partial) {
    if (vertex) continue;  // the domain's corners: their coefficients are values already
    for (const auto& [i, w] : terms) {
      t.index.push_back(i);
      t.weight.push_back(w);
    }
    t.first.push_back(static_cast<int>(t.index.size()));
    longest = std::max(longest, terms.size());
  }
  t.gamma = rounding_gamma(2 * static_cast<int>(longest) + 8);
  return t;
}

namespace {

// The generated table of a common basis; else one built on first use, kept for the process.
// (Building one was about 13 us of a 155 us check of quad_h0.4_o2 in a fresh process.)
ProbeRows probe_rows(const BezierBasis& basis) {
  thread_local const BezierBasis* last_basis = nullptr;
  thread_local ProbeRows last_rows;
  if (&basis == last_basis) return last_rows;
  if (const ProbeTableView* g = generated_probe_table(basis.family(), basis.order())) {
    last_rows = {g->first, g->index, g->weight, g->gamma};
  } else {
    static std::mutex mutex;
    static std::vector<std::pair<const BezierBasis*, std::unique_ptr<const MidpointProbeTable>>> tables;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = std::find_if(tables.begin(), tables.end(), [&](const auto& e) { return e.first == &basis; });
    if (it == tables.end()) {
      tables.emplace_back(&basis, std::make_unique<const MidpointProbeTable>(build_midpoint_probe_table(basis)));
      it = tables.end() - 1;
    }
    const MidpointProbeTable& t = *it->second;
    last_rows = {t.first, t.index, t.weight, t.gamma};
  }
  last_basis = &basis;
  return last_rows;
}

}  // namespace

double midpoint_probe_upper(const BezierBasis& basis, const double* coeffs, double err) {
  const ProbeRows t = probe_rows(basis);
  double upper = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p + 1 < t.first.size(); ++p) {
    double value = 0, magnitude = 0;
    for (auto k = static_cast<std::size_t>(t.first[p]); k < static_cast<std::size_t>(t.first[p + 1]); ++k) {
      const double term = t.weight[k] * coeffs[t.index[k]];
      value += term;
      magnitude += std::abs(term);
    }
    // The error bound's own few operations are covered by the 1% on it.
    upper = std::min(upper, next_up(value + next_up((err + t.gamma * magnitude) * 1.01)));
  }
  return upper;
}

}  // namespace quadval
