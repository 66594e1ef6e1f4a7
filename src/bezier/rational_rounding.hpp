#pragma once
// Exact rationals to doubles, for the tables built once in GMP and then used in double
// arithmetic (Bézier conversions, derivative maps, products). Internal to src/.
#include <gmpxx.h>

#include <algorithm>
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

/// The double nearest to q (the lower one on a tie): |result - q| <= u |q|, u = 2^-53, in
/// the normal range. Error bounds built on these tables may assume that much.
/// GMP's get_d truncates toward zero: q is d or lies strictly between d and e, the next
/// double away from zero; it is then compared once with their midpoint (exact: a sum of two
/// doubles). tests/bezier/rational_rounding_test.cpp checks it against the definition.
inline double nearest_double(const mpq_class& q) {
  const double d = q.get_d();
  const mpq_class dq(d);
  if (cmp(dq, q) == 0) return d;  // cmp, not ==: q need not be canonical
  const double e = std::nextafter(d, sgn(q) > 0 ? std::numeric_limits<double>::infinity()
                                                : -std::numeric_limits<double>::infinity());
  const double lo = std::min(d, e), hi = std::max(d, e);
  return mpq_class(2 * q) <= mpq_class(dq + mpq_class(e)) ? lo : hi;
}

}  // namespace quadval
