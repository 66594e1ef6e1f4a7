#pragma once
// eta of Paper I eq. 3 from a quad's worst corner: eta = 1 - asin(c) / (pi / 2), c = the
// largest |cos| of its corner angles (|pi/2 - alpha| = asin |cos alpha|). One function for
// one quad (quad_eta, and so every cost and statistic) and for four at once (the smoothing's
// lanes), with the same operations in the same order (no FMA contraction: -ffp-contract=off),
// so both give the same value to the bit: smoothing never lowers quad_eta's worst.
//
// Why not std::asin: it has no four-lane form that rounds as it does, and calling it per
// lane took a quarter of the smoothing's time (square-hole-1M, perf). Here asin is a
// polynomial on [0, 1/2] (for c > 1/2, asin c = pi/2 - 2 asin sqrt((1 - c) / 2), so that
// eta = asin(sqrt((1 - c) / 2)) / (pi / 4), which also keeps eta's relative accuracy as
// c -> 1). asin s = s + s^3 Q(s^2), Q the Taylor series of degree 70 economised to degree
// 11 in Chebyshev polynomials on z = s^2 in [0, 1/4] (exact rational arithmetic; the
// dropped terms sum to 1.4e-15 Q(0), which the factor s^2 Q <= 0.05 makes 7e-17 of asin).
// Within 2.5e-16 of 1 - asinl(c) / (pi / 2) on a dense sweep, and never increasing
// (tests/recombine/quad_quality_test.cpp).

#include <cmath>

namespace quadval::recombine_detail {

namespace eta_detail {

// Q(z), lowest degree first (hexadecimal: exactly the doubles nearest the rationals).
inline constexpr double kQ[12] = {
    0x1.555555555554ep-3,  0x1.3333333337110p-4, 0x1.6db6db68067fep-5, 0x1.f1c71fb700f11p-6,
    0x1.6e8b26f89d407p-6,  0x1.1c598c739143cp-6, 0x1.c86b17413a7b6p-7, 0x1.8559b6cfd3c89p-7,
    0x1.fd4f1fa1ac91cp-8,  0x1.084522a849f25p-6, -0x1.65717d3785d18p-7, 0x1.cf6d7d2572a46p-6};
inline constexpr double kHalfPi = 0x1.921fb54442d18p+0;  // pi / 2, rounded to nearest
inline constexpr double kQuarterPi = 0x1.921fb54442d18p-1;

// asin s for s in [0, 1/2]; T is double or a vector of doubles (GCC vector extension).
// Q by Estrin's scheme: a third of Horner's latency, which one quad at a time waits on.
template <class T>
T asin_to_half(T s) noexcept {
  const T z = s * s, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
  T p[6];
  for (int k = 0; k < 6; ++k) p[k] = z * kQ[2 * k + 1] + kQ[2 * k];
  const T low = (p[0] + z2 * p[1]) + z4 * (p[2] + z2 * p[3]);
  const T q = low + z8 * (p[4] + z2 * p[5]);
  return s + (s * z) * q;
}

}  // namespace eta_detail

/// eta for c = min(worst |cos|, 1) in [0, 1]: 1 at c = 0, 0 at c = 1, never negative.
inline double eta_of_cosine(double c) noexcept {
  using namespace eta_detail;
  if (c > 0.5) return asin_to_half(std::sqrt((1.0 - c) * 0.5)) / kQuarterPi;
  return 1.0 - asin_to_half(c) / kHalfPi;
}

/// Four lanes of eta_of_cosine, each equal to it to the bit.
using EtaLanes = double __attribute__((vector_size(32)));
inline EtaLanes eta_of_cosine(EtaLanes c) noexcept {
  using namespace eta_detail;
  const EtaLanes half = (1.0 - c) * 0.5;
  EtaLanes root;
  for (int l = 0; l < 4; ++l) root[l] = std::sqrt(half[l] > 0.0 ? half[l] : 0.0);  // c <= 1/2 lanes unused
  const auto big = c > 0.5;
  const EtaLanes a = asin_to_half(big ? root : c);
  return big ? a / kQuarterPi : 1.0 - a / kHalfPi;
}

}  // namespace quadval::recombine_detail
