#pragma once
// Directed one-ulp steps for outward rounding of bounds: same results as
// std::nextafter(x, +-inf), without the library call on the hot path.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace quadval {

/// The smallest double > x (x itself for +inf and NaN). On the bits, with selects rather
/// than branches (bounds take several per value: the tests and branches were the larger
/// part of the scaled Jacobian of straight-sided tetrahedra): positive values and +0 step
/// up, negative ones down (-inf to -max), +-0 give the least subnormal.
inline double next_up(double x) noexcept {
  constexpr std::uint64_t kMagnitude = 0x7fffffffffffffff, kInfBits = 0x7ff0000000000000;
  const auto b = std::bit_cast<std::uint64_t>(x);
  const std::uint64_t mag = b & kMagnitude;
  std::uint64_t r = (b >> 63) != 0 ? b - 1 : b + 1;
  r = mag == 0 ? 1 : r;
  r = mag > kInfBits || b == kInfBits ? b : r;  // NaN, +inf
  return std::bit_cast<double>(r);
}

/// The largest double < x (x itself for -inf and NaN).
inline double next_down(double x) noexcept { return -next_up(-x); }

}  // namespace quadval
