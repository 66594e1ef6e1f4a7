#pragma once
// W doubles side by side in one register (a GCC vector: each operation is the scalar one on
// every lane, in the same IEEE arithmetic, so lane l computes what an element computed
// alone does). Internal to src/analysis.
//
// Avoid W = 1: GCC 12 keeps a one-double vector in memory, with a store and a reload around
// every operation (measured: twice the time of two lanes). One element runs in two lanes
// instead, both reading it, and lane 0 is its result.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "bezier/native_lanes.hpp"

namespace quadval {

template <int W>
using Lanes = typename LaneVector<W>::Type;

template <int W>
Lanes<W> load_lanes(const double* p) {
  Lanes<W> v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Folds by min and max, lane by lane. Loops written with these instead of
// `#pragma omp simd reduction(min : m)` over std::min: GCC 12 compiles that reduction into
// masked gathers from an accumulator kept on the stack, one round trip through memory per
// step (a quarter of the scaled Jacobian's time on warped_tetrahedron_o3).

/// Every lane v.
template <int W>
Lanes<W> broadcast_lanes(double v) {
  return Lanes<W>{} + v;
}
/// std::min(a, b) on every lane (b where b < a, else a); V: Lanes<W> or double.
template <class V>
V vmin(V a, V b) {
  return b < a ? b : a;
}
/// std::max(a, b) on every lane (b where a < b, else a).
template <class V>
V vmax(V a, V b) {
  return a < b ? b : a;
}
/// |a| on every lane (-0 stays -0, which no comparison tells from +0).
template <class V>
V vabs(V a) {
  return a < 0 ? -a : a;
}
/// m folded with the lanes of v by std::min, lane 0 first.
template <class V>
double fold_min(V v, double m) {
  for (std::size_t l = 0; l < sizeof(V) / sizeof(double); ++l) m = std::min(m, v[l]);
  return m;
}
/// m folded with the lanes of v by std::max, lane 0 first.
template <class V>
double fold_max(V v, double m) {
  for (std::size_t l = 0; l < sizeof(V) / sizeof(double); ++l) m = std::max(m, v[l]);
  return m;
}

// Below this many values a plain loop is faster than the lanes and their final fold (mu of
// quadratic quadrangles: 3% slower with lanes from 8 values on).
inline constexpr std::size_t kFoldLanesFrom = 32;

// The folds below keep 8 running values (x_i in value i % 8), in registers of
// kNativeLanes, and fold them in the order 0..7: the same bits on every target.
inline constexpr int kFoldRegisters = 8 / kNativeLanes;

/// The least of x_0..x_{n-1} as std::min folds them (+inf for n = 0), 8 lanes at a time.
inline double least_value(const double* x, std::size_t n) {
  constexpr double kInf = __builtin_inf();
  double m = kInf;
  std::size_t i = 0;
  if (n >= kFoldLanesFrom) {
    Lanes<kNativeLanes> m8[kFoldRegisters];
    for (auto& r : m8) r = broadcast_lanes<kNativeLanes>(kInf);
    for (; i + 8 <= n; i += 8)
      for (int r = 0; r < kFoldRegisters; ++r) m8[r] = vmin(m8[r], load_lanes<kNativeLanes>(x + i + r * kNativeLanes));
    for (const auto& r : m8) m = fold_min(r, m);
  }
  for (; i < n; ++i) m = std::min(m, x[i]);
  return m;
}
/// max(0, |x_0|, ..., |x_{n-1}|) as std::max folds it, 8 lanes at a time.
inline double largest_magnitude(const double* x, std::size_t n) {
  double m = 0;
  std::size_t i = 0;
  if (n >= kFoldLanesFrom) {
    Lanes<kNativeLanes> m8[kFoldRegisters];
    for (auto& r : m8) r = broadcast_lanes<kNativeLanes>(0);
    for (; i + 8 <= n; i += 8)
      for (int r = 0; r < kFoldRegisters; ++r)
        m8[r] = vmax(m8[r], vabs(load_lanes<kNativeLanes>(x + i + r * kNativeLanes)));
    for (const auto& r : m8) m = fold_max(r, m);
  }
  for (; i < n; ++i) m = std::max(m, std::abs(x[i]));
  return m;
}

}  // namespace quadval
