#pragma once
// The lane width of the vectorised arithmetic (src/bezier, src/analysis).

namespace quadval {

/// Doubles in one vector register of the target: 8 with AVX-512, else 4 (AVX2's width; at
/// least 4, as Lanes<2> has separate uses). The lane code runs at this width. A wider GCC
/// vector is split by the compiler, but its comparisons, selects and integer lanes into
/// scalars: with AVX2 only, an 8-lane next_up takes 239 instructions and a compare and
/// select 204, against 22 and 15 at 4 lanes (mu of the curved triangle plate took 2.9 times
/// its time on an AVX-512 machine). Every lane computes what one element alone does, so the
/// width changes no result.
inline constexpr int kNativeLanes =
#if defined(__AVX512F__)
    8;
#else
    4;
#endif

/// A GCC vector of W doubles (LaneVector<W>::Type; src/analysis names it Lanes<W>).
template <int W>
struct LaneVector {
  typedef double Type __attribute__((vector_size(8 * W)));
};

}  // namespace quadval
