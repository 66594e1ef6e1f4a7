// Edge bisection of tensor-product Bernstein polynomials by de Casteljau at 1/2
// (bernstein_bisection.hpp).
#include "bezier/bernstein_bisection.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "bezier/multi_index_table.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;
constexpr double kHalfDenormMin = 0x1p-1074;  // bound on the error of a subnormal halving

}  // namespace

FactorEdgeLines build_factor_edge_lines(int dim, int degree) {
  const std::vector<std::array<int, 4>> alphas = simplex_multi_indices(dim, degree);
  // (A std::map here was most of the first subdivision's cost: 20 us of a 230 us check
  // of tri_h0.4_o4.)
  const MultiIndexTable local_of(alphas, degree);
  FactorEdgeLines out;
  for (int a = 0; a <= dim; ++a)
    for (int b = 0; b <= dim; ++b) {
      if (a == b) continue;
      const auto k = static_cast<std::size_t>(a * 4 + b);
      std::vector<int>& first = out.first[k];
      std::vector<int>& index = out.index[k];
      first.push_back(0);
      for (const auto& alpha : alphas) {
        if (alpha[static_cast<std::size_t>(b)] != 0) continue;
        std::array<int, 4> beta = alpha;
        const int m = alpha[static_cast<std::size_t>(a)];
        for (int i = 0; i <= m; ++i) {
          beta[static_cast<std::size_t>(a)] = m - i;
          beta[static_cast<std::size_t>(b)] = i;
          index.push_back(local_of(beta));
        }
        first.push_back(static_cast<int>(index.size()));
      }
    }
  return out;
}

BernsteinBisection::BernsteinBisection(std::vector<FactorDegree> factors)
    : factors_(std::move(factors)) {
  QV_ASSERT(!factors_.empty() && factors_.size() <= 3, factors_.size() << " factors");
  std::array<std::vector<std::array<int, 4>>, 3> alphas;
  std::array<int, 3> sizes{1, 1, 1};
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    const FactorDegree fd = factors_[f];
    QV_ASSERT(fd.dim >= 1 && fd.dim <= 3 && fd.degree >= 0, "factor " << fd.dim << "/" << fd.degree);
    alphas[f] = simplex_multi_indices(fd.dim, fd.degree);
    sizes[f] = static_cast<int>(alphas[f].size());
    stride_[f] = size_;
    size_ *= sizes[f];
    dim_ += fd.dim;
  }
  QV_ASSERT(dim_ <= 3, "dimension " << dim_);

  for (std::size_t f = 0; f < factors_.size(); ++f) {
    // Offsets of every combination of the other factors' indices.
    for (int g = 0; g < size_; ++g)
      if ((g / stride_[f]) % sizes[f] == 0) bases_[f].push_back(g);
    const int d = factors_[f].dim;
    const int n = factors_[f].degree;
    if (const FactorEdgeLinesView* g = generated_factor_edge_lines(d, n)) {
      for (std::size_t k = 0; k < 16; ++k) lines_[f][k] = {g->first[k], g->index[k]};
    } else {
      built_lines_[f] = build_factor_edge_lines(d, n);
      for (std::size_t k = 0; k < 16; ++k) lines_[f][k] = {built_lines_[f].first[k], built_lines_[f].index[k]};
    }
    // Maubach's start (tag d). Triangles: (v1, v0, v2), so that the first edge is the
    // hypotenuse. Tetrahedra: (v0, v1, v2, v3), the image of the Kuhn simplex
    // (0, e1, e1 + e2, e1 + e2 + e3) under a linear map; measured on
    // warped_tetrahedron_o3_N6_a0.25.msh (--tol 1e-2, 1000 splits): 8 elements short of
    // the tolerance (the 8 folds of stuck_at_floor) against 11 when starting from
    // (v1, v0, v2, v3) and 22 with longest-edge bisection.
    root_.tag[f] = static_cast<std::int8_t>(d);
    root_.order[f] = d == 1   ? std::array<std::int8_t, 4>{0, 1, 0, 0}
                     : d == 2 ? std::array<std::int8_t, 4>{1, 0, 2, 0}
                              : std::array<std::int8_t, 4>{0, 1, 2, 3};
    // d bisections of degree n per split.
    rounding_relative_ += d * n * kUnit;
    rounding_absolute_ += d * n * kHalfDenormMin;
    halving_relative_ = std::max(halving_relative_, n * kUnit);
    halving_absolute_ = std::max(halving_absolute_, n * kHalfDenormMin);
  }
  // The bound above counts one rounding per average; multiplying by 1 + 1e-12 covers
  // the rounding of this bound's own products.
  rounding_relative_ *= 1 + 1e-12;
  rounding_absolute_ *= 1 + 1e-12;
  halving_relative_ *= 1 + 1e-12;
  halving_absolute_ *= 1 + 1e-12;

  // Vertex coefficients: alpha = n e_a in every factor.
  std::array<std::vector<int>, 3> vertex_local;
  for (std::size_t f = 0; f < 3; ++f) {
    if (f >= factors_.size()) {
      vertex_local[f] = {0};
      continue;
    }
    for (int i = 0; i < sizes[f]; ++i)
      for (int a = 0; a <= factors_[f].dim; ++a)
        if (alphas[f][static_cast<std::size_t>(i)][static_cast<std::size_t>(a)] == factors_[f].degree) {
          vertex_local[f].push_back(i);
          break;
        }
  }
  for (int i2 : vertex_local[2])
    for (int i1 : vertex_local[1])
      for (int i0 : vertex_local[0]) vertex_indices_.push_back(i0 + stride_[1] * i1 + stride_[2] * i2);
  std::sort(vertex_indices_.begin(), vertex_indices_.end());
}

