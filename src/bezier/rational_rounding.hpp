#pragma once
// Exact rationals to doubles, for the tables built once in GMP and then used in double
// arithmetic (Bézier conversions, derivative maps, products). Internal to src/.
#include <gmpxx.h>

#include <cmath>
#include <limits>

namespace quadval {

/// The largest double <= q.
inline double round_down(const mpq_class& q) {
  double d = q.get_d();  // truncated toward zero: within one ulp of q
  while (mpq_class(d) > q) d = std::nextafter(d, -std::numeric_limits<double>::infinity());
  while (mpq_class(std::nextafter(d, std::numeric_limits<double>::infinity())) <= q)
    d = std::nextafter(d, std::numeric_limits<double>::infinity());
  return d;
}

/// The smallest double >= q.
inline double round_up(const mpq_class& q) {
  double d = q.get_d();
  while (mpq_class(d) < q) d = std::nextafter(d, std::numeric_limits<double>::infinity());
  while (mpq_class(std::nextafter(d, -std::numeric_limits<double>::infinity())) >= q)
    d = std::nextafter(d, -std::numeric_limits<double>::infinity());
  return d;
}

/// The double nearest to q (either one on a tie): |result - q| <= u |q|, u = 2^-53, in
/// the normal range. Error bounds built on these tables may assume that much.
inline double nearest_double(const mpq_class& q) {
  const double lo = round_down(q), hi = round_up(q);
  return mpq_class(q - mpq_class(lo)) <= mpq_class(mpq_class(hi) - q) ? lo : hi;
}

}  // namespace quadval
