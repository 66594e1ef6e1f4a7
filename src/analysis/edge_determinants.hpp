#pragma once
// What the fixed-size scaled-Jacobian bounds of first-order hexahedra and pyramids
// (trilinear_hex_sj.hpp, linear_pyramid_sj.hpp) share: vectors of three doubles, their
// 1-norms, determinants with the magnitude sum their rounding bound needs, the weights of
// a product of two degree-1 Bernstein polynomials, and the hand-out of their lanes'
// results. Internal to src/analysis.
#include <array>
#include <cmath>

#include "analysis/lane_vector.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval::edge_determinants {

using Vec = std::array<double, 3>;

inline double norm1(const Vec& v) { return std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2]); }

/// det[a, b, c] as a . (b x c); t receives T, the sum of its six triple products'
/// magnitudes (the computed determinant is within 16u T of the exact one of these inputs).
inline double det(const Vec& a, const Vec& b, const Vec& c, double& t) {
  t = std::abs(a[0]) * (std::abs(b[1] * c[2]) + std::abs(b[2] * c[1])) +
      std::abs(a[1]) * (std::abs(b[2] * c[0]) + std::abs(b[0] * c[2])) +
      std::abs(a[2]) * (std::abs(b[0] * c[1]) + std::abs(b[1] * c[0]));
  return a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/// w1(i, j) = C(1,i) C(1,j) / C(2,i+j): B_i B_j = w1(i, j) B^2_{i+j} for degree-1 Bernstein
/// polynomials (exact in doubles).
inline constexpr double kW1[2][2] = {{1, 0.5}, {0.5, 1}};

/// out[l] = [lower, upper] of lane l, no subdivision, the tolerance met, for each lane where
/// `ok`; returns those lanes' bits.
template <int W>
unsigned settled_lanes(lanes3::Mask<W> ok, Lanes<W> lower, Lanes<W> upper, QualityBounds* out) {
  const unsigned done = lanes3::mask_bits<W>(ok);
  for (int l = 0; l < W; ++l)
    if (((done >> l) & 1u) != 0) {
      out[l] = QualityBounds{};
      out[l].lower = lower[l];
      out[l].upper = upper[l];
      out[l].tolerance_met = true;
    }
  return done;
}

}  // namespace quadval::edge_determinants
