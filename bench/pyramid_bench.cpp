// Jacobian bounds of curved pyramids against hexahedra of the same order, per element and
// per Bézier coefficient of J (issue 4: pyramids no slower per coefficient than hexahedra).
// Validity goal, one thread, random curved elements (amplitude 0.1, mostly valid).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "quadval/bezier_basis.hpp"
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

void BM_PyramidBounds(benchmark::State& s) { bm_bounds(s, ElementFamily::pyramid); }
void BM_HexahedronBounds(benchmark::State& s) { bm_bounds(s, ElementFamily::hexahedron); }
BENCHMARK(BM_PyramidBounds)->DenseRange(1, 3);
BENCHMARK(BM_HexahedronBounds)->DenseRange(1, 3);

}  // namespace
}  // namespace quadval
