#pragma once
// Certified eigenvalue steps on symmetric 3 x 3 matrices, several matrices at once in SIMD
// lanes (lane_vector.hpp: each lane computes exactly what the scalar functions of
// mu_control_bound.cpp and mu_metric.cpp compute for one matrix). Shared by the closed form
// of straight-sided tetrahedra (straight_simplex_mu.hpp, lanes over elements) and the control
// matrices of first-order hexahedra (trilinear_hex_mu.hpp, lanes over control points).
// Internal to src/analysis.
//
// Matrices are given by their entries m00, m11, m22, m01, m02, m12, one Lanes<W> each.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "quadval/bezier_basis.hpp"

namespace quadval::lanes3 {

inline constexpr double kSlack = 1 + 1e-12;
inline constexpr double kMax = std::numeric_limits<double>::max();

template <int W>
struct MaskVector {
  typedef std::int64_t Type __attribute__((vector_size(8 * W)));
};
template <int W>
using Mask = typename MaskVector<W>::Type;  // a lane's comparison: all ones or zero

/// Bit l set where lane l of `m` is true.
template <int W>
unsigned mask_bits(Mask<W> m) {
  unsigned bits = 0;
  for (int l = 0; l < W; ++l) bits |= m[l] != 0 ? 1u << l : 0u;
  return bits;
}

// next_up / next_down (outward_rounding.hpp) lane by lane, on the bits.
template <int W>
Lanes<W> up(Lanes<W> x) {
  constexpr std::int64_t kMagnitude = 0x7fffffffffffffff, kInfBits = 0x7ff0000000000000;
  const Mask<W> b = std::bit_cast<Mask<W>>(x);
  const Mask<W> mag = b & kMagnitude;
  // b - 1 or b + 1 in unsigned lanes: -0's b - 1 (and a NaN's b + 1) would overflow as
  // signed, in lanes the selects below discard.
  typedef std::uint64_t Bits __attribute__((vector_size(8 * W)));
  const Mask<W> step = b < 0 ? Mask<W>{} - 1 : Mask<W>{} + 1;
  Mask<W> r = std::bit_cast<Mask<W>>(std::bit_cast<Bits>(b) + std::bit_cast<Bits>(step));
  r = mag == 0 ? Mask<W>{} + 1 : r;
  r = (mag > kInfBits) | (b == kInfBits) ? b : r;
  return std::bit_cast<Lanes<W>>(r);
}
template <int W>
Lanes<W> down(Lanes<W> x) {
  return -up<W>(-x);
}
template <int W>
Lanes<W> root(Lanes<W> x) {  // vsqrtpd: correctly rounded, as std::sqrt
  for (int l = 0; l < W; ++l) x[l] = std::sqrt(x[l]);
  return x;
}
template <int W>
Mask<W> finite(Lanes<W> x) {
  return vabs(x) <= kMax;
}

/// positive_definite3 (mu_control_bound.cpp) lane by lane: Sylvester's criterion on the
/// exact matrix [s0 s3 s4; s3 s1 s5; s4 s5 s2], each minor with an a priori error bound.
template <int W>
Mask<W> positive_definite(const Lanes<W>* a) {
  const double g = rounding_gamma(8);
  const Lanes<W> p01 = a[0] * a[1], s01 = a[3] * a[3];
  const Lanes<W> c0 = a[1] * a[2] - a[5] * a[5];
  const Lanes<W> c1 = a[3] * a[2] - a[5] * a[4];
  const Lanes<W> c2 = a[3] * a[5] - a[1] * a[4];
  const Lanes<W> det = a[0] * c0 - a[3] * c1 + a[4] * c2;
  const Lanes<W> mag = vabs(a[0]) * (vabs(a[1] * a[2]) + a[5] * a[5]) +
                       vabs(a[3]) * (vabs(a[3] * a[2]) + vabs(a[5] * a[4])) +
                       vabs(a[4]) * (vabs(a[3] * a[5]) + vabs(a[1] * a[4]));
  return (a[0] > 0) & (p01 - s01 > g * (vabs(p01) + s01) * (1 + g)) & (det > g * mag * (1 + g));
}

/// ratio_at_least3 (mu_control_bound.cpp) lane by lane, with the same operations in the
/// same order (bit-identical decisions): lambda_min >= r lambda_max certified for every
/// exact symmetric matrix within err entrywise of m, from the Laguerre-Samuelson bound of
/// lambda_max and Sylvester's criterion on m - r lambda_max I. @pre 0 <= r < 1
template <int W>
Mask<W> ratio_at_least(const Lanes<W>* m, double err, double r) {
  using L = Lanes<W>;
  constexpr double u = 0x1p-53;
  const L c = (m[0] + m[1] + m[2]) / 3;
  const L shift = 4 * u * (vabs(m[0]) + vabs(m[1]) + vabs(m[2]));
  const L d0 = m[0] - c, d1 = m[1] - c, d2 = m[2] - c;
  const L sq = d0 * d0 + d1 * d1 + d2 * d2 + 2 * (m[3] * m[3] + m[4] * m[4] + m[5] * m[5]);
  const Mask<W> ok = vabs(sq) <= kMax;
  const L spread = up<W>(root<W>(up<W>(sq * (2.0 / 3.0) * (1 + 16 * u))));
  const double e3 = next_up(3 * err * (1 + 1e-15));
  const L t = up<W>(up<W>(up<W>(c + shift) + spread) + e3);
  const L sa = up<W>(up<W>(r * t) + e3);
  const L a[6] = {down<W>(m[0] - sa), down<W>(m[1] - sa), down<W>(m[2] - sa), m[3], m[4], m[5]};
  return ok & positive_definite<W>(a);
}

/// cos(acos(c) / 3) for c in [-1, 1]: mu_control_bound.cpp's trisected_cosine, lane by lane.
template <int W>
Lanes<W> trisected_cosine(Lanes<W> c) {
  const Lanes<W> s = root<W>(0.5 * (1 + c));
  Lanes<W> x = Lanes<W>{} + 0x1.2d945fe635cc5p-10;
  for (const double k : {-0x1.945b176bae327p-8, 0x1.08c20eb3ca04dp-6, -0x1.f0a66ec75bf0ap-6, 0x1.b11a9b6a6b367p-5,
                         -0x1.c6d5485f6740bp-4, 0x1.279a0e23f9291p-1, 0x1.000000c367160p-1})
    x = x * s + k;
  Mask<W> going = Mask<W>{} - 1;
  for (int step = 0; step < 2; ++step) {
    const Lanes<W> slope = 12 * x * x - 3;
    going = going & (slope > 0);
    x = going ? x - ((4 * x * x - 3) * x - c) / slope : x;
  }
  return vmin(vmax(x, Lanes<W>{} + 0.5), Lanes<W>{} + 1.0);
}

/// Certified lo <= lambda_min and lambda_max <= hi of every exact symmetric matrix within
/// err entrywise of m, where ok (extreme_eigen_bounds3 of mu_control_bound.cpp, lane by
/// lane): the trigonometric closed form of the eigenvalues, one Newton step each, widened
/// by a margin and 3 err, then certified by Sylvester's criterion on m - lo' I and
/// hi' I - m. Not ok where a step is not finite or a certification fails.
template <int W>
struct ExtremeEigen {
  Lanes<W> lo, hi;
  Mask<W> ok;
};
template <int W>
ExtremeEigen<W> extreme_eigen(const Lanes<W>* m, Lanes<W> err) {
  using L = Lanes<W>;
  // Eigenvalues q + y: y^3 - 3 p^2 y - e3 = 0 with D = M - q I, p^2 = tr D^2 / 6, e3 = det D.
  const L q = (m[0] + m[1] + m[2]) / 3;
  const L d0 = m[0] - q, d1 = m[1] - q, d2 = m[2] - q;
  const L off = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
  const L p2 = (d0 * d0 + d1 * d1 + d2 * d2 + 2 * off) / 6;
  const L scale = vabs(q) + 2 * root<W>(vmax(p2, L{}));
  Mask<W> ok = finite<W>(scale) & (scale > 0);
  const Mask<W> spread = p2 > 1e-30 * q * q;
  const L p = root<W>(spread ? p2 : L{} + 1);
  const L e3 = d0 * (d1 * d2 - m[5] * m[5]) - m[3] * (m[3] * d2 - m[5] * m[4]) + m[4] * (m[3] * m[5] - d1 * m[4]);
  const L c = vmin(vmax(e3 / (2 * p2 * p), L{} - 1), L{} + 1);
  const L ct = trisected_cosine<W>(spread ? c : L{});
  const L st = root<W>((1 - ct) * (1 + ct));
  L y[2] = {2 * p * (-0.5 * ct - 0.8660254037844386 * st), 2 * p * ct};  // least, largest
  for (L& yk : y) {  // one Newton step each (accuracy only)
    const L f = (yk * yk - 3 * p2) * yk - e3, fp = 3 * (yk * yk - p2);
    const Mask<W> steep = vabs(fp) > 1e-3 * p2;
    const L step = f / (steep ? fp : L{} + 1);
    yk = steep & (vabs(step) < 1e-3 * p) ? yk - step : yk;
    yk = spread ? yk : L{};
  }
  const L margin = 1e-12 * scale + 3 * err;
  ExtremeEigen<W> out;
  out.lo = down<W>(q + y[0] - margin);
  out.hi = up<W>(q + y[1] + margin);
  const L e3x = up<W>(3 * err * (1 + 1e-15));
  const L sa = up<W>(out.lo + e3x), sb = down<W>(out.hi - e3x);
  const L s[6] = {down<W>(m[0] - sa), down<W>(m[1] - sa), down<W>(m[2] - sa), m[3], m[4], m[5]};
  const L t[6] = {down<W>(sb - m[0]), down<W>(sb - m[1]), down<W>(sb - m[2]), -m[3], -m[4], -m[5]};
  out.ok = ok & positive_definite<W>(s) & positive_definite<W>(t);
  return out;
}

/// An approximate unit eigenvector of m for lambda (accuracy only): the largest cross
/// product of two rows of m - lambda I; ok false where those are nearly parallel.
template <int W>
Mask<W> eigenvector(const Lanes<W>* m, Lanes<W> lambda, Lanes<W>* v) {
  const Lanes<W> r[3][3] = {{m[0] - lambda, m[3], m[4]}, {m[3], m[1] - lambda, m[5]}, {m[4], m[5], m[2] - lambda}};
  const auto cross = [](const Lanes<W>* p, const Lanes<W>* q, Lanes<W>* out) {
    out[0] = p[1] * q[2] - p[2] * q[1];
    out[1] = p[2] * q[0] - p[0] * q[2];
    out[2] = p[0] * q[1] - p[1] * q[0];
  };
  const auto square = [](const Lanes<W>* p) { return p[0] * p[0] + p[1] * p[1] + p[2] * p[2]; };
  Lanes<W> best[3], other[3];
  cross(r[0], r[1], best);
  Lanes<W> n2 = square(best);
  for (const auto& [i, j] : {std::pair{0, 2}, std::pair{1, 2}}) {
    cross(r[i], r[j], other);
    const Lanes<W> o2 = square(other);
    const Mask<W> larger = o2 > n2;
    for (int k = 0; k < 3; ++k) best[k] = larger ? other[k] : best[k];
    n2 = larger ? o2 : n2;
  }
  const Lanes<W> rows = square(r[0]) + square(r[1]) + square(r[2]);
  const Mask<W> ok = (n2 > 1e-16 * rows * rows) & finite<W>(n2);
  const Lanes<W> norm = root<W>(ok ? n2 : Lanes<W>{} + 1);
  for (int k = 0; k < 3; ++k) v[k] = best[k] / norm;
  return ok;
}

/// corner_upper's Rayleigh quotient |W v|^2 / |v|^2 (mu_metric.cpp), enclosed from above
/// (upper) or below, with W (w[j][c]: coordinate c of column j) within err entrywise:
/// y_c within err sum|v| + gamma_4 sum |w v|.
template <int W>
Lanes<W> rayleigh(const Lanes<W> (*w)[3], const Lanes<W>* v, Lanes<W> err, bool upper) {
  const Lanes<W> v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  const Lanes<W> vsum = vabs(v[0]) + vabs(v[1]) + vabs(v[2]);
  Lanes<W> y2{};
  for (int c = 0; c < 3; ++c) {
    Lanes<W> y{}, mag{};
    for (int j = 0; j < 3; ++j) {
      y += w[j][c] * v[j];
      mag += vabs(w[j][c] * v[j]);
    }
    const Lanes<W> rad = (err * vsum + rounding_gamma(4) * mag) * kSlack;
    const Lanes<W> e = upper ? vabs(y) + rad : vmax(Lanes<W>{}, vabs(y) - rad);
    y2 += e * e;
  }
  const double g = rounding_gamma(6) * kSlack;
  return upper ? y2 * (1 + g) / (v2 * (1 - g)) * (1 + g) : y2 * (1 - g) / (v2 * (1 + g)) * (1 - g);
}

/// Certified upper bound of lambda_min / lambda_max of W^T W (W within err entrywise),
/// from the Rayleigh quotients at the approximate eigenvectors of m = W^T W for the
/// eigenvalue estimates lo and hi; 1 where no bound is found (a failed eigenvector, a
/// zero quotient).
template <int W>
Lanes<W> ratio_upper(const Lanes<W> (*w)[3], const Lanes<W>* m, Lanes<W> lo, Lanes<W> hi, Lanes<W> err,
                     Mask<W>& vectors_ok) {
  using L = Lanes<W>;
  L v_min[3], v_max[3];
  vectors_ok = eigenvector<W>(m, lo, v_min) & eigenvector<W>(m, hi, v_max);
  const L lmin_hi = rayleigh<W>(w, v_min, err, true);
  const L lmax_lo = rayleigh<W>(w, v_max, err, false);
  const Mask<W> has_upper = (lmax_lo > 0) & finite<W>(lmin_hi);
  return has_upper ? up<W>(lmin_hi / (has_upper ? lmax_lo : L{} + 1)) : L{} + 1;
}

}  // namespace quadval::lanes3
