// The vectorised folds of lane_vector.hpp (least_value, largest_magnitude, vmin,
// vmax) against std::min_element and a plain loop of std::max(|x|): every length from
// 0 to 100 (the plain loop below kFoldLanesFrom, lanes and a tail above), values of both
// signs, signed zeros, infinities and subnormals, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "analysis/lane_vector.hpp"

namespace quadval {
namespace {

using Limits = std::numeric_limits<double>;

std::vector<double> sample(std::size_t n, std::mt19937_64& rng) {
  const double specials[] = {0.0, -0.0, Limits::infinity(), -Limits::infinity(), Limits::denorm_min(),
                             -Limits::denorm_min(), Limits::max(), -Limits::max(), 1.0, -1.0};
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  std::uniform_int_distribution<int> pick(0, 9);
  std::vector<double> x(n);
  for (double& v : x) v = pick(rng) == 0 ? specials[pick(rng)] : u(rng);
  return x;
}

TEST(LaneFolds, LeastValueAndLargestMagnitudeMatchPlainFolds) {
  std::mt19937_64 rng(11);
  for (std::size_t n = 0; n <= 100; ++n)
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<double> x = sample(n, rng);
      const double least = n == 0 ? Limits::infinity() : *std::min_element(x.begin(), x.end());
      double largest = 0;
      for (double v : x) largest = std::max(largest, std::abs(v));
      // Equal as numbers; a zero's sign may differ with the order of the fold.
      EXPECT_EQ(least_value(x.data(), n), least) << "n = " << n;
      EXPECT_EQ(std::bit_cast<std::uint64_t>(largest_magnitude(x.data(), n)), std::bit_cast<std::uint64_t>(largest))
          << "n = " << n;
    }
}

TEST(LaneFolds, LaneMinAndMaxAreStdMinAndMaxPerLane) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 1000; ++trial) {
    const std::vector<double> a = sample(8, rng), b = sample(8, rng);
    const Lanes<8> lo = vmin(load_lanes<8>(a.data()), load_lanes<8>(b.data()));
    const Lanes<8> hi = vmax(load_lanes<8>(a.data()), load_lanes<8>(b.data()));
    for (int l = 0; l < 8; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      EXPECT_EQ(std::bit_cast<std::uint64_t>(lo[l]), std::bit_cast<std::uint64_t>(std::min(a[ul], b[ul])));
      EXPECT_EQ(std::bit_cast<std::uint64_t>(hi[l]), std::bit_cast<std::uint64_t>(std::max(a[ul], b[ul])));
    }
  }
}

}  // namespace
}  // namespace quadval