namespace {

// The de Casteljau triangles of up to kRun parallel lines at once, lane j holding the line
// whose coefficient i sits at offset[i] + j * lane (lane = 1: side by side in memory); the
// children's coefficients go to the same places in keep_a and keep_b. Each coefficient gets
// the same averages, in the same order, as in the per-vector lanes of bisect().
constexpr std::size_t kRun = 8;
template <std::size_t kWidth, bool kSideBySide>
void casteljau_lanes(const double* src, const std::size_t* offset, std::size_t lane, int m, std::size_t width,
                     double* keep_a, double* keep_b, double (*w)[kRun]) {
  const std::size_t n = kWidth != 0 ? kWidth : width;
  const std::size_t step = kSideBySide ? 1 : lane;
  for (int i = 0; i <= m; ++i)
    for (std::size_t j = 0; j < n; ++j) w[i][j] = src[offset[i] + j * step];
  for (std::size_t j = 0; j < n; ++j) {
    keep_a[offset[0] + j * step] = w[0][j];
    keep_b[offset[m] + j * step] = w[m][j];
  }
  for (int r = 1; r <= m; ++r) {
    for (int i = 0; i + r <= m; ++i) {
#pragma omp simd
      for (std::size_t j = 0; j < n; ++j) w[i][j] = (w[i][j] + w[i + 1][j]) * 0.5;
    }
    for (std::size_t j = 0; j < n; ++j) {
      keep_a[offset[r] + j * step] = w[0][j];
      keep_b[offset[m - r] + j * step] = w[m - r][j];
    }
  }
}

#if defined(__AVX2__)
// The de Casteljau triangle of a line of M + 1 coefficients (M a constant), unrolled for
// the register kernels below: load(at[i]) gives coefficient i's lanes, store(out, at[i], x)
// writes them, average(x, y) = (x + y) * 0.5 lane by lane.
template <int M, class V, class Load, class Store, class Average>
inline void casteljau_unrolled(const std::size_t* at, Load load, Store store, Average average, double* keep_a,
                               double* keep_b) {
  V w[M + 1];
#pragma GCC unroll 17
  for (int i = 0; i <= M; ++i) w[i] = load(at[i]);
  store(keep_a, at[0], w[0]);
  store(keep_b, at[M], w[M]);
#pragma GCC unroll 16
  for (int r = 1; r <= M; ++r) {
#pragma GCC unroll 16
    for (int i = 0; i + r <= M; ++i) w[i] = average(w[i], w[i + 1]);
    store(keep_a, at[r], w[0]);
    store(keep_b, at[M - r], w[M - r]);
  }
}

constexpr int kMaxRegisterLine = 16;
#endif

#if defined(__AVX512F__)
// The de Casteljau triangle of up to 8 lines side by side (lane j holds the line whose
// coefficient i sits at at[i] + j: one masked vector load or store) whose length m + 1 is a
// constant, so that the whole triangle stays in registers; lanes outside `mask` are zero and
// never stored. The same averages, in the same order, as casteljau_lanes (bit-identical).
// Strided lines go to the scalar-load kernels below instead: on an AMD Zen 4 core, gathering
// and scattering them (one index vector per coefficient) took 2.7 times as long for the
// validity of warped_tetrahedron_o3 (one thread, best of 5: 12.1 -> 4.5 ms; its scaled
// Jacobian 69 -> 53 ms, mixed_h0.6_o2's 36 -> 32 ms; the rest the same or faster).
template <int M>
void casteljau_registers(const double* src, const std::size_t* at, __mmask8 mask, double* keep_a, double* keep_b) {
  const auto load = [&](std::size_t off) { return _mm512_maskz_loadu_pd(mask, src + off); };
  const auto store = [&](double* out, std::size_t off, __m512d x) { _mm512_mask_storeu_pd(out + off, mask, x); };
  const __m512d half = _mm512_set1_pd(0.5);
  casteljau_unrolled<M, __m512d>(
      at, load, store, [&](__m512d x, __m512d y) { return _mm512_mul_pd(_mm512_add_pd(x, y), half); }, keep_a,
      keep_b);
}

using RegisterKernel = void (*)(const double*, const std::size_t*, __mmask8, double*, double*);
template <int... M>
constexpr std::array<RegisterKernel, sizeof...(M)> register_kernels(std::integer_sequence<int, M...>) {
  return {&casteljau_registers<M>...};
}
constexpr std::array<RegisterKernel, kMaxRegisterLine + 1> kRegisterKernels =
    register_kernels(std::make_integer_sequence<int, kMaxRegisterLine + 1>());
#endif

#if defined(__AVX2__)
// The de Casteljau triangle of N <= 4 lanes (lane v: a vector's line or a neighbouring
// line, its coefficient i at v * size + at[i]), loaded and stored one double at a time, of
// degree M a constant, so that the triangle is unrolled into registers: no loop exits to
// mispredict, which cost more than the averages themselves (a degree-12 tetrahedron's 91
// lines of 1 to 13 coefficients: 3.1 us per halving of one vector with the loops). Lanes
// past N are zero and never stored. The same averages, in the same order, as casteljau_lanes
// and the per-vector lanes of bisect() (bit-identical).

template <int M, std::size_t N>
void casteljau_avx2(const double* src, const std::size_t* at, std::size_t size, double* keep_a, double* keep_b) {
  static_assert(N >= 1 && N <= 4);
  const auto load = [&](std::size_t off) {
    return _mm256_setr_pd(src[off], N > 1 ? src[size + off] : 0.0, N > 2 ? src[2 * size + off] : 0.0,
                          N > 3 ? src[3 * size + off] : 0.0);
  };
  const auto store = [&](double* out, std::size_t off, __m256d x) {
    const __m128d lo = _mm256_castpd256_pd128(x);
    _mm_storel_pd(out + off, lo);
    if constexpr (N > 1) _mm_storeh_pd(out + size + off, lo);
    if constexpr (N > 2) {
      const __m128d hi = _mm256_extractf128_pd(x, 1);
      _mm_storel_pd(out + 2 * size + off, hi);
      if constexpr (N > 3) _mm_storeh_pd(out + 3 * size + off, hi);
    }
  };
  const __m256d half = _mm256_set1_pd(0.5);
  casteljau_unrolled<M, __m256d>(
      at, load, store, [&](__m256d x, __m256d y) { return _mm256_mul_pd(_mm256_add_pd(x, y), half); }, keep_a,
      keep_b);
}

using Avx2Kernel = void (*)(const double*, const std::size_t*, std::size_t, double*, double*);
template <std::size_t N, int... M>
constexpr std::array<Avx2Kernel, sizeof...(M)> avx2_kernels(std::integer_sequence<int, M...>) {
  return {&casteljau_avx2<M, N>...};
}
// kAvx2Kernels[N - 1][M]
constexpr std::array<std::array<Avx2Kernel, kMaxRegisterLine + 1>, 4> kAvx2Kernels = {
    avx2_kernels<1>(std::make_integer_sequence<int, kMaxRegisterLine + 1>()),
    avx2_kernels<2>(std::make_integer_sequence<int, kMaxRegisterLine + 1>()),
    avx2_kernels<3>(std::make_integer_sequence<int, kMaxRegisterLine + 1>()),
    avx2_kernels<4>(std::make_integer_sequence<int, kMaxRegisterLine + 1>())};
#endif

}  // namespace

