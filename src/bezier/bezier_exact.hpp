#pragma once
// Exact rational data of a Bernstein factor, for the exact-arithmetic fallback of the
// Jacobian bounds (src/analysis). Internal: GMP stays out of the public headers.
#include <gmpxx.h>

#include <mutex>
#include <vector>

#include "quadval/bezier_basis.hpp"

namespace quadval {

struct BernsteinSimplex::Exact {
  /// The exact Lagrange-to-Bézier matrix T (size x size, row-major), eq. (18).
  std::vector<mpq_class> to_bezier;
  /// The subdivision matrices as exact rationals (num_children blocks of size x size);
  /// copied from the (exact, dyadic) doubles on first exact().
  std::vector<mpq_class> subdivision;
  std::once_flag subdivision_once;
};

}  // namespace quadval
