// R's bounds of a first-order prism from its control matrices, in lanes (see the header).
#include "analysis/linear_prism_mu.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;

// The prism's vertices q = i + 3 l (triangle vertex i, end l of zeta) and M's control
// points: the triangle's degree-2 multi-index of a pair (i, i') (0, 1, 2 for 2 e_i; 3, 4, 5
// for e_0 + e_1, e_0 + e_2, e_1 + e_2) plus 6 (l + l').
const VertexProducts& prism() {
  static const VertexProducts domain = vertex_products(6, 18, [](int q, int r) {
    constexpr int kTriangle[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    return kTriangle[q % 3][r % 3] + 6 * (q / 3 + r / 3);
  });
  return domain;
}

}  // namespace

CertifiedRatio linear_prism_ratio(std::span<const double> x, const std::array<double, 9>& jinv) {
  QV_ASSERT(x.size() == 18, x.size() << " coordinates for a first-order prism");
  const auto node = [&](int n, int k) { return x[static_cast<std::size_t>(3 * n + k)]; };
  double col[3][8][3] = {};
  double a = 0;  // the largest |entry|
  for (int q = 0; q < 6; ++q) {
    const int i = q % 3, top = 3 * (q / 3);
    for (int k = 0; k < 3; ++k) {
      col[0][q][k] = 2 * (node(top + 1, k) - node(top, k));
      col[1][q][k] = 2 * (node(top + 2, k) - node(top, k));
      col[2][q][k] = node(i + 3, k) - node(i, k);
      for (int c = 0; c < 3; ++c) a = std::max(a, std::abs(col[c][q][k]));
    }
  }
  const double rounding[3] = {kUnit * a, kUnit * a, kUnit * a};
  return columns_ratio(prism(), col, rounding, jinv);
}

}  // namespace quadval