void BernsteinBisection::bisect(const double* in, std::size_t count, std::size_t f, int a, int b, double* keep_a,
                                double* keep_b) const {
  const EdgeLines& el = lines(f, a, b);
  const int stride = stride_[f];
  const auto size = static_cast<std::size_t>(size_);
  constexpr std::size_t kMaxLine = 128;
  // Lines of neighbouring bases, in lanes, vector by vector, where there are enough of
  // them: for a factor after the first, the bases come in runs of `stride` consecutive
  // offsets, so their lines sit side by side (contiguous loads and stores); for the first
  // factor, consecutive bases are one factor size apart. Else (a single factor) the lanes
  // hold the vectors, below. Measured on BM_CheckSharedQuality (scaled Jacobian, warm, one
  // thread, medians of 3): warped_hexahedron_o2 34.6 -> 26.6 ms, warped_prism_o2 43.5 ->
  // 40.4 ms, quad_h0.4_o2 1.40 -> 1.32 ms; the rest unchanged.
  const auto& bases = bases_[f];
  const bool side_by_side = f > 0;
  const std::size_t run = side_by_side ? static_cast<std::size_t>(stride) : bases.size();
  const std::size_t lane = side_by_side ? 1 : static_cast<std::size_t>(stride_[1]);
  if (run >= kRun / 2) {
    alignas(64) double w[kMaxLine][kRun];
    std::array<std::size_t, kMaxLine> offset;
    for (std::size_t v = 0; v < count; ++v) {
      const double* src = in + v * size;
      double* ka = keep_a + v * size;
      double* kb = keep_b + v * size;
      for (std::size_t r = 0; r < bases.size(); r += run)
        for (std::size_t l = 0; l + 1 < el.first.size(); ++l) {
          const int* idx = el.index.data() + el.first[l];
          const int m = el.first[l + 1] - el.first[l] - 1;
          QV_ASSERT(m < static_cast<int>(kMaxLine), "line of degree " << m);
          for (std::size_t j0 = 0; j0 < run; j0 += kRun) {
            const auto first = static_cast<std::size_t>(bases[r + j0]);
            for (int i = 0; i <= m; ++i)
              offset[static_cast<std::size_t>(i)] = first + static_cast<std::size_t>(stride * idx[i]);
            const std::size_t width = std::min(kRun, run - j0);
#if defined(__AVX512F__)
            if (m <= kMaxRegisterLine && side_by_side) {
              kRegisterKernels[static_cast<std::size_t>(m)](src, offset.data(),
                                                            static_cast<__mmask8>((1u << width) - 1), ka, kb);
              continue;
            }
#endif
#if defined(__AVX2__)
            if (m <= kMaxRegisterLine) {
              const std::size_t step = side_by_side ? 1 : lane;
              for (std::size_t h = 0; h < width; h += 4)
                kAvx2Kernels[std::min<std::size_t>(4, width - h) - 1][static_cast<std::size_t>(m)](
                    src + h * step, offset.data(), step, ka + h * step, kb + h * step);
              continue;
            }
#endif
            if (side_by_side && width == kRun)
              casteljau_lanes<kRun, true>(src, offset.data(), lane, m, width, ka, kb, w);
            else if (side_by_side)
              casteljau_lanes<0, true>(src, offset.data(), lane, m, width, ka, kb, w);
            else if (width == kRun)
              casteljau_lanes<kRun, false>(src, offset.data(), lane, m, width, ka, kb, w);
            else
              casteljau_lanes<0, false>(src, offset.data(), lane, m, width, ka, kb, w);
          }
        }
    }
    return;
  }
  // Up to G vectors at once, lane v holding vector v: the same averages per coefficient as
  // one vector alone (bit-identical), the index work shared and the averages vectorised
  // across the vectors. Lanes past the last vector hold zeros (set once per group: the
  // averages keep them zero), never stored. Without AVX-512, 4 lanes (one AVX2 register).
#if defined(__AVX512F__)
  bisect_vector_lanes<8>(in, count, f, el, keep_a, keep_b);
#else
  bisect_vector_lanes<4>(in, count, f, el, keep_a, keep_b);
#endif
}

