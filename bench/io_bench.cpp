// MSH read and write speed on a large generated mesh: a structured grid of 1000 x 1000
// nodes split into 2 x 999 x 999 (about 2 million) linear triangles, plus its boundary lines.
//
//   build/bench/quadval_bench --benchmark_filter=Msh
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "quadval/io.hpp"

namespace {

using quadval::Mesh;

Mesh grid_mesh(std::size_t n) {
  Mesh m;
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < n; ++i) {
      m.node_tags.push_back(j * n + i + 1);
      m.coords.insert(m.coords.end(), {static_cast<double>(i) / static_cast<double>(n - 1) + 1e-7 * static_cast<double>(j),
                                       static_cast<double>(j) / static_cast<double>(n - 1), 0.0});
    }
  }
  m.node_blocks.push_back({2, 1, 0, n * n});
  quadval::ElementBlock tris;
  tris.type = quadval::find_element_type(2);
  tris.entity_dim = 2;
  tris.entity_tag = 1;
  quadval::Tag tag = 0;
  for (std::size_t j = 0; j + 1 < n; ++j) {
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const auto a = static_cast<quadval::NodeIndex>(j * n + i);
      const auto b = a + 1, c = static_cast<quadval::NodeIndex>(a + n), d = c + 1;
      tris.nodes.insert(tris.nodes.end(), {a, b, d, a, d, c});
      tris.tags.push_back(++tag);
      tris.tags.push_back(++tag);
    }
  }
  m.blocks.push_back(std::move(tris));
  return m;
}

const Mesh& big_mesh() {
  static const Mesh m = grid_mesh(1000);
  return m;
}

std::filesystem::path bench_file(const char* name, quadval::MeshFormat format, bool binary) {
  const auto path = std::filesystem::temp_directory_path() / name;
  static bool written[8] = {};
  const int slot = static_cast<int>(format) * 2 + (binary ? 1 : 0);
  if (!written[slot]) {
    quadval::write_mesh(big_mesh(), path, {format, binary});
    written[slot] = true;
  }
  return path;
}

void read_bench(benchmark::State& state, const char* name, quadval::MeshFormat format, bool binary) {
  const auto path = bench_file(name, format, binary);
  std::size_t elements = 0;
  for (auto _ : state) {
    const Mesh m = quadval::read_mesh(path);
    elements = m.num_elements();
    benchmark::DoNotOptimize(m.coords.data());
  }
  state.counters["elements"] = static_cast<double>(elements);
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(elements));
}

void write_bench(benchmark::State& state, quadval::MeshFormat format, bool binary) {
  const Mesh& m = big_mesh();
  const auto path = std::filesystem::temp_directory_path() / "quadval_bench_write.msh";
  for (auto _ : state) quadval::write_mesh(m, path, {format, binary});
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.num_elements()));
  std::filesystem::remove(path);
}

void BM_MshRead41Ascii(benchmark::State& s) { read_bench(s, "quadval_bench_41a.msh", quadval::MeshFormat::msh41, false); }
void BM_MshRead41Binary(benchmark::State& s) { read_bench(s, "quadval_bench_41b.msh", quadval::MeshFormat::msh41, true); }
void BM_MshRead22Ascii(benchmark::State& s) { read_bench(s, "quadval_bench_22a.msh", quadval::MeshFormat::msh22, false); }
void BM_MshRead22Binary(benchmark::State& s) { read_bench(s, "quadval_bench_22b.msh", quadval::MeshFormat::msh22, true); }
void BM_MshWrite41Ascii(benchmark::State& s) { write_bench(s, quadval::MeshFormat::msh41, false); }
void BM_MshWrite41Binary(benchmark::State& s) { write_bench(s, quadval::MeshFormat::msh41, true); }
void BM_VtuWrite(benchmark::State& s) { write_bench(s, quadval::MeshFormat::vtu, false); }

BENCHMARK(BM_MshRead41Ascii)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MshRead41Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MshRead22Ascii)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MshRead22Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MshWrite41Ascii)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MshWrite41Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_VtuWrite)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
