// Look-ahead recombination (Paper II) on triangle meshes made here, in memory: a jittered
// triangular lattice of a rectangle (near-equilateral triangles, interior degree 6, as a
// frontal-Delaunay mesher gives) with 10k, 100k and 1M triangles. Times the selective tree at
// horizon 3 (issue 8's targets: 1M triangles under 10 s, 10x triangles at most 12x time), the
// building of its graph, and Blossom on the same pairs for comparison.
//
//   build/bench/quadval_bench --benchmark_filter=Lookahead
#include <cmath>
#include <map>
#include <memory>
#include <random>

#include <benchmark/benchmark.h>

#include "quadval/recombine.hpp"
#include "recombine/dual_graph.hpp"
#include "recombine/lookahead_state.hpp"
#include "recombine/lookahead_tree.hpp"
#include "recombine/matching.hpp"
#include "recombine/triangle_input.hpp"

namespace {

using namespace quadval;
namespace rd = quadval::recombine_detail;

// About `triangles` triangles: rows of a triangular lattice (odd rows shifted by half a
// step), nodes jittered by up to 0.2 of the step (boundary nodes along the boundary only),
// each strip between two rows cut into 2 * columns triangles.
Mesh jittered_lattice(std::int64_t triangles, unsigned seed) {
  const double h = std::sqrt(3.0) / 2.0;
  // columns / rows chosen so that the rectangle is about square: 2 nx ny = triangles.
  const int ny = std::max(2, static_cast<int>(std::sqrt(static_cast<double>(triangles) * h / 2.0)));
  const int nx = std::max(2, static_cast<int>(triangles / (2 * ny)));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  Mesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      // Odd rows are shifted by half a step, their first and last nodes pulled back onto
      // the sides x = 0 and x = nx.
      double x = i + ((j % 2 == 1) ? 0.5 : 0.0), y = j * h;
      if (i == 0) x = 0.0;
      if (i == nx) x = nx;
      if (i > 0 && i < nx) x += u(rng);
      if (j > 0 && j < ny) y += u(rng) * h;
      m.node_tags.push_back(m.node_tags.size() + 1);
      m.coords.insert(m.coords.end(), {x, y, 0.0});
    }
  ElementBlock b;
  b.type = find_element_type(2);
  b.entity_dim = 2;
  b.entity_tag = 1;
  auto id = [&](int i, int j) { return static_cast<NodeIndex>(j * (nx + 1) + i); };
  auto add = [&](NodeIndex p, NodeIndex q, NodeIndex r) {
    b.nodes.insert(b.nodes.end(), {p, q, r});
    b.tags.push_back(b.tags.size() + 1);
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const NodeIndex a = id(i, j), c = id(i + 1, j), d = id(i + 1, j + 1), e = id(i, j + 1);
      if (j % 2 == 0) {  // upper row shifted right: cut along c-e
        add(a, c, e);
        add(c, d, e);
      } else {  // lower row shifted right: cut along a-d
        add(a, c, d);
        add(a, d, e);
      }
    }
  m.blocks.push_back(std::move(b));
  return m;
}

struct Prepared {
  rd::TriangleSurface surface;
  rd::DualGraph dual;
  rd::LookaheadGraph graph;
};

// One prepared mesh per size, kept for all benchmarks of the run.
const Prepared& prepared(std::int64_t triangles) {
  static std::map<std::int64_t, std::unique_ptr<Prepared>> cache;
  auto& slot = cache[triangles];
  if (!slot) {
    slot = std::make_unique<Prepared>();
    std::vector<std::string> warnings;
    slot->surface = rd::prepare_triangles(jittered_lattice(triangles, 7), "bench", warnings);
    const auto& s = slot->surface;
    rd::DualGraphInput in{&s.coords, &s.triangles, &s.region, s.node_tags.size(),
                          PairCostKind::angle, nullptr, 0.0, false, 1000.0};
    slot->dual = rd::build_dual_graph(in);
    slot->graph = rd::build_lookahead_graph(slot->dual, s.triangles, s.node_tags.size());
  }
  return *slot;
}

void BM_LookaheadSelective(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  LookaheadOptions o;
  o.horizon = static_cast<int>(state.range(1));
  rd::LookaheadOutcome out;
  for (auto _ : state) out = rd::lookahead_run(p.graph, o, 1);
  const double n = p.graph.num_triangles;
  state.counters["triangles"] = n;
  state.counters["left_pct"] = 100.0 * static_cast<double>(out.run.triangles_left) / n;
  state.counters["search_steps_per_tri"] = static_cast<double>(out.run.search_steps) / n;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}

void BM_LookaheadGraph(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(rd::build_lookahead_graph(p.dual, p.surface.triangles,
                                                       p.surface.node_tags.size()));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.graph.num_triangles));
}

void BM_LookaheadBlossomSamePairs(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(rd::blossom_matching(p.dual));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.graph.num_triangles));
}

BENCHMARK(BM_LookaheadSelective)
    ->Args({10'000, 3})->Args({100'000, 3})->Args({1'000'000, 3})->Args({100'000, 5})
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LookaheadGraph)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LookaheadBlossomSamePairs)->Arg(10'000)->Arg(100'000)
    ->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