template <std::size_t G>
void BernsteinBisection::bisect_vector_lanes(const double* in, std::size_t count, std::size_t f, const EdgeLines& el,
                                             double* keep_a, double* keep_b) const {
  constexpr std::size_t kMaxLine = 128;
  const int stride = stride_[f];
  const auto size = static_cast<std::size_t>(size_);
  alignas(64) std::array<double, kMaxLine * G> w;
  std::array<std::size_t, kMaxLine> at;  // a line's coefficient offsets
  // The longest line along an edge of a simplex factor of degree n: n + 1 coefficients.
  const auto longest = static_cast<std::size_t>(factors_[f].degree) + 1;
  QV_ASSERT(longest <= kMaxLine, "line of " << longest << " coefficients");
  for (std::size_t g0 = 0; g0 < count; g0 += G) {
    const std::size_t n = std::min(G, count - g0);
    for (std::size_t i = 0; i < longest; ++i)
      for (std::size_t v = n; v < G; ++v) w[i * G + v] = 0.0;
    const double* src = in + g0 * size;
    double* ka = keep_a + g0 * size;
    double* kb = keep_b + g0 * size;
    for (int base : bases_[f])
      for (std::size_t l = 0; l + 1 < el.first.size(); ++l) {
        const int* idx = el.index.data() + el.first[l];
        const int m = el.first[l + 1] - el.first[l] - 1;
        for (int i = 0; i <= m; ++i)
          at[static_cast<std::size_t>(i)] = static_cast<std::size_t>(base + stride * idx[i]);
#if defined(__AVX2__)
        if (m <= kMaxRegisterLine) {
          for (std::size_t h = 0; h < n; h += 4)  // vectors h .. h + 3
            kAvx2Kernels[std::min<std::size_t>(4, n - h) - 1][static_cast<std::size_t>(m)](
                src + h * size, at.data(), size, ka + h * size, kb + h * size);
          continue;
        }
#endif
        for (int i = 0; i <= m; ++i) {
          const std::size_t o = at[static_cast<std::size_t>(i)];
          for (std::size_t v = 0; v < n; ++v) w[static_cast<std::size_t>(i) * G + v] = src[v * size + o];
        }
        // Level r of the de Casteljau triangle: w[0] is the keep-a child's coefficient with
        // r midpoints, w[m - r] the keep-b child's with m - r copies of b.
        for (std::size_t v = 0; v < n; ++v) {
          ka[v * size + at[0]] = w[v];
          kb[v * size + at[static_cast<std::size_t>(m)]] = w[static_cast<std::size_t>(m) * G + v];
        }
        for (int r = 1; r <= m; ++r) {
          for (int j = 0; j + r <= m; ++j) {
            double* lo = w.data() + static_cast<std::size_t>(j) * G;
            const double* hi = lo + G;
#pragma omp simd
            for (std::size_t v = 0; v < G; ++v) lo[v] = (lo[v] + hi[v]) * 0.5;
          }
          const std::size_t ra = at[static_cast<std::size_t>(r)], rb = at[static_cast<std::size_t>(m - r)];
          for (std::size_t v = 0; v < n; ++v) {
            ka[v * size + ra] = w[v];
            kb[v * size + rb] = w[static_cast<std::size_t>(m - r) * G + v];
          }
        }
      }
  }
}

