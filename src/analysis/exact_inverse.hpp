#pragma once
// Exact inverse of a generalized Vandermonde matrix (rationals), for the exact shape-function
// gradients of jacobian_space.cpp and pyramid_space.cpp. Internal to src/analysis.
#include <gmpxx.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "quadval/element_type.hpp"
#include "quadval/error.hpp"

namespace quadval {

/// V^{-1} of the n x n row-major matrix v, by Gauss-Jordan in exact rational arithmetic
/// (rows with a zero pivot are swapped; zeros are skipped, the matrices are sparse).
/// @pre v is invertible: a singular v means the type's nodes are not unisolvent for its
///      space, a bug, reported with QV_ASSERT naming `type`.
inline std::vector<mpq_class> exact_inverse(std::vector<mpq_class> v, std::size_t n,
                                            const ElementType& type) {
  std::vector<mpq_class> inv(n * n, mpq_class(0));
  for (std::size_t i = 0; i < n; ++i) inv[i * n + i] = 1;
  for (std::size_t col = 0; col < n; ++col) {
    std::size_t piv = col;
    while (piv < n && sgn(v[piv * n + col]) == 0) ++piv;
    QV_ASSERT(piv < n, "nodes not unisolvent for " << type.name);
    if (piv != col)
      for (std::size_t c = 0; c < n; ++c) {
        std::swap(v[piv * n + c], v[col * n + c]);
        std::swap(inv[piv * n + c], inv[col * n + c]);
      }
    const mpq_class pv = v[col * n + col];
    for (std::size_t c = 0; c < n; ++c) {
      v[col * n + c] /= pv;
      inv[col * n + c] /= pv;
    }
    for (std::size_t r = 0; r < n; ++r) {
      if (r == col || sgn(v[r * n + col]) == 0) continue;
      const mpq_class f = v[r * n + col];
      for (std::size_t c = 0; c < n; ++c) {
        if (sgn(v[col * n + c]) != 0) v[r * n + c] -= f * v[col * n + c];
        if (sgn(inv[col * n + c]) != 0) inv[r * n + c] -= f * inv[col * n + c];
      }
    }
  }
  return inv;
}

}  // namespace quadval
