#pragma once
// std::sqrt as the one correctly rounded instruction, always inline. In the tool's
// one-partition link-time build GCC 12 turns many std::sqrt into calls to libm's sqrt, an
// SSE-encoded sqrtsd, and after AVX-512 code such a call costs far more than the
// instruction (the SSE/AVX transition): the scaled Jacobian of warped_pyramid_o1's
// first-order pyramids took 10.7 ms with those calls and 1.5 ms without. The value is the
// same: an IEEE 754 square root is correctly rounded (and NaN below 0, as with
// -fno-math-errno). Internal to src/analysis.
#include <algorithm>
#include <cmath>

#include "analysis/outward_rounding.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace quadval {

inline double sqrt_rn(double x) noexcept {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_sqrt_sd(_mm_set_sd(x), _mm_set_sd(x)));
#else
  return std::sqrt(x);
#endif
}

/// Bounds of mu = sqrt(R) in [0, 1] from bounds of R: rounded down and up.
inline double sqrt_down(double r) noexcept { return r <= 0 ? 0.0 : std::min(1.0, next_down(sqrt_rn(r))); }
inline double sqrt_up(double r) noexcept { return r <= 0 ? 0.0 : std::min(1.0, next_up(sqrt_rn(r))); }

}  // namespace quadval