void BernsteinBisection::split(const double* parent, std::size_t count, const BisectionState& state,
                               double* children, BisectionState* states,
                               std::vector<double>& scratch) const {
  const auto block = static_cast<std::size_t>(size_) * count;
  const auto nc = static_cast<std::size_t>(num_children());
  // Pieces live in `children` (final layout) and `scratch` (the previous level), swapped
  // level by level; the last level must land in `children`.
  scratch.resize(block * nc);
  std::size_t levels = 0;
  for (const FactorDegree& fd : factors_) levels += static_cast<std::size_t>(fd.dim);
  double* cur = (levels % 2 == 0) ? children : scratch.data();
  double* nxt = (levels % 2 == 0) ? scratch.data() : children;
  std::copy(parent, parent + block, cur);
  states[0] = state;
  std::size_t pieces = 1;
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    for (int level = 0; level < factors_[f].dim; ++level) {
      // Descending: piece p is read before 2p and 2p + 1 are written.
      for (std::size_t p = pieces; p-- > 0;) {
        const BisectionState s = states[p];
        const auto& o = s.order[f];
        const int k = s.tag[f];
        const int a = o[0], b = o[static_cast<std::size_t>(k)];
        bisect(cur + p * block, count, f, a, b, nxt + (2 * p) * block, nxt + (2 * p + 1) * block);
        const auto tag = static_cast<std::int8_t>(k > 1 ? k - 1 : factors_[f].dim);
        BisectionState first = s, second = s;
        first.tag[f] = tag;   // (x_0..x_{k-1}, z, x_{k+1}..): z took x_k's slot b
        second.tag[f] = tag;  // (x_1..x_k, z, x_{k+1}..): z took x_0's slot a
        for (int i = 0; i < k; ++i) second.order[f][static_cast<std::size_t>(i)] = o[static_cast<std::size_t>(i + 1)];
        second.order[f][static_cast<std::size_t>(k)] = static_cast<std::int8_t>(a);
        states[2 * p] = first;
        states[2 * p + 1] = second;
      }
      pieces *= 2;
      std::swap(cur, nxt);
    }
  }
  QV_ASSERT(cur == children && pieces == nc, "bisection levels");
  for (std::size_t q = 0; q < nc; ++q) {
    states[q].depth = state.depth + 1;
    states[q].step = state.step + dim_;
  }
}

