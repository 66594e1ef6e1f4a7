// Jacobian bounds of curved pyramids against hexahedra of the same order, per element and
// per Bézier coefficient of J (issue 4: pyramids no slower per coefficient than hexahedra).
// Validity goal, one thread, random curved elements (amplitude 0.1, mostly valid).
// BM_*Bounds: the general path per element (jacobian_bounds); BM_LinearChunk*: the
// first-order fast path of check_mesh (analysis/linear_jacobian.hpp), a chunk at a time.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "analysis/linear_jacobian.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/check_report.hpp"
#include "quadval/io.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

std::vector<std::vector<double>> random_elements(const ElementType& type, int count) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::vector<double>> out;
  for (int e = 0; e < count; ++e) {
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(type))
      for (int k = 0; k < 3; ++k) x.push_back(p[static_cast<std::size_t>(k)] + 0.1 * u(rng));
    out.push_back(std::move(x));
  }
  return out;
}

void bm_bounds(benchmark::State& state, ElementFamily family) {
  const ElementType& type = *find_element_type(family, static_cast<int>(state.range(0)), true);
  const auto elements = random_elements(type, 256);
  const int coeffs = bezier_basis(family, type.order).size();
  BoundsWorkspace ws;
  const BoundsOptions opt;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(jacobian_bounds(type, elements[i], opt, ws));
    i = (i + 1) % elements.size();
  }
  state.counters["elements/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["coeffs/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * coeffs, benchmark::Counter::kIsRate);
  state.counters["coeffs"] = coeffs;
}

// One full chunk of first-order elements through linear_validity_chunk. "coeffs" counts
// the Bézier coefficients of J in the element's J space (27 hexahedron; 9 pyramid, Paper
// IV's degree (2, 2), the general path's basis), "fast coeffs" those the fast path forms
// (27; 4, the pyramid's J being bilinear).
void bm_linear_chunk(benchmark::State& state, ElementFamily family) {
  const ElementType& type = *find_element_type(family, 1, true);
  const LinearKind kind = linear_kind(type, false);
  const auto nv = static_cast<std::size_t>(linear_num_vertices(kind));
  const auto elements = random_elements(type, static_cast<int>(kLinearChunk));
  std::vector<double> soa(nv * 3 * kLinearRow);
  for (std::size_t e = 0; e < kLinearChunk; ++e)
    for (std::size_t v = 0; v < nv; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow + e] = elements[e][v * 3 + a];
  std::vector<JacobianBounds> out(kLinearChunk);
  bool decided[kLinearChunk];
  for (auto _ : state) {
    linear_validity_chunk(kind, soa.data(), kLinearChunk, out.data(), decided);
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(decided);
  }
  std::size_t open = 0;
  for (bool d : decided) open += d ? 0 : 1;
  const int fast = family == ElementFamily::pyramid ? 4 : 27;
  const double n = static_cast<double>(state.iterations()) * static_cast<double>(kLinearChunk);
  const int coeffs = bezier_basis(family, 1).size();
  state.counters["elements/s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["coeffs/s"] = benchmark::Counter(n * coeffs, benchmark::Counter::kIsRate);
  state.counters["fast coeffs/s"] = benchmark::Counter(n * fast, benchmark::Counter::kIsRate);
  state.counters["undecided"] = static_cast<double>(open);
}

void BM_LinearChunkPyramid(benchmark::State& s) { bm_linear_chunk(s, ElementFamily::pyramid); }
void BM_LinearChunkHexahedron(benchmark::State& s) { bm_linear_chunk(s, ElementFamily::hexahedron); }
BENCHMARK(BM_LinearChunkPyramid);
BENCHMARK(BM_LinearChunkHexahedron);


void BM_PyramidBounds(benchmark::State& s) { bm_bounds(s, ElementFamily::pyramid); }
void BM_HexahedronBounds(benchmark::State& s) { bm_bounds(s, ElementFamily::hexahedron); }
BENCHMARK(BM_PyramidBounds)->DenseRange(1, 3);
BENCHMARK(BM_HexahedronBounds)->DenseRange(1, 3);

}  // namespace
}  // namespace quadval
