// Throughput of the certified Jacobian check (check_mesh, validity) on structured meshes
// built in memory: linear hexahedra with perturbed nodes, and third-order tetrahedra
// (6 Kuhn tetrahedra per cube) with every lattice node perturbed, so all are curved
// (amplitude 0.15 of the node spacing: more than half invalid; 0.05: mostly valid), the
// same with second-order tetrahedra, and separate random curved hexahedra (orders 2, 3)
// and pyramids (order 2).
//
//   build-jac/bench/quadval_bench --benchmark_filter=Check --benchmark_repetitions=3
// Counters: elements/s (wall), and the answers so a regression in them shows.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <utility>
#include <vector>

#include "analysis/jacobian_engine.hpp"
#include "analysis/jacobian_space.hpp"
#include "quadval/check_report.hpp"
#include "quadval/io.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

// (n+1)^3 nodes on a unit-spaced lattice, perturbed by up to `amp`.
Mesh linear_hexes(int n, double amp) {
  Mesh m;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-amp, amp);
  const auto id = [n](int i, int j, int k) { return static_cast<NodeIndex>(i + (n + 1) * (j + (n + 1) * k)); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        m.node_tags.push_back(m.node_tags.size() + 1);
        m.coords.insert(m.coords.end(), {i + u(rng), j + u(rng), k + u(rng)});
      }
  ElementBlock b;
  b.type = find_element_type(5);
  b.entity_dim = 3;
  b.entity_tag = 1;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        b.tags.push_back(b.tags.size() + 1);
        b.nodes.insert(b.nodes.end(), {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                                       id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                                       id(i, j + 1, k + 1)});
      }
  m.blocks.push_back(std::move(b));
  return m;
}

// n^2 first-order quadrangles, or 2 n^2 triangles, on the unit-spaced lattice of the plane
// z = 0 with its nodes perturbed by up to `amp` (a few quadrangles fold at 0.3).
Mesh linear_planar(int n, double amp, bool triangles) {
  Mesh m;
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-amp, amp);
  const auto id = [n](int i, int j) { return static_cast<NodeIndex>(i + (n + 1) * j); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      m.node_tags.push_back(m.node_tags.size() + 1);
      m.coords.insert(m.coords.end(), {i + u(rng), j + u(rng), 0.0});
    }
  ElementBlock b;
  b.type = find_element_type(triangles ? 2 : 3);
  b.entity_dim = 2;
  b.entity_tag = 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const NodeIndex q[4] = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
      if (triangles) {
        b.nodes.insert(b.nodes.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
        b.tags.insert(b.tags.end(), {b.tags.size() + 1, b.tags.size() + 2});
      } else {
        b.nodes.insert(b.nodes.end(), {q[0], q[1], q[2], q[3]});
        b.tags.push_back(b.tags.size() + 1);
      }
    }
  m.blocks.push_back(std::move(b));
  return m;
}

// 6 n^3 order-p tetrahedra; nodes on the lattice of step 1/p, all perturbed by up to amp/p.
Mesh curved_tets(int n, int p, double amp) {
  Mesh m;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-amp / p, amp / p);
  const int L = p * n + 1;
  for (int k = 0; k < L; ++k)
    for (int j = 0; j < L; ++j)
      for (int i = 0; i < L; ++i) {
        m.node_tags.push_back(m.node_tags.size() + 1);
        m.coords.insert(m.coords.end(), {double(i) / p + u(rng), double(j) / p + u(rng), double(k) / p + u(rng)});
      }
  const ElementType& type = *find_element_type(ElementFamily::tetrahedron, p, true);
  const auto ref = reference_nodes(type);
  // Kuhn subdivision of the unit cube: paths 0 -> 7 through the cube corners.
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  static constexpr bool kOdd[6] = {false, true, true, false, false, true};
  ElementBlock b;
  b.type = &type;
  b.entity_dim = 3;
  b.entity_tag = 1;
  for (int ck = 0; ck < n; ++ck)
    for (int cj = 0; cj < n; ++cj)
      for (int ci = 0; ci < n; ++ci)
        for (const auto& perm : kPerm) {
          std::array<std::array<int, 3>, 4> v{};  // tet vertices, in lattice cells
          v[0] = {0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            v[static_cast<std::size_t>(s + 1)] = v[static_cast<std::size_t>(s)];
            v[static_cast<std::size_t>(s + 1)][static_cast<std::size_t>(perm[s])] = 1;
          }
          // Odd permutations give negatively oriented tetrahedra: swap two vertices.
          if (kOdd[&perm - kPerm]) std::swap(v[1], v[2]);
          b.tags.push_back(b.tags.size() + 1);
          for (const auto& r : ref) {
            const double lam[4] = {1 - r[0] - r[1] - r[2], r[0], r[1], r[2]};
            int q[3];
            for (int a = 0; a < 3; ++a) {
              double x = 0;
              for (int c = 0; c < 4; ++c) x += lam[c] * v[static_cast<std::size_t>(c)][static_cast<std::size_t>(a)];
              q[a] = static_cast<int>(std::lround(x * p)) + p * (a == 0 ? ci : a == 1 ? cj : ck);
            }
            b.nodes.push_back(static_cast<NodeIndex>(q[0] + L * (q[1] + L * q[2])));
          }
        }
  m.blocks.push_back(std::move(b));
  return m;
}

