// next_up / next_down (outward_rounding.hpp) against the C library's nextafter, which shares
// no code with them: special values, the neighbourhoods of zero, of the subnormal and of
// the infinite range, and random bit patterns.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "analysis/outward_rounding.hpp"
#include "analysis/symmetric3_lanes.hpp"

namespace quadval {
namespace {

using Limits = std::numeric_limits<double>;

// Same bits (NaN: both NaN).
void expect_same(double got, double want, double x) {
  if (std::isnan(want)) {
    EXPECT_TRUE(std::isnan(got)) << "x = " << x;
    return;
  }
  EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want)) << "x = " << x;
}

void expect_steps(double x) {
  expect_same(next_up(x), std::nextafter(x, Limits::infinity()), x);
  expect_same(next_down(x), std::nextafter(x, -Limits::infinity()), x);
}

TEST(OutwardRounding, SpecialValuesStepLikeNextafter) {
  const std::vector<double> xs{0.0,
                               -0.0,
                               Limits::denorm_min(),
                               -Limits::denorm_min(),
                               Limits::min(),
                               -Limits::min(),
                               std::nextafter(Limits::min(), 0.0),
                               -std::nextafter(Limits::min(), 0.0),
                               1.0,
                               -1.0,
                               0.5,
                               Limits::max(),
                               -Limits::max(),
                               Limits::infinity(),
                               -Limits::infinity(),
                               Limits::quiet_NaN(),
                               -Limits::quiet_NaN()};
  for (double x : xs) expect_steps(x);
  // Every power of two (a change of exponent), both signs.
  for (int e = -1074; e <= 1023; ++e) {
    expect_steps(std::ldexp(1.0, e));
    expect_steps(-std::ldexp(1.0, e));
  }
}

TEST(OutwardRounding, RandomBitPatternsStepLikeNextafter) {
  std::mt19937_64 rng(2026);
  for (int i = 0; i < 200000; ++i) expect_steps(std::bit_cast<double>(rng()));
}

// The lane versions (symmetric3_lanes.hpp), 8 lanes at a time, against nextafter: the
// special values (the signed zeros and the NaNs with every payload bit set, whose step
// would overflow as signed integers), then random bit patterns.
TEST(OutwardRounding, LaneStepsLikeNextafter) {
  std::vector<double> xs{0.0, -0.0, Limits::denorm_min(), -Limits::denorm_min(), Limits::max(), -Limits::max(),
                         Limits::infinity(), -Limits::infinity(), Limits::quiet_NaN(),
                         std::bit_cast<double>(std::uint64_t{0x7fffffffffffffff}),
                         std::bit_cast<double>(std::uint64_t{0xffffffffffffffff}), 1.0, -1.0};
  std::mt19937_64 rng(7);
  while (xs.size() < 8 * 4000) xs.push_back(std::bit_cast<double>(rng()));
  while (xs.size() % 8 != 0) xs.push_back(1.0);
  for (std::size_t i = 0; i < xs.size(); i += 8) {
    Lanes<8> x;
    for (int l = 0; l < 8; ++l) x[l] = xs[i + static_cast<std::size_t>(l)];
    const Lanes<8> u = lanes3::up<8>(x), d = lanes3::down<8>(x);
    for (int l = 0; l < 8; ++l) {
      expect_same(u[l], std::nextafter(x[l], Limits::infinity()), x[l]);
      expect_same(d[l], std::nextafter(x[l], -Limits::infinity()), x[l]);
    }
  }
}

}  // namespace
}  // namespace quadval
