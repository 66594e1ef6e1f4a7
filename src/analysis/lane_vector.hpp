#pragma once
// W doubles side by side in one register (a GCC vector: each operation is the scalar one on
// every lane, in the same IEEE arithmetic, so lane l computes what an element computed
// alone does). Internal to src/analysis.
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