void BernsteinBisection::halve(const double* parent, std::size_t count, const BisectionState& state,
                               double* children, BisectionState* states) const {
  halve(parent, count, state, children, children + static_cast<std::size_t>(size_) * count, states);
}

void BernsteinBisection::halve(const double* parent, std::size_t count, const BisectionState& state,
                               double* first_child, double* second_child, BisectionState* states) const {
  // The factor split() would bisect at this point of its sequence.
  int level = state.step % dim_;
  std::size_t f = 0;
  while (level >= factors_[f].dim) level -= factors_[f].dim, ++f;
  const auto& o = state.order[f];
  const int k = state.tag[f];
  const int a = o[0], b = o[static_cast<std::size_t>(k)];
  bisect(parent, count, f, a, b, first_child, second_child);
  const auto tag = static_cast<std::int8_t>(k > 1 ? k - 1 : factors_[f].dim);
  BisectionState first = state, second = state;
  first.tag[f] = tag;
  second.tag[f] = tag;
  for (int i = 0; i < k; ++i) second.order[f][static_cast<std::size_t>(i)] = o[static_cast<std::size_t>(i + 1)];
  second.order[f][static_cast<std::size_t>(k)] = static_cast<std::int8_t>(a);
  for (BisectionState* st : {&first, &second}) {
    st->step = state.step + 1;
    st->depth = st->step / dim_;
  }
  states[0] = first;
  states[1] = second;
}

const BernsteinBisection& bernstein_bisection(std::span<const FactorDegree> factors) {
  using Key = std::vector<std::pair<int, int>>;
  static std::mutex mutex;
  static std::map<Key, std::unique_ptr<const BernsteinBisection>> cache;
  Key key;
  for (const FactorDegree& f : factors) key.emplace_back(f.dim, f.degree);
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[key];
  if (!slot) slot = std::make_unique<const BernsteinBisection>(std::vector<FactorDegree>(factors.begin(), factors.end()));
  return *slot;
}

}  // namespace quadval
