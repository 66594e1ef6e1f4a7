// R's bounds of a first-order pyramid from its control matrices, in lanes (see the header
// for the method and its rounding).
#include "analysis/linear_pyramid_mu.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "analysis/straight_tet_mu.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

using namespace lanes3;
using L8 = Lanes<8>;

constexpr double kUnit = 0x1p-53;
constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr int kPoints = 9;
constexpr int kSlots = 16;  // 2 blocks of 8 lanes; the spare lanes repeat slot 0

// Base node at square vertex q = i + 2 j.
constexpr int kBase[4] = {0, 1, 3, 2};

// The control points (a, b) of degree 2, as a + 3 b, by slot: the 4 corners first (slot q:
// vertex q -> (2i, 2j)), then the others; the spare slots repeat slot 0.
constexpr std::array<int, kSlots> kPointOfSlot = {0, 2, 6, 8, 1, 3, 4, 5, 7, 0, 0, 0, 0, 0, 0, 0};

}  // namespace

LinearPyramidRatio linear_pyramid_ratio(std::span<const double> x, const std::array<double, 9>& jinv) {
  QV_ASSERT(x.size() == 15, x.size() << " coordinates for a first-order pyramid");
  const auto node = [&](int n, int k) { return x[static_cast<std::size_t>(3 * n + k)]; };
  // Twice J's columns at the square's vertices.
  double col[3][4][3];
  double d = 0;  // the largest difference coordinate
  for (int q = 0; q < 4; ++q) {
    const int i = q & 1, j = q >> 1;
    // u v = 1 at (0,0) and (1,1): then the other two base nodes are 1 and 3.
    const int n0 = i == j ? 1 : 0, n1 = i == j ? 3 : 2;
    for (int k = 0; k < 3; ++k) {
      const double e0 = j == 0 ? node(1, k) - node(0, k) : node(2, k) - node(3, k);
      const double e1 = i == 0 ? node(3, k) - node(0, k) : node(2, k) - node(1, k);
      const double a0 = node(4, k) - node(n0, k), a1 = node(4, k) - node(n1, k);
      col[0][q][k] = e0;
      col[1][q][k] = e1;
      col[2][q][k] = a0 + a1;
      d = std::max({d, std::abs(e0), std::abs(e1), std::abs(a0), std::abs(a1)});
    }
  }
  LinearPyramidRatio out;
  // A base that is a parallelogram (to 1e-9) makes W constant: the closed form of
  // straight-sided tetrahedra (straight_tet_ratio, two lanes) with each column's spread
  // over the vertices as its margin, plus its rounding (a difference within u d, the
  // third column's sum of two within 4u d).
  Lanes<2> edges[9], margins[3];
  double spread = 0;
  for (int c = 0; c < 3; ++c) {
    double beta = 0;
    for (int q = 1; q < 4; ++q)
      for (int k = 0; k < 3; ++k) beta = std::max(beta, std::abs(col[c][q][k] - col[c][0][k]));
    spread = std::max(spread, beta);
    margins[c] = broadcast_lanes<2>(next_up((beta + (c < 2 ? 1 : 4) * kUnit * d) * kSlack));
    for (int k = 0; k < 3; ++k) edges[3 * c + k] = broadcast_lanes<2>(col[c][0][k]);
  }
  if (spread <= 1e-9 * d) {
    const StraightTetRatio<2> r = straight_tet_ratio<2>(edges, margins, jinv);
    if ((r.ok & 1u) != 0) {
      out = {r.lower[0], r.upper[0], r.lower[0] <= r.upper[0]};
      return out;
    }
  }
  // W's control values: the third column over sqrt 2.
  double w[3][4][3];
  for (int c = 0; c < 3; ++c)
    for (int q = 0; q < 4; ++q)
      for (int k = 0; k < 3; ++k) w[c][q][k] = c < 2 ? col[c][q][k] : col[c][q][k] * kInvSqrt2;
  const double delta = next_up(8 * kUnit * d * kSlack);
  const double b = 2 * d;  // >= |W| entries: |a0 + a1| / sqrt 2 <= sqrt 2 d, rounding included
  const double err = next_up((3 * (2 * b + delta) * delta + rounding_gamma(10) * 3 * b * b) * kSlack);
  if (!(err < kMax) || !(d > 0)) return out;
  // The control values of M's entries m00, m11, m22, m01, m02, m12, by slot.
  constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  alignas(64) double m[6][kSlots];
  for (int e = 0; e < 6; ++e) {
    const auto& wx = w[kPairs[e][0]];
    const auto& wy = w[kPairs[e][1]];
    double sum[kPoints] = {};
    for (int q = 0; q < 4; ++q)
      for (int r = 0; r < 4; ++r)
        sum[(q & 1) + (r & 1) + 3 * ((q >> 1) + (r >> 1))] += wx[q][0] * wy[r][0] + wx[q][1] * wy[r][1] + wx[q][2] * wy[r][2];
    for (int t = 0; t < kSlots; ++t) {
      const int p = kPointOfSlot[static_cast<std::size_t>(t)];
      m[e][t] = sum[p] * ((p % 3 == 1 ? 0.5 : 1.0) * (p / 3 == 1 ? 0.5 : 1.0));
    }
  }
  // Lower: the least certified ratio of the 9 control matrices (mu_control_bound.hpp).
  L8 lower = broadcast_lanes<8>(1.0);
  L8 corner_m[6];
  ExtremeEigen<8> corners{};
  for (int block = 0; block < kSlots / 8; ++block) {
    L8 mb[6];
    for (int e = 0; e < 6; ++e) mb[e] = load_lanes<8>(&m[e][8 * block]);
    const ExtremeEigen<8> eig = extreme_eigen<8>(mb, broadcast_lanes<8>(err));
    if (mask_bits<8>(eig.ok & (eig.lo > 0)) != 0xffu) return out;
    lower = vmin(lower, down<8>(eig.lo / eig.hi));
    if (block == 0) {
      corners = eig;
      std::copy_n(mb, 6, corner_m);
    }
  }
  // Upper: Rayleigh quotients of W at the 4 corners (lanes 0-3 of block 0; lanes 4-7 are
  // not used).
  L8 wc[3][3];
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 8; ++l) wc[c][k][l] = w[c][l & 3][k];
  Mask<8> vectors_ok;
  const L8 upper = ratio_upper<8>(wc, corner_m, corners.lo, corners.hi, broadcast_lanes<8>(delta), vectors_ok);
  double best = 1;
  for (int l = 0; l < 4; ++l) best = std::min(best, upper[l]);
  out.lower = std::clamp(fold_min(lower, 1.0), 0.0, 1.0);
  out.upper = std::clamp(best, 0.0, 1.0);
  out.ok = out.lower <= out.upper;
  return out;
}

}  // namespace quadval
