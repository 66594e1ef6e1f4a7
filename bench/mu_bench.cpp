// Throughput of the certified quality measures mu (mu_bounds, default tolerance 1e-3) and
// the scaled Jacobian (scaled_jacobian_bounds) next to the validity check of the same
// elements (jacobian_bounds, validity goal): batches of random curved elements of each
// family and order (reference nodes through a random near-identity affine map, every node
// moved by up to 0.1 / order).
//
//   build-mu/bench/quadval_bench --benchmark_filter='Mu|ScaledJacobian|Validity' --benchmark_repetitions=3
// Counters: elements/s; "subdiv" is the mean number of subdomains split per element for mu.
// BM_MuMode/<type>/<mode> compares mu's subdomain bounds (mu_control_bound.hpp): 0 the
// degree-12n certificate alone (the method before the control-matrix bound), 1 the
// control-matrix bound alone, 2 the default.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"
#include "analysis/mu_control_bound.hpp"

namespace quadval {
namespace {

// Elements per batch: fewer for the types whose degree-12n certificate is costly.
int batch(const ElementType& t) {
  const bool heavy = t.dim == 3 && t.order >= 2 && !(t.family == ElementFamily::tetrahedron && t.order == 2);
  return heavy ? 10 : 200;
}

std::vector<double> random_elements(const ElementType& type, int count) {
  std::mt19937 rng(static_cast<unsigned>(type.gmsh_id));
  std::uniform_real_distribution<double> u(-1, 1);
  const auto ref = reference_nodes(type);
  std::vector<double> out;
  for (int e = 0; e < count; ++e) {
    double a[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (auto& row : a)
      for (double& v : row) v += 0.2 * u(rng);
    if (type.dim == 2) a[2][0] = a[2][1] = a[0][2] = a[1][2] = 0, a[2][2] = 1;
    for (const auto& p : ref)
      for (int i = 0; i < 3; ++i) {
        double v = 0;
        for (int j = 0; j < 3; ++j) v += a[i][j] * p[static_cast<std::size_t>(j)];
        if (!(type.dim == 2 && i == 2)) v += 0.1 / type.order * u(rng);
        out.push_back(v);
      }
  }
  return out;
}

void BM_Mu(benchmark::State& state) {
  const ElementType& type = *find_element_type(static_cast<int>(state.range(0)));
  // Second argument (BM_MuMode): the subdomain bound of mu_control_bound.hpp's
  // mu_use_control_bound (0 certificate alone, 1 control matrices alone, 2 both).
  const int mode = state.range(1) >= 0 ? static_cast<int>(state.range(1)) : 2;
  mu_use_control_bound(mode);
  const int kBatch = batch(type);
  const auto x = random_elements(type, kBatch);
  const std::size_t stride = 3 * static_cast<std::size_t>(type.num_nodes);
  const QualityOptions opt;
  long subdivisions = 0;
  double sink = 0;
  for (auto _ : state) {
    for (int e = 0; e < kBatch; ++e) {
      const QualityBounds b = mu_bounds(type, std::span<const double>(x.data() + e * stride, stride), opt, true);
      sink += b.lower;
      subdivisions += b.subdivisions;
    }
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["subdiv"] = double(subdivisions) / double(state.iterations() * kBatch);
  state.SetLabel(std::string(type.name));
  mu_use_control_bound(2);
}

// The certified minimum of the scaled Jacobian (scaled_jacobian_bounds, default tolerance).
void BM_ScaledJacobian(benchmark::State& state) {
  const ElementType& type = *find_element_type(static_cast<int>(state.range(0)));
  const int kBatch = batch(type);
  const auto x = random_elements(type, kBatch);
  const std::size_t stride = 3 * static_cast<std::size_t>(type.num_nodes);
  const QualityOptions opt;
  long subdivisions = 0;
  double sink = 0;
  for (auto _ : state) {
    for (int e = 0; e < kBatch; ++e) {
      const QualityBounds b =
          scaled_jacobian_bounds(type, std::span<const double>(x.data() + e * stride, stride), opt, true);
      sink += b.lower;
      subdivisions += b.subdivisions;
    }
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["subdiv"] = double(subdivisions) / double(state.iterations() * kBatch);
  state.SetLabel(std::string(type.name));
}

void BM_Validity(benchmark::State& state) {
  const ElementType& type = *find_element_type(static_cast<int>(state.range(0)));
  const int kBatch = batch(type);
  const auto x = random_elements(type, kBatch);
  const std::size_t stride = 3 * static_cast<std::size_t>(type.num_nodes);
  BoundsWorkspace ws;
  BoundsOptions opt;
  opt.goal = BoundsGoal::validity;
  int valid = 0;
  for (auto _ : state) {
    for (int e = 0; e < kBatch; ++e)
      valid += jacobian_bounds(type, std::span<const double>(x.data() + e * stride, stride), opt, ws, true).validity ==
               Validity::valid;
  }
  benchmark::DoNotOptimize(valid);
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.SetLabel(std::string(type.name));
}

// Triangles 3, 6, 10; quadrangles 4, 9, 16; tetrahedra 4, 10, 20; prisms 6, 18;
// hexahedra 8, 27 (orders 1-3 where mu_supported).
#define QV_MU_TYPES ->Arg(2)->Arg(9)->Arg(21)->Arg(3)->Arg(10)->Arg(36)->Arg(4)->Arg(11)->Arg(29)->Arg(6)->Arg(13)->Arg(5)->Arg(12)
BENCHMARK(BM_Mu)->ArgsProduct({{2, 9, 21, 3, 10, 36, 4, 11, 29, 6, 13, 5, 12}, {-1}})->Unit(benchmark::kMicrosecond);
// The three subdomain bounds side by side.
BENCHMARK(BM_Mu)->Name("BM_MuMode")->ArgsProduct({{2, 9, 21, 3, 10, 36, 4, 11, 29, 6, 13, 5, 12}, {0, 1, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ScaledJacobian) QV_MU_TYPES->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Validity) QV_MU_TYPES->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace quadval
