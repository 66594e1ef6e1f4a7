// Recombination benchmarks on jittered grids of n triangles: the dual graph, the exact
// matching (blossom_solver.hpp), and the whole pipeline (the end-to-end figure with I/O is
// measured by bench/compare_gmsh_recombine.py). The matching is also timed on a jittered equilateral
// lattice: near-equilateral triangles (as Frontal-Delaunay makes) give nearly equal pair costs,
// the hard case of blossom algorithms (LEMON's fractional warm start and our alternating trees
// both grow superlinearly there), which the right-triangle grid with its spread of costs hides.
//
//   build/bench/quadval_bench --benchmark_filter=Recombine
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "quadval/recombine.hpp"
#include "recombine/dual_graph.hpp"
#include "recombine/matching.hpp"
#include "recombine/triangle_input.hpp"

namespace {

using namespace quadval;

// k x k cells of a jittered grid, each cut along a random diagonal: 2 k^2 triangles.
Mesh jittered_grid(int k, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.25, 0.25);
  Mesh m;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) {
      m.node_tags.push_back(m.node_tags.size() + 1);
      const double x = i + (i > 0 && i < k ? u(rng) : 0.0), y = j + (j > 0 && j < k ? u(rng) : 0.0);
      m.coords.insert(m.coords.end(), {x, y, 0.0});
    }
  ElementBlock b;
  b.type = find_element_type(2);
  b.entity_dim = 2;
  b.entity_tag = 1;
  auto id = [&](int i, int j) { return static_cast<NodeIndex>(j * (k + 1) + i); };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const NodeIndex a = id(i, j), c = id(i + 1, j), d = id(i + 1, j + 1), e = id(i, j + 1);
      const bool flip = rng() & 1;
      const NodeIndex t[6] = {a, c, flip ? d : e, flip ? a : c, d, e};
      b.nodes.insert(b.nodes.end(), t, t + 6);
      b.tags.push_back(b.tags.size() + 1);
      b.tags.push_back(b.tags.size() + 1);
    }
  m.blocks.push_back(std::move(b));
  return m;
}

// A k x k patch of the equilateral triangular lattice (rows offset by half a cell), interior
// nodes moved by up to 0.1 edge lengths: 2 k^2 near-equilateral triangles.
Mesh jittered_lattice(int k, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const double row_height = std::sqrt(3.0) / 2;
  Mesh m;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) {
      m.node_tags.push_back(m.node_tags.size() + 1);
      const bool inside = i > 0 && i < k && j > 0 && j < k;
      const double x = i + (j % 2 ? 0.5 : 0.0) + (inside ? u(rng) : 0.0);
      const double y = j * row_height + (inside ? u(rng) : 0.0);
      m.coords.insert(m.coords.end(), {x, y, 0.0});
    }
  ElementBlock b;
  b.type = find_element_type(2);
  b.entity_dim = 2;
  b.entity_tag = 1;
  auto id = [&](int i, int j) { return static_cast<NodeIndex>(j * (k + 1) + i); };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const NodeIndex a = id(i, j), c = id(i + 1, j), d = id(i + 1, j + 1), e = id(i, j + 1);
      // Even rows lean right (a c e, c d e), odd rows left (a c d, a d e): equilateral cells.
      const NodeIndex t[6] = {a, c, j % 2 ? d : e, j % 2 ? a : c, d, e};
      b.nodes.insert(b.nodes.end(), t, t + 6);
      b.tags.push_back(b.tags.size() + 1);
      b.tags.push_back(b.tags.size() + 1);
    }
  m.blocks.push_back(std::move(b));
  return m;
}

int cells_for(std::int64_t triangles) {
  return static_cast<int>(std::sqrt(static_cast<double>(triangles) / 2.0));
}

void BM_RecombineDualGraph(benchmark::State& state) {
  const Mesh m = jittered_grid(cells_for(state.range(0)));
  std::vector<std::string> warnings;
  const auto s = recombine_detail::prepare_triangles(m, "bench", warnings);
  for (auto _ : state) {
    recombine_detail::DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size()};
    benchmark::DoNotOptimize(recombine_detail::build_dual_graph(in));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.triangles.size()));
}

void run_blossom_matching(benchmark::State& state, const Mesh& m) {
  std::vector<std::string> warnings;
  const auto s = recombine_detail::prepare_triangles(m, "bench", warnings);
  recombine_detail::DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size()};
  const auto g = recombine_detail::build_dual_graph(in);
  for (auto _ : state) benchmark::DoNotOptimize(recombine_detail::blossom_matching(g));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.triangles.size()));
}

void BM_RecombineBlossomMatching(benchmark::State& state) {
  run_blossom_matching(state, jittered_grid(cells_for(state.range(0))));
}

void BM_RecombineBlossomMatchingLattice(benchmark::State& state) {
  run_blossom_matching(state, jittered_lattice(cells_for(state.range(0))));
}

void BM_RecombinePipeline(benchmark::State& state) {
  const Mesh m = jittered_grid(cells_for(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(recombine(m, {}));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.num_elements()));
}

BENCHMARK(BM_RecombineDualGraph)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecombineBlossomMatching)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecombineBlossomMatchingLattice)->Arg(10'000)->Arg(30'000)->Arg(100'000)
    ->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_RecombinePipeline)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
