#pragma once
// The least or largest of the quotients q_i = fl(fl(num_i + a) / fl(den_i + b)) over a
// vector, bit for bit as the plain loop computes it (with AVX2, a zero's sign aside): with
// AVX-512, most divisions replaced by approximate reciprocals; else the divisions a vector
// at a time. Internal to src/analysis (the scaled Jacobian's bounds, where these divisions
// were most of a subdomain's bound: vdivpd is 8 to 16 times slower than a multiplication).
//
// Why the AVX-512 path gives the same value. Pass 1 approximates each quotient by p_i = n_i * rcp14(d_i),
// within delta = 2^-14 + 2u relative of n_i / d_i while the p_i are normal numbers. With
// P the extreme p_i, the element E attaining the extreme q_i has
// |p_E| >= |P| (1 - 2^-12) on the extreme's side (q_E beats every q_k after rounding, so
// its exact quotient is within (1 + u) / (1 - u) of theirs), so it lies within the
// threshold P -+ |P| 2^-10; pass 2 divides exactly only the elements within it. When P is
// not a normal number of magnitude at least 2^-1000, or not finite, every element is
// divided (the plain loop).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "analysis/outward_rounding.hpp"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace quadval {

struct RatioScan {
  double extreme;    // min (kLeast) or max of the quotients; +inf (kLeast) or -inf if none
  double least_den;  // min_i fl(den_i + c); +inf if none
};

/// min_i (kLeast) or max_i of fl(fl(num_i + a) / fl(den_i + b)), and min_i fl(den_i + c),
/// over i < size, ignoring NaN quotients as `x < m ? x : m` does.
template <bool kLeast>
RatioScan scan_ratios(const double* num, double a, const double* den, double b, double c, std::size_t size) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const auto better = [](double x, double m) { return kLeast ? x < m : m < x; };
  const auto exact = [&](std::size_t i) { return (num[i] + a) / (den[i] + b); };
  RatioScan out{kLeast ? kInf : -kInf, kInf};
#if defined(__AVX512F__)
  const __m512d va = _mm512_set1_pd(a), vb = _mm512_set1_pd(b), vc = _mm512_set1_pd(c);
  const auto approx = [&](std::size_t i, __mmask8 m) {
    const __m512d n = _mm512_add_pd(_mm512_maskz_loadu_pd(m, num + i), va);
    const __m512d d = _mm512_add_pd(_mm512_maskz_loadu_pd(m, den + i), vb);
    return _mm512_mul_pd(n, _mm512_rcp14_pd(d));
  };
  const auto lanes = [&](std::size_t i) {
    return size - i >= 8 ? __mmask8(0xff) : static_cast<__mmask8>((1u << (size - i)) - 1);
  };
  __m512d ext = _mm512_set1_pd(out.extreme), least = _mm512_set1_pd(kInf);
  for (std::size_t i = 0; i < size; i += 8) {
    const __mmask8 m = lanes(i);
    const __m512d p = approx(i, m);
    // Masked min/max: lanes outside m keep their value (and NaN p is ignored: vminpd
    // returns its second operand when either is NaN).
    ext = kLeast ? _mm512_mask_min_pd(ext, m, p, ext) : _mm512_mask_max_pd(ext, m, p, ext);
    const __m512d dc = _mm512_add_pd(_mm512_maskz_loadu_pd(m, den + i), vc);
    least = _mm512_mask_min_pd(least, m, dc, least);
  }
  out.least_den = _mm512_reduce_min_pd(least);
  const double p = kLeast ? _mm512_reduce_min_pd(ext) : _mm512_reduce_max_pd(ext);
  if (std::abs(p) >= 0x1p-1000 && std::abs(p) < kInf) {
    const double threshold = kLeast ? p + std::abs(p) * 0x1p-10 : p - std::abs(p) * 0x1p-10;
    const __m512d t = _mm512_set1_pd(threshold);
    for (std::size_t i = 0; i < size; i += 8) {
      const __mmask8 m = lanes(i);
      auto near = _mm512_mask_cmp_pd_mask(m, approx(i, m), t, kLeast ? _CMP_LE_OQ : _CMP_GE_OQ);
      for (; near != 0; near = static_cast<__mmask8>(near & (near - 1))) {
        const double q = exact(i + static_cast<std::size_t>(__builtin_ctz(near)));
        if (better(q, out.extreme)) out.extreme = q;
      }
    }
    return out;
  }
  out.extreme = kLeast ? kInf : -kInf;
  for (std::size_t i = 0; i < size; ++i) {
    const double q = exact(i);
    if (better(q, out.extreme)) out.extreme = q;
  }
