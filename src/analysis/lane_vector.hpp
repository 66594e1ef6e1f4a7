#pragma once
// W doubles side by side in one register (a GCC vector: each operation is the scalar one on
// every lane, in the same IEEE arithmetic, so lane l computes what an element computed
// alone does). Internal to src/analysis.
//
// Avoid W = 1: GCC 12 keeps a one-double vector in memory, with a store and a reload around
// every operation (measured: twice the time of two lanes). One element runs in two lanes
// instead, both reading it, and lane 0 is its result.
#include <cstring>

namespace quadval {

template <int W>
struct LaneVector {
  typedef double Type __attribute__((vector_size(8 * W)));
};
template <int W>
using Lanes = typename LaneVector<W>::Type;

template <int W>
Lanes<W> load_lanes(const double* p) {
  Lanes<W> v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

}  // namespace quadval
