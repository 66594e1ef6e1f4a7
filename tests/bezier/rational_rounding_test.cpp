// nearest_double (one comparison with the midpoint of GMP's truncation and its neighbour)
// against its definition by the two-sided roundings round_down and round_up: the nearer
// of the two, the lower one on a tie. Random rationals of every size and sign, exact
// doubles, exact midpoints (ties), and non-canonical fractions (the tables build some).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bezier/rational_rounding.hpp"

namespace quadval {
namespace {

double nearest_by_definition(const mpq_class& q) {
  const double lo = round_down(q), hi = round_up(q);
  return mpq_class(q - mpq_class(lo)) <= mpq_class(mpq_class(hi) - q) ? lo : hi;
}

TEST(RationalRounding, NearestDoubleIsTheNearerOfBothRoundings) {
  std::mt19937_64 rng(42);
  int ties = 0, exact = 0;
  for (int t = 0; t < 200000; ++t) {
    mpz_class a = rng() >> (rng() % 60), b = (rng() >> (rng() % 60)) + 1;
    if (t % 3 == 0) a *= mpz_class(static_cast<unsigned long>(rng()));
    if (t % 5 == 0) b *= mpz_class(static_cast<unsigned long>(rng() | 1));
    if (t % 2 == 1) a = -a;
    mpq_class q;
    if (t % 13 == 0) {  // a tie: the midpoint of two neighbouring doubles
      const double x = static_cast<double>(rng() >> 11) * 1e-3;
      q = (mpq_class(x) + mpq_class(std::nextafter(x, INFINITY))) / 2;
      if (t % 2 == 1) q = -q;
      ++ties;
    } else if (t % 17 == 0) {  // exactly a double
      q = mpq_class(static_cast<double>(rng() >> 11) * 0.125);
      ++exact;
    } else if (t % 7 == 0) {  // not canonical: numerator and denominator share a factor
      const mpz_class k = mpz_class(static_cast<unsigned long>(rng() % 1000 + 2));
      q = mpq_class(mpz_class(a * k), mpz_class(b * k));
    } else {
      q = mpq_class(a, b);
      q.canonicalize();
    }
    ASSERT_EQ(nearest_double(q), nearest_by_definition(q)) << q.get_str();
  }
  EXPECT_GT(ties, 1000);
  EXPECT_GT(exact, 1000);
}

}  // namespace
}  // namespace quadval
