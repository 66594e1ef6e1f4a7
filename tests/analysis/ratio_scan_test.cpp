// scan_ratios (ratio_scan.hpp) against the plain loop of divisions it replaces: the same
// extreme quotient bit for bit (a zero's sign aside), and the same least denominator, on
// random vectors of every tail length, with ties, both signs, zeros, quotients near the
// underflow threshold and non-finite entries.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "analysis/ratio_scan.hpp"

namespace quadval {
namespace {

template <bool kLeast>
RatioScan plain(const std::vector<double>& num, double a, const std::vector<double>& den, double b, double c) {
  RatioScan out{kLeast ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < num.size(); ++i) {
    const double q = (num[i] + a) / (den[i] + b);
    if (kLeast ? q < out.extreme : out.extreme < q) out.extreme = q;
    const double d = den[i] + c;
    if (d < out.least_den) out.least_den = d;
  }
  return out;
}

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

template <bool kLeast>
void expect_same(const std::vector<double>& num, double a, const std::vector<double>& den, double b, double c,
                 const char* what) {
  const RatioScan want = plain<kLeast>(num, a, den, b, c);
  const RatioScan got = scan_ratios<kLeast>(num.data(), a, den.data(), b, c, num.size());
  // A zero extreme may carry the other sign when it is reached by several elements (the
  // AVX2 path keeps an extreme per lane); every use tests its sign first.
  EXPECT_TRUE(same_bits(got.extreme, want.extreme) || (got.extreme == 0 && want.extreme == 0))
      << what << (kLeast ? " least " : " largest ") << got.extreme << " != " << want.extreme << ", size " << num.size();
  EXPECT_TRUE(same_bits(got.least_den, want.least_den) || (got.least_den == 0 && want.least_den == 0))
      << what << " least denominator " << got.least_den << " != " << want.least_den;
}

void expect_both(const std::vector<double>& num, double a, const std::vector<double>& den, double b, double c,
                 const char* what) {
  expect_same<true>(num, a, den, b, c, what);
  expect_same<false>(num, a, den, b, c, what);
}

TEST(RatioScan, EqualsThePlainLoopBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  // Every length to 40, then lengths around the blocks of 64 that the path without
  // AVX-512 divides at a time.
  std::vector<std::size_t> sizes;
  for (std::size_t size = 1; size <= 40; ++size) sizes.push_back(size);
  for (std::size_t size : {63, 64, 65, 100, 127, 128, 129, 200}) sizes.push_back(size);
  for (std::size_t size : sizes) {
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<double> num(size), den(size);
      const int scale = static_cast<int>(40 * u(rng));
      for (std::size_t i = 0; i < size; ++i) {
        num[i] = std::ldexp(u(rng), scale);
        den[i] = 0.5 + std::abs(u(rng));
      }
      // Quotients within a few ulps of each other: where an approximate reciprocal cannot
      // tell them apart.
      if (trial % 3 == 0)
        for (std::size_t i = 1; i < size; i += 2) {
          num[i] = std::nextafter(num[i - 1], 2 * num[i - 1]);
          den[i] = std::nextafter(den[i - 1], 0.0);
        }
      if (trial % 5 == 0)
        for (double& x : num) x = std::abs(x);
      expect_both(num, 1e-3 * u(rng), den, 1e-4 * u(rng), -1e-4, "random");
    }
  }
}

TEST(RatioScan, EdgeCasesEqualThePlainLoop) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Exact ties everywhere, zeros of both signs, all quotients zero or negative.
  expect_both({1, 2, 3, 4, 5, 6, 7, 8, 9}, 0, {2, 4, 6, 8, 10, 12, 14, 16, 18}, 0, 0, "ties");
  expect_both({0, -0.0, 0, 0, 0}, 0, {1, 2, 3, 4, 5}, 0, 0, "zeros");
  expect_both({1, -0.0, 1, 1, 0, 2}, 0, {1, 2, 3, 4, 5, 6}, 0, 0, "zeros in two lanes");
  expect_both({-1, -2, -3}, 0, {1, 1, 1}, 0, 0, "negative");
  // Quotients near and below the threshold of the approximation (2^-1000), subnormal.
  expect_both({0x1p-1020, 0x1p-1010, 0x1p-990, 0x1p-1000}, 0, {1, 3, 0x1p+20, 1.5}, 0, 0, "tiny");
  expect_both({0x1p-1060, 0x1p-1070, 0x1p-1074}, 0, {1, 0.75, 1}, 0, 0, "subnormal");
  expect_both({0x1p-1060, 1e-300, 0x1p-1074, 5e-324}, 0, {1, 1e300, 0.5, 3}, 0, 0, "mixed tiny");
  // Non-positive, tiny and huge denominators, infinities and NaN.
  expect_both({1, 2, 3, 4}, 0, {1, -1, 0, 2}, 0, 0, "non-positive denominator");
  expect_both({1, 2, 3}, 0, {0x1p-1070, 1, 2}, 0, 0, "tiny denominator");
  expect_both({1, 2, 3}, 0, {1e308, 1, 2}, 0, 0, "huge denominator");
  expect_both({1, inf, 3}, 0, {1, 1, 2}, 0, 0, "infinite numerator");
  expect_both({1, nan, 3, 0.5}, 0, {1, 1, 2, 4}, 0, 0, "NaN numerator");
  expect_both({1, 2, 3, 0.5}, 0, {1, nan, 2, 4}, 0, 0, "NaN denominator");
}

}  // namespace
}  // namespace quadval
