#include "smoothing.hpp"

#include <algorithm>
#include <cmath>

namespace quadval::recombine_detail {

std::size_t smooth(MixedMesh& m, const std::vector<char>& fixed, const SmoothingOptions& options) {
  if (options.passes <= 0) return 0;
  // Static CSR node -> elements: the topology does not change here.
  const std::size_t n = m.num_nodes();
  std::vector<std::uint32_t> offsets(n + 1, 0);
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e])
      for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i) ++offsets[m.elements[e][i] + 1];
  for (std::size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  std::vector<std::uint32_t> incident(offsets[n]);
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t e = 0; e < m.elements.size(); ++e)
      if (m.alive[e])
        for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i)
          incident[fill[m.elements[e][i]]++] = static_cast<std::uint32_t>(e);
  }
  std::vector<double> score(m.elements.size(), 0.0);
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e]) score[e] = element_score(m, e);

  std::size_t accepted = 0;
  std::vector<double> trial;
  for (int pass = 0; pass < 2 * options.passes; ++pass) {
    const bool raise_mean = pass >= options.passes;
    std::size_t accepted_this_pass = 0;
    double global_min = 2.0;
    for (std::size_t e = 0; e < m.elements.size(); ++e)
      if (m.alive[e]) global_min = std::min(global_min, score[e]);
    for (NodeIndex v = 0; v < n; ++v) {
      if (fixed[v] || offsets[v] == offsets[v + 1]) continue;
      const std::array<double, 3> x = m.point(v);
      double sum[3] = {0, 0, 0}, weights = 0;
      std::array<double, 3> normal{0, 0, 0};
      double old_min = 2.0;
      for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
        const std::uint32_t e = incident[i];
        old_min = std::min(old_min, score[e]);
        for (int d = 0; d < 3; ++d) normal[d] += m.normal[e][d];
        const auto& el = m.elements[e];
        const int c = corner_of(el, v);
        // Each edge neighbour appears in two elements at an interior node: each counts once
        // per element, which weighs them equally.
        for (NodeIndex j : {next_corner(el, c), prev_corner(el, c)}) {
          const auto y = m.point(j);
          double w = 1.0;
          if (options.size_field != nullptr) {
            const double h = (*options.size_field)(0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1]),
                                                   0.5 * (x[2] + y[2]));
            w = h > 0 && std::isfinite(h) ? 1.0 / h : 1.0;
          }
          for (int d = 0; d < 3; ++d) sum[d] += w * y[d];
          weights += w;
        }
      }
      std::array<double, 3> move{sum[0] / weights - x[0], sum[1] / weights - x[1],
                                 sum[2] / weights - x[2]};
      if (options.tangential) {
        const double nn = normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2];
        if (nn > 0) {
          const double h = (move[0] * normal[0] + move[1] * normal[1] + move[2] * normal[2]) / nn;
          for (int d = 0; d < 3; ++d) move[d] -= h * normal[d];
        }
      }
      for (double fraction : {1.0, 0.5}) {
        for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d] + fraction * move[d];
        trial.clear();
        double new_min = 2.0, new_sum = 0, old_sum = 0;
        for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
          trial.push_back(element_score(m, incident[i]));
          new_min = std::min(new_min, trial.back());
          new_sum += trial.back();
          old_sum += score[incident[i]];
        }
        // Phase 1: never lower the worst element at v. Phase 2: also take moves that raise
        // the sum of the scores at v while keeping them above the mesh's current worst.
        const bool ok = new_min >= old_min ||
                        (raise_mean && new_min >= global_min && new_min > 0 && new_sum > old_sum);
        if (ok) {
          for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i)
            score[incident[i]] = trial[i - offsets[v]];
          ++accepted_this_pass;
          break;
        }
        for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d];
      }
    }
    accepted += accepted_this_pass;
    if (accepted_this_pass == 0 && raise_mean) break;
  }
  return accepted;
}

}  // namespace quadval::recombine_detail
