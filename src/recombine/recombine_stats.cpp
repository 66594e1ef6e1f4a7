#include "recombine_stats.hpp"

#include <algorithm>
#include <cmath>

#include "quadval/quad_quality.hpp"

namespace quadval::recombine_detail {

double adimensional_length(const std::array<double, 3>& a, const std::array<double, 3>& b,
                           const SizeFunction& h) {
  // Gauss-Legendre nodes and weights on [0, 1].
  static constexpr double t[5] = {0.04691007703066800, 0.23076534494715845, 0.5,
                                  0.76923465505284155, 0.95308992296933200};
  static constexpr double w[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444,
                                  0.23931433524968324, 0.11846344252809454};
  const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double integral = 0;
  for (int i = 0; i < 5; ++i)
    integral += w[i] / h(a[0] + t[i] * d[0], a[1] + t[i] * d[1], a[2] + t[i] * d[2]);
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * integral;
}

double efficiency_index(const std::vector<double>& lengths) {
  if (lengths.empty()) return 0.0;
  double sum = 0;
  for (double l : lengths) sum += l < 1 ? l - 1 : 1 / l - 1;
  return 100.0 * std::exp(sum / static_cast<double>(lengths.size()));
}

void compute_statistics(const MixedMesh& m, const SizeFunction& size_field, RecombineStats& stats) {
  stats.quads = stats.triangles = stats.invalid_quads = 0;
  // eta and validity of the quads on the threads; summed below in element order, so that
  // eta_mean does not depend on the thread count.
  const auto ne = static_cast<std::ptrdiff_t>(m.elements.size());
  std::vector<double> quad_eta_of(m.elements.size(), 0.0);
  std::vector<char> quad_invalid(m.elements.size(), 0);
#pragma omp parallel for schedule(static) if (ne > 16384)
  for (std::ptrdiff_t i = 0; i < ne; ++i) {
    const auto e = static_cast<std::size_t>(i);
    const auto& el = m.elements[e];
    if (!m.alive[e] || MixedMesh::size(el) != 4) continue;
    const QuadCorners x{m.point(el[0]), m.point(el[1]), m.point(el[2]), m.point(el[3])};
    quad_eta_of[e] = quad_eta(x, m.normal[e]).eta;
    quad_invalid[e] = quad_min_corner_sine(x, m.normal[e]) <= 0;
  }
  double eta_sum = 0, eta_min = 1;
  std::vector<std::uint32_t> degree(m.num_nodes(), 0);
  std::vector<std::array<NodeIndex, 2>> edges;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    const int k = MixedMesh::size(el);
    for (int i = 0; i < k; ++i) {
      ++degree[el[i]];
      if (size_field) edges.push_back({std::min(el[i], el[(i + 1) % k]), std::max(el[i], el[(i + 1) % k])});
    }
    if (k == 3) {
      ++stats.triangles;
      continue;
    }
    ++stats.quads;
    eta_sum += quad_eta_of[e];
    eta_min = std::min(eta_min, quad_eta_of[e]);
    stats.invalid_quads += quad_invalid[e];
  }
  stats.eta_min = stats.quads > 0 ? eta_min : 0.0;
  stats.eta_mean = stats.quads > 0 ? eta_sum / static_cast<double>(stats.quads) : 0.0;

  const std::vector<char> boundary = region_boundary_nodes(m);
  std::size_t interior = 0, four = 0, used = 0;
  stats.degree_min = 0;
  stats.degree_max = 0;
  for (std::size_t v = 0; v < m.num_nodes(); ++v) {
    if (degree[v] == 0) continue;
    ++used;
    if (boundary[v]) continue;
    const int d = static_cast<int>(degree[v]);
    stats.degree_min = interior == 0 ? d : std::min(stats.degree_min, d);
    stats.degree_max = std::max(stats.degree_max, d);
    ++interior;
    four += (d == 4);
  }
  stats.nodes = used;
  stats.degree4_share = interior > 0 ? static_cast<double>(four) / static_cast<double>(interior) : 0.0;

  stats.has_tau = static_cast<bool>(size_field);
  if (stats.has_tau) {
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<double> lengths(edges.size());
    const auto ne = static_cast<std::ptrdiff_t>(edges.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < ne; ++i)
      lengths[static_cast<std::size_t>(i)] =
          adimensional_length(m.point(edges[static_cast<std::size_t>(i)][0]),
                              m.point(edges[static_cast<std::size_t>(i)][1]), size_field);
    stats.tau = efficiency_index(lengths);
  }
}

}  // namespace quadval::recombine_detail