#elif defined(__AVX2__)
  // Without AVX-512's rcp14: the exact quotients divided a vector at a time (the same
  // correctly rounded quotients), and both extremes kept per lane, merged at the end. The
  // lanes ignore NaN quotients as the plain loop does (vminpd / vmaxpd return the second
  // operand, the running extreme, when either is NaN); an extreme of equal values may come
  // from another element than the loop's, which can only change the sign of a zero, and
  // every use tests its sign first. Against the plain loop over a block's quotients, whose
  // two running extremes were chains of dependent scalar operations (scaled Jacobian, one
  // thread, medians of 4 x 3 interleaved, BM_CheckSharedQuality): warped_tetrahedron_o3
  // 79 -> 72 ms, warped_hexahedron_o2 4.7 -> 4.4 ms, warped_prism_o2 9.0 -> 8.5 ms.
  const __m256d va = _mm256_set1_pd(a), vb = _mm256_set1_pd(b), vc = _mm256_set1_pd(c);
  __m256d ext = _mm256_set1_pd(out.extreme), least = _mm256_set1_pd(kInf);
  std::size_t i = 0;
  for (; i + 4 <= size; i += 4) {
    const __m256d d = _mm256_loadu_pd(den + i);
    const __m256d q = _mm256_div_pd(_mm256_add_pd(_mm256_loadu_pd(num + i), va), _mm256_add_pd(d, vb));
    ext = kLeast ? _mm256_min_pd(q, ext) : _mm256_max_pd(q, ext);
    least = _mm256_min_pd(_mm256_add_pd(d, vc), least);
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, ext);
  for (const double x : lanes)
    if (better(x, out.extreme)) out.extreme = x;
  _mm256_store_pd(lanes, least);
  for (const double x : lanes) out.least_den = std::min(out.least_den, x);
  for (; i < size; ++i) {
    const double q = exact(i);
    if (better(q, out.extreme)) out.extreme = q;
    out.least_den = std::min(out.least_den, den[i] + c);
  }
#else
  // Without AVX-512's rcp14: the exact quotients of a block, divided a vector at a time
  // (the same correctly rounded quotients), then the plain loop over them. Scaled Jacobian,
  // AVX2, one thread, medians of 5 (BM_CheckSharedQuality): warped_tetrahedron_o3 107 ->
  // 90 ms, warped_prism_o2 10.2 -> 9.1 ms, against one division after another.
  constexpr std::size_t kBlock = 64;
  double q[kBlock];
  for (std::size_t i0 = 0; i0 < size; i0 += kBlock) {
    const std::size_t n = std::min(kBlock, size - i0);
#pragma omp simd
    for (std::size_t k = 0; k < n; ++k) q[k] = exact(i0 + k);
    for (std::size_t k = 0; k < n; ++k) {
      out.least_den = std::min(out.least_den, den[i0 + k] + c);
      if (better(q[k], out.extreme)) out.extreme = q[k];
    }
  }
#endif
  return out;
}

/// Below the exact quotient (num_i + a) / (den_i + b) whose computed value is q (an
/// extreme of scan_ratios, den_i + b > 0 exactly): a difference of doubles keeps its sign,
/// and the sum, the difference and the quotient round once each (relative u; an
/// underflowing quotient loses at most denorm_min), so q moved by 4u toward -inf, less
/// denorm_min, is below it. @pre q != 0 and finite
inline double quotient_below(double q) {
  constexpr double u = 0x1p-53;
  return next_down(next_down(q * (q < 0 ? 1 + 4 * u : 1 - 4 * u)) - std::numeric_limits<double>::denorm_min());
}

}  // namespace quadval
