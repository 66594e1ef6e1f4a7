#pragma once
// Directed one-ulp steps for outward rounding of bounds: same results as
// std::nextafter(x, +-inf), without the library call on the hot path.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace quadval {

/// The smallest double > x (x itself for +inf and NaN).
inline double next_up(double x) noexcept {
  if (std::isnan(x) || x == std::numeric_limits<double>::infinity()) return x;
  if (x == 0) return std::numeric_limits<double>::denorm_min();
  const auto b = std::bit_cast<std::uint64_t>(x);
  return std::bit_cast<double>(x > 0 ? b + 1 : b - 1);
}

/// The largest double < x (x itself for -inf and NaN).
inline double next_down(double x) noexcept { return -next_up(-x); }

}  // namespace quadval