// `count` elements of `type`, each with its own nodes: the reference nodes (element size
// about 1) on a row, every node moved by up to `amp` at random, so all are curved.
Mesh random_curved_block(const ElementType& type, std::size_t count, double amp) {
  Mesh m;
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-amp, amp);
  const auto ref = reference_nodes(type);
  ElementBlock b;
  b.type = &type;
  b.entity_dim = type.dim;
  b.entity_tag = 1;
  for (std::size_t e = 0; e < count; ++e) {
    b.tags.push_back(b.tags.size() + 1);
    for (const auto& r : ref) {
      b.nodes.push_back(static_cast<NodeIndex>(m.node_tags.size()));
      m.node_tags.push_back(m.node_tags.size() + 1);
      m.coords.insert(m.coords.end(), {2.0 * static_cast<double>(e) + r[0] + u(rng), r[1] + u(rng), r[2] + u(rng)});
    }
  }
  m.blocks.push_back(std::move(b));
  return m;
}

void run(benchmark::State& state, const Mesh& mesh) {
  CheckOptions o;
  o.threads = static_cast<int>(state.range(1));
  CheckReport r;
  for (auto _ : state) {
    r = check_mesh(mesh, o);
    benchmark::DoNotOptimize(r.elements.data());
  }
  state.counters["elements/s"] =
      benchmark::Counter(static_cast<double>(mesh.num_elements()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["valid"] = static_cast<double>(r.count(Validity::valid));
  state.counters["invalid"] = static_cast<double>(r.count(Validity::invalid));
  state.counters["undetermined"] = static_cast<double>(r.count(Validity::undetermined));
  // Elements that needed subdivision (stage >= 2 of Paper III Table 2).
  std::size_t subdivided = 0;
  for (std::size_t i = 2; i < r.stages.size(); ++i) subdivided += r.stages[i].valid + r.stages[i].invalid;
  state.counters["subdivided"] = static_cast<double>(subdivided);
}

void BM_CheckLinearHex(benchmark::State& state) {
  static const Mesh mesh = linear_hexes(static_cast<int>(state.range(0)), 0.2);
  run(state, mesh);
}
BENCHMARK(BM_CheckLinearHex)->Args({100, 1})->Args({100, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CheckCurvedTetP3(benchmark::State& state) {
  static const Mesh mesh = curved_tets(static_cast<int>(state.range(0)), 3, 0.15);
  run(state, mesh);
}
// 6 * 55^3 = 998,250 tetrahedra
BENCHMARK(BM_CheckCurvedTetP3)->Args({55, 1})->Args({55, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

// The same lattice with milder perturbations: mostly valid, as in a usable curved mesh.
void BM_CheckCurvedTetP3Mild(benchmark::State& state) {
  static const Mesh mesh = curved_tets(static_cast<int>(state.range(0)), 3, 0.05);
  run(state, mesh);
}
BENCHMARK(BM_CheckCurvedTetP3Mild)->Args({55, 1})->Args({55, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CheckCurvedTetP2(benchmark::State& state) {
  static const Mesh mesh = curved_tets(static_cast<int>(state.range(0)), 2, 0.15);
  run(state, mesh);
}
BENCHMARK(BM_CheckCurvedTetP2)->Args({55, 1})->Args({55, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

// One thread: validity (range 1 = 0), mu (1) or the scaled Jacobian (2), for the cost of
// each measure over the validity check.
void run_quality(benchmark::State& state, const Mesh& mesh) {
  CheckOptions o;
  o.threads = 1;
  o.measure = state.range(1) == 0 ? CheckMeasure::validity : state.range(1) == 1 ? CheckMeasure::mu
                                                                                 : CheckMeasure::scaled_jacobian;
  for (auto _ : state) benchmark::DoNotOptimize(check_mesh_streamed(mesh, o, "", {}));
  state.counters["elements/s"] = benchmark::Counter(static_cast<double>(mesh.num_elements()),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}

// First-order tetrahedra, 6 n^3 (range 0).
void BM_CheckLinearTetQuality(benchmark::State& state) {
  static const Mesh mesh = curved_tets(static_cast<int>(state.range(0)), 1, 0.15);
  run_quality(state, mesh);
}
// 6 * 40^3 = 384,000 tetrahedra
BENCHMARK(BM_CheckLinearTetQuality)->ArgsProduct({{40}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// First-order planar triangles (2 n^2) and quadrangles (n^2), range 0 = n.
void BM_CheckLinearTriangleQuality(benchmark::State& state) {
  static const Mesh mesh = linear_planar(static_cast<int>(state.range(0)), 0.3, true);
  run_quality(state, mesh);
}
// 2 * 400^2 = 320,000 triangles
BENCHMARK(BM_CheckLinearTriangleQuality)->ArgsProduct({{400}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

void BM_CheckLinearQuadQuality(benchmark::State& state) {
  static const Mesh mesh = linear_planar(static_cast<int>(state.range(0)), 0.3, false);
  run_quality(state, mesh);
}
// 500^2 = 250,000 quadrangles
BENCHMARK(BM_CheckLinearQuadQuality)->ArgsProduct({{500}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// First-order hexahedra, n^3 (range 0), vertices moved by up to 0.2 of the spacing.
void BM_CheckLinearHexQuality(benchmark::State& state) {
  static const Mesh mesh = linear_hexes(static_cast<int>(state.range(0)), 0.2);
  run_quality(state, mesh);
}
BENCHMARK(BM_CheckLinearHexQuality)->ArgsProduct({{40}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// Separate random elements of one Gmsh type (range 2), range 0 of them.
void BM_CheckCurvedType(benchmark::State& state) {
  const Mesh mesh = random_curved_block(*find_element_type(static_cast<int>(state.range(2))),
                                        static_cast<std::size_t>(state.range(0)), 0.08);
  run(state, mesh);
}
// hexahedra of order 2 (27 nodes, type 12) and 3 (64 nodes, type 92); pyramids of order 2
// (14 nodes, type 19)
BENCHMARK(BM_CheckCurvedType)
    ->ArgsProduct({{100000}, {1, 2}, {12, 92, 19}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A curved mesh of ../shared/data: the shared folder is $QUADVAL_SHARED_DIR, else ../shared
// beside the repository; false (an error row) when the file cannot be read.
bool read_shared_curved(benchmark::State& state, const std::string& name, Mesh& mesh) {
  const char* env = std::getenv("QUADVAL_SHARED_DIR");
  const std::string dir =
      env ? env : (std::filesystem::path(__FILE__).parent_path() / ".." / ".." / "shared").string();
  try {
    mesh = read_mesh(dir + "/data/curved/" + name + ".msh");
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return false;
  }
  return true;
}

// check as `quadval check FILE -q` runs it (streamed, summary only) on each curved mesh of
// ../shared/data, the meshes of bench/compare_gmsh_check.py: small ones, where fixed and
// per-element costs show.
void BM_CheckSharedCurved(benchmark::State& state, const std::string& name) {
  Mesh mesh;
  if (!read_shared_curved(state, name, mesh)) return;
  CheckOptions o;
  o.threads = static_cast<int>(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(check_mesh_streamed(mesh, o, name, [](const CheckBatch&) {}));
  state.counters["elements/s"] = benchmark::Counter(static_cast<double>(mesh.num_elements()),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}

// The quality measures of `check` (mu, the scaled Jacobian; validity included) on a mesh,
// one thread, at the CLI's default tolerance: Arg 0 mu, 1 the scaled Jacobian.
void check_quality(benchmark::State& state, const Mesh& mesh, const std::string& name) {
  CheckOptions o;
  o.threads = 1;
  o.measure = state.range(0) == 0 ? CheckMeasure::mu : CheckMeasure::scaled_jacobian;
  for (auto _ : state)
    benchmark::DoNotOptimize(check_mesh_streamed(mesh, o, name, {}));
  state.counters["elements/s"] = benchmark::Counter(static_cast<double>(mesh.num_elements()),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}

// On a shared mesh.
void BM_CheckSharedQuality(benchmark::State& state, const std::string& name) {
  Mesh mesh;
  if (read_shared_curved(state, name, mesh)) check_quality(state, mesh, name);
}

// The same on a plate of curved, valid elements throughout, made (and cached under
// /tmp/quadval_check_bench/) by `bench/compare_gmsh_check.py --plate tri:0.05 quad:0.08`:
// 51,205 quartic triangles, 10,030 quadratic quadrangles. Skipped until it exists.
void BM_CheckPlateQuality(benchmark::State& state, const std::string& name) {
  Mesh mesh;
  try {
    mesh = read_mesh("/tmp/quadval_check_bench/" + name + ".msh");
  } catch (const std::exception& e) {
    state.SkipWithError((std::string(e.what()) + " (made by bench/compare_gmsh_check.py --plate)").c_str());
    return;
  }
  check_quality(state, mesh, name);
}

// The product kernel alone (jacobian_coefficients: nodes -> Bézier coefficients of J and
// their error bounds) over the first block of a shared mesh, in chunks of 64 as `check`
// calls it; the nodes are gathered once, outside the timing.
void BM_JacobianProductKernel(benchmark::State& state, const std::string& name) {
  Mesh mesh;
  if (!read_shared_curved(state, name, mesh)) return;
  const ElementBlock& blk = mesh.blocks.front();
  const JacobianSpace& space = jacobian_space(*blk.type);
  const auto nn = static_cast<std::size_t>(blk.type->num_nodes);
  const auto s = static_cast<std::size_t>(space.basis().size());
  const bool planar = blk.type->dim == 2;
  std::vector<double> nodes;
  for (std::size_t e = 0; e < blk.size(); ++e)
    for (NodeIndex n : blk.element(e))
      for (std::size_t j = 0; j < 3; ++j) nodes.push_back(mesh.coords[3 * static_cast<std::size_t>(n) + j]);
  constexpr std::size_t kChunk = 64;
  std::vector<double> coeffs(kChunk * s), errors(kChunk);
  ProductScratch scratch;
  for (auto _ : state)
    for (std::size_t e = 0; e < blk.size(); e += kChunk) {
      jacobian_coefficients(space, nodes.data() + e * nn * 3, std::min(kChunk, blk.size() - e), planar,
                            coeffs.data(), errors.data(), scratch);
      benchmark::DoNotOptimize(coeffs.data());
    }
  state.counters["elements/s"] = benchmark::Counter(static_cast<double>(blk.size()),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}

const bool kSharedCurvedRegistered = [] {
  for (const char* name :
       {"hex_box_N20_amp0.35_seed777", "mixed_h0.6_o2", "quad_h0.4_o2", "tets_h0.8_o2",
        "tri_h0.4_o4", "warped_hexahedron_o2_N6_a0.25", "warped_prism_o2_N6_a0.25",
        "warped_pyramid_o1_N6_a0.1", "warped_pyramid_o2_N6_a0.15",
        "warped_tetrahedron_o3_N6_a0.25"})
    benchmark::RegisterBenchmark((std::string("BM_CheckSharedCurved/") + name).c_str(),
                                 [name](benchmark::State& s) { BM_CheckSharedCurved(s, name); })
        ->Arg(1)
        ->Arg(2)
        ->Unit(benchmark::kMicrosecond);
  for (const char* name : {"hex_box_N20_amp0.35_seed777", "mixed_h0.6_o2", "quad_h0.4_o2", "tets_h0.8_o2",
                           "tri_h0.4_o4", "warped_hexahedron_o2_N6_a0.25", "warped_prism_o2_N6_a0.25",
                           "warped_pyramid_o1_N6_a0.1", "warped_pyramid_o2_N6_a0.15",
                           "warped_tetrahedron_o3_N6_a0.25"})
    benchmark::RegisterBenchmark((std::string("BM_CheckSharedQuality/") + name).c_str(),
                                 [name](benchmark::State& s) { BM_CheckSharedQuality(s, name); })
        ->Arg(0)
        ->Arg(1)
        ->Unit(benchmark::kMicrosecond);
  for (const char* name : {"plate_tri_h0.05", "plate_quad_h0.08"})
    benchmark::RegisterBenchmark((std::string("BM_CheckPlateQuality/") + name).c_str(),
                                 [name](benchmark::State& s) { BM_CheckPlateQuality(s, name); })
        ->Arg(0)
        ->Arg(1)
        ->Unit(benchmark::kMillisecond);
  for (const char* name : {"quad_h0.4_o2", "tets_h0.8_o2", "tri_h0.4_o4", "warped_hexahedron_o2_N6_a0.25",
                           "warped_prism_o2_N6_a0.25", "warped_tetrahedron_o3_N6_a0.25"})
    benchmark::RegisterBenchmark((std::string("BM_JacobianProductKernel/") + name).c_str(),
                                 [name](benchmark::State& s) { BM_JacobianProductKernel(s, name); })
        ->Unit(benchmark::kMicrosecond);
  return true;
}();

}  // namespace
}  // namespace quadval
