#pragma once
// Small helpers shared by the scaled-Jacobian tests: 3-vectors, and straight elements of
// any order through given corners.
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval::test {

using Vec = std::array<double, 3>;

inline Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Vec& a) { return std::sqrt(dot(a, a)); }
inline Vec minus(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
/// sum_k w_k c_k.
inline Vec combo(const std::array<Vec, 3>& c, const Vec& w) {
  Vec out{};
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t j = 0; j < 3; ++j) out[j] += w[k] * c[k][j];
  return out;
}

/// The nodes of `type` on the straight element through `corners` (the family's vertices in
/// Gmsh order), placed with the first-order shape functions.
inline std::vector<double> straight_element(const ElementType& type, const std::vector<Vec>& corners) {
  const LagrangeBasis& lb = lagrange_basis(*find_element_type(type.family, 1, true));
  std::vector<double> x, w(static_cast<std::size_t>(lb.num_nodes()));
  for (const RefPoint& p : reference_nodes(type)) {
    lb.evaluate(p, w);
    for (std::size_t j = 0; j < 3; ++j) {
      double v = 0;
      for (std::size_t i = 0; i < corners.size(); ++i) v += w[i] * corners[i][j];
      x.push_back(v);
    }
  }
  return x;
}

}  // namespace quadval::test
