// R's bounds of a first-order pyramid from its control matrices, in lanes (see the header
// for the method and its rounding).
#include "analysis/linear_pyramid_mu.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "analysis/vertex_metric_ratio.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;

// The square's vertices q = i + 2 j and M's control points a + 3 b.
const VertexProducts& square() {
  static const VertexProducts domain =
      vertex_products(4, 9, [](int q, int r) { return (q & 1) + (r & 1) + 3 * ((q >> 1) + (r >> 1)); });
  return domain;
}

// Twice J's columns at the square's vertices, col[c][q][k], from the nodes x[3 n + k];
// returns the largest difference coordinate d. T: double, or Lanes<W> for one pyramid per
// lane (the same operations: the same bits).
template <class T>
T pyramid_columns(const T* x, T (*col)[8][3]) {
  const auto node = [&](int n, int k) { return x[3 * n + k]; };
  T d{};
  for (int q = 0; q < 4; ++q) {
    const int i = q & 1, j = q >> 1;
    // u v = 1 at (0,0) and (1,1): then the other two base nodes are 1 and 3.
    const int n0 = i == j ? 1 : 0, n1 = i == j ? 3 : 2;
    for (int k = 0; k < 3; ++k) {
      const T a0 = node(4, k) - node(n0, k), a1 = node(4, k) - node(n1, k);
      col[0][q][k] = j == 0 ? node(1, k) - node(0, k) : node(2, k) - node(3, k);
      col[1][q][k] = i == 0 ? node(3, k) - node(0, k) : node(2, k) - node(1, k);
      col[2][q][k] = a0 + a1;
      d = vmax(vmax(vmax(vmax(d, vabs(col[0][q][k])), vabs(col[1][q][k])), vabs(a0)), vabs(a1));
    }
  }
  return d;
}

}  // namespace

CertifiedRatio linear_pyramid_ratio(std::span<const double> x, const std::array<double, 9>& jinv) {
  QV_ASSERT(x.size() == 15, x.size() << " coordinates for a first-order pyramid");
  double col[3][8][3] = {};
  const double d = pyramid_columns(x.data(), col);
  // A difference within u d of the exact one; the third column's sum of two within 4u d.
  const double rounding[3] = {kUnit * d, kUnit * d, 4 * kUnit * d};
  return columns_ratio(square(), col, rounding, jinv);
}

StraightSimplexRatio<kNativeLanes> linear_pyramid_constant_ratio(const Lanes<kNativeLanes>* x,
                                                                 const std::array<double, 9>& jinv) {
  constexpr int kW = kNativeLanes;
  Lanes<kW> col[3][8][3] = {};
  const Lanes<kW> d = pyramid_columns(x, col);
  const Lanes<kW> rounding[3] = {kUnit * d, kUnit * d, 4 * kUnit * d};
  return constant_columns_ratio<kW>(col, 4, rounding, jinv);
}

}  // namespace quadval
