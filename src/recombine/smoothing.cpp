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
      const bool sliding =
          fixed[v] && options.slides != nullptr && (*options.slides)[v][0] != kNoNode;
      if ((fixed[v] && !sliding) || offsets[v] == offsets[v + 1]) continue;
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
      std::array<double, 3> a{}, along{};
      if (sliding) {
        // Keep only the component along the side a-b.
        a = m.point((*options.slides)[v][0]);
        const auto b = m.point((*options.slides)[v][1]);
        along = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double ll = along[0] * along[0] + along[1] * along[1] + along[2] * along[2];
        const double t = (move[0] * along[0] + move[1] * along[1] + move[2] * along[2]) / ll;
        for (int d = 0; d < 3; ++d) move[d] = t * along[d];
      } else if (options.tangential) {
        const double nn = normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2];
        if (nn > 0) {
          const double h = (move[0] * normal[0] + move[1] * normal[1] + move[2] * normal[2]) / nn;
          for (int d = 0; d < 3; ++d) move[d] -= h * normal[d];
        }
      }
      for (double fraction : {1.0, 0.5}) {
        if (sliding) {
          // Strictly between a and b (s in (0, 1) along a-b), so the side keeps its order.
          double s = 0, ll = 0;
          for (int d = 0; d < 3; ++d) {
            s += (x[d] + fraction * move[d] - a[d]) * along[d];
            ll += along[d] * along[d];
          }
          if (!(s > 0 && s < ll)) continue;
        }
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

std::size_t polish_worst(MixedMesh& m, const std::vector<char>& fixed,
                         const SmoothingOptions& options, double share) {
  const std::vector<std::vector<std::uint32_t>> at = node_elements(m);
  std::vector<std::pair<double, std::uint32_t>> worst;
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e]) worst.push_back({element_score(m, e), static_cast<std::uint32_t>(e)});
  const std::size_t count = std::min(
      worst.size(), std::max<std::size_t>(16, static_cast<std::size_t>(share * worst.size())));
  std::partial_sort(worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(count),
                    worst.end());
  std::vector<NodeIndex> nodes;
  for (std::size_t i = 0; i < count; ++i) {
    const auto& el = m.elements[worst[i].second];
    for (int c = 0; c < MixedMesh::size(el); ++c) nodes.push_back(el[c]);
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());

  auto local_min = [&](NodeIndex v) {
    double low = 2.0;
    for (std::uint32_t e : at[v]) low = std::min(low, element_score(m, e));
    return low;
  };
  std::size_t kept = 0;
  for (NodeIndex v : nodes) {
    const bool sliding =
        fixed[v] && options.slides != nullptr && (*options.slides)[v][0] != kNoNode;
    if ((fixed[v] && !sliding) || at[v].empty()) continue;
    // Directions: the straight side, or two orthonormal tangents of the mean normal.
    std::array<double, 3> a{}, d1{}, d2{};
    int directions = 2;
    double edge = 0;
    int edges = 0;
    const auto x0 = m.point(v);
    std::array<double, 3> normal{0, 0, 0};
    for (std::uint32_t e : at[v]) {
      for (int k = 0; k < 3; ++k) normal[k] += m.normal[e][k];
      const auto& el = m.elements[e];
      const auto y = m.point(next_corner(el, corner_of(el, v)));
      edge += std::sqrt((y[0] - x0[0]) * (y[0] - x0[0]) + (y[1] - x0[1]) * (y[1] - x0[1]) +
                        (y[2] - x0[2]) * (y[2] - x0[2]));
      ++edges;
    }
    edge /= edges;
    auto unit = [](std::array<double, 3> u) {
      const double l = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      return std::array<double, 3>{u[0] / l, u[1] / l, u[2] / l};
    };
    std::array<double, 3> b{};
    if (sliding) {
      a = m.point((*options.slides)[v][0]);
      b = m.point((*options.slides)[v][1]);
      d1 = unit({b[0] - a[0], b[1] - a[1], b[2] - a[2]});
      directions = 1;
    } else {
      const auto n = unit(normal);
      // Any vector not parallel to n, made orthogonal to it; then n x d1.
      std::array<double, 3> t = std::abs(n[0]) < 0.9 ? std::array<double, 3>{1, 0, 0}
                                                     : std::array<double, 3>{0, 1, 0};
      const double tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
      d1 = unit({t[0] - tn * n[0], t[1] - tn * n[1], t[2] - tn * n[2]});
      d2 = {n[1] * d1[2] - n[2] * d1[1], n[2] * d1[0] - n[0] * d1[2], n[0] * d1[1] - n[1] * d1[0]};
    }
    double best = local_min(v);
    for (double h = 0.1 * edge; h >= 1e-3 * edge;) {
      bool improved = false;
      for (int k = 0; k < 2 * directions && !improved; ++k) {
        const auto& dir = k < 2 ? d1 : d2;
        const double step = (k % 2 == 0 ? h : -h);
        const auto x = m.point(v);
        const std::array<double, 3> y{x[0] + step * dir[0], x[1] + step * dir[1],
                                      x[2] + step * dir[2]};
        if (sliding) {  // strictly inside the side a-b
          double s = 0, ll = 0;
          for (int q = 0; q < 3; ++q) {
            s += (y[q] - a[q]) * (b[q] - a[q]);
            ll += (b[q] - a[q]) * (b[q] - a[q]);
          }
          if (!(s > 0 && s < ll)) continue;
        }
        for (int q = 0; q < 3; ++q) m.coords[3 * std::size_t{v} + q] = y[q];
        const double trial = local_min(v);
        if (trial > best) {
          best = trial;
          improved = true;
          ++kept;
        } else {
          for (int q = 0; q < 3; ++q) m.coords[3 * std::size_t{v} + q] = x[q];
        }
      }
      if (!improved) h *= 0.5;
    }
  }
  return kept;
}

}  // namespace quadval::recombine_detail
