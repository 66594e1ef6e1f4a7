// check_mesh: the batched, threaded analysis of a whole mesh (Paper III §4.4: samples and
// first Bézier coefficients for many elements at once; only the undecided few are
// subdivided). Fixed chunks of one block make the results independent of the threads.
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>

#include "analysis/jacobian_engine.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/linear_jacobian.hpp"
#include "analysis/outward_rounding.hpp"
#include "quadval/check_report.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr std::size_t kChunk = 256;
static_assert(kChunk <= kLinearChunk);

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Per-thread accumulators, merged at the end (sums are order-independent integers; the
// times are only reported).
struct ThreadStats {
  std::vector<StageRow> stages;
  std::size_t exact = 0;
  std::map<int, std::array<std::size_t, 4>> counts;  // as CheckReport::counts
  void add(int stage, Validity v, double seconds) {
    const auto row = static_cast<std::size_t>(stage < 0 ? 0 : stage);
    if (stages.size() <= row) stages.resize(row + 1);
    if (v == Validity::valid) ++stages[row].valid;
    if (v == Validity::invalid) ++stages[row].invalid;
    stages[row].seconds += seconds;
  }
};

std::string stage_name(std::size_t i) {
  if (i == 0) return "samples";
  if (i == 1) return "Bezier";
  return std::to_string(i - 1) + (i == 2 ? " subdivision" : " subdivisions");
}

}  // namespace

CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options, const std::string& file) {
  const double t0 = now_seconds();
  CheckReport report;
  report.file = file;
  report.measure = options.measure;
  report.dimension = mesh.dimension();
  for (double c : mesh.coords)
    if (!std::isfinite(c)) throw InputError::in_file(file, "a node coordinate is not finite");

  // Planar 2D: every node of every 2D block has the same z.
  if (report.dimension == 2) {
    report.planar = true;
    double z0 = NAN;
    for (const ElementBlock& b : mesh.blocks) {
      if (b.type->dim != 2) continue;
      for (NodeIndex n : b.nodes) {
        const double z = mesh.coords[3 * static_cast<std::size_t>(n) + 2];
        if (std::isnan(z0)) z0 = z;
        if (z != z0) report.planar = false;
      }
    }
  }

  BoundsOptions bo;
  bo.goal = options.measure == CheckMeasure::validity ? BoundsGoal::validity : BoundsGoal::measure;
  bo.rel_tol = options.rel_tol;
  bo.abs_tol = options.abs_tol;
  bo.max_subdivisions = options.max_subdivisions;

  // First-order fast path (linear_jacobian.hpp): validity only; measuring refines further.
  const bool fast_path = options.measure == CheckMeasure::validity;

  // Work list: (block, first element) chunks of the analysed dimension.
  struct Chunk {
    std::size_t block, first, count, out;
  };
  std::vector<Chunk> chunks;
  std::size_t total = 0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& blk = mesh.blocks[b];
    if (blk.type->dim != report.dimension) continue;
    for (std::size_t e = 0; e < blk.size(); e += kChunk)
      chunks.push_back({b, e, std::min(kChunk, blk.size() - e), total + e});
    total += blk.size();
  }
  report.elements.resize(total);

  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  report.threads = threads;
  std::vector<ThreadStats> stats(static_cast<std::size_t>(threads));
  std::atomic<std::size_t> done{0};
  std::exception_ptr failure;
  // Build the shared spaces up front (once per type, outside the parallel region), except
  // for fast-path types: their space is built (thread-safely) only if an element needs it.
  for (const ElementBlock& blk : mesh.blocks)
    if (blk.type->dim == report.dimension && jacobian_supported(*blk.type) &&
        !(fast_path && linear_kind(*blk.type, report.planar) != LinearKind::none))
      (void)jacobian_space(*blk.type);

#pragma omp parallel num_threads(threads)
  {
    BoundsWorkspace workspace;
    auto& ws = workspace.impl();
    ThreadStats& st = stats[static_cast<std::size_t>(omp_get_thread_num())];
    std::vector<double> nodes, samples, errors, transposed, coeffs_t, coeffs, scratch, soa;
    std::vector<JacobianBounds> fast_bounds;
    bool decided[kLinearChunk];
#pragma omp for schedule(dynamic, 1)
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      try {
        const Chunk& ch = chunks[c];
        const ElementBlock& blk = mesh.blocks[ch.block];
        const ElementType& type = *blk.type;
        for (std::size_t i = 0; i < ch.count; ++i) {
          ElementCheck& ec = report.elements[ch.out + i];
          ec.tag = blk.tags[ch.first + i];
          ec.type = &type;
        }
        const LinearKind fast = fast_path ? linear_kind(type, report.planar) : LinearKind::none;
        if (jacobian_supported(type)) {
          const auto nn = static_cast<std::size_t>(type.num_nodes);
          // What every analysed element gets once its bounds are known.
          const auto finish = [&](ElementCheck& ec, const double* xe, double seconds) {
            ec.analysed = true;
            const JacobianBounds& b = ec.bounds;
            if (b.jmax_upper > 0) ec.ratio_lower = next_down(b.jmin_lower / b.jmax_upper);
            if (b.javg > 0) ec.jmin_over_javg = b.jmin_lower / b.javg;
            if (options.measure == CheckMeasure::distortion)
              ec.distortion = distortion_from(jacobian_space(type), xe, report.planar, b, ws);
            if (b.exact) ++st.exact;
            st.add(b.stage, b.validity, seconds);
          };
          if (fast != LinearKind::none) {
            // First-order fast path (linear_jacobian.hpp): the coefficients straight from
            // the vertices; the few it leaves open go one by one to the general path.
            const double ts = now_seconds();
            const auto nv = static_cast<std::size_t>(linear_num_vertices(fast));
            soa.resize(nv * 3 * kLinearChunk);
            for (std::size_t i = 0; i < ch.count; ++i) {
              const auto conn = blk.element(ch.first + i);
              for (std::size_t k = 0; k < nv; ++k)
                for (std::size_t j = 0; j < 3; ++j)
                  soa[(k * 3 + j) * kLinearChunk + i] = mesh.coords[3 * static_cast<std::size_t>(conn[k]) + j];
            }
            fast_bounds.resize(ch.count);
            linear_validity_chunk(fast, soa.data(), ch.count, fast_bounds.data(), decided);
            const double share = (now_seconds() - ts) / static_cast<double>(ch.count);
            nodes.resize(nn * 3);
            errors.resize(1);
            for (std::size_t i = 0; i < ch.count; ++i) {
              ElementCheck& ec = report.elements[ch.out + i];
              const auto conn = blk.element(ch.first + i);
              if (decided[i]) {
                ec.bounds = fast_bounds[i];
                finish(ec, nullptr, share);  // no distortion: fast_path is validity only
                continue;
              }
              const double te = now_seconds();
              const JacobianSpace& space = jacobian_space(type);
              samples.resize(static_cast<std::size_t>(space.num_samples()));
              for (std::size_t k = 0; k < nn; ++k)
                for (std::size_t j = 0; j < 3; ++j)
                  nodes[k * 3 + j] = mesh.coords[3 * static_cast<std::size_t>(conn[k]) + j];
              jacobian_samples(space, SampleMap::curved, nodes.data(), 1, report.planar,
                               samples.data(), errors.data(), ws.sample_scratch);
              ec.bounds = bounds_from_samples(space, samples.data(), errors[0], nodes.data(),
                                              report.planar, bo, ws);
              finish(ec, nodes.data(), share + (now_seconds() - te));
            }
          } else {
            const JacobianSpace& space = jacobian_space(type);
            const auto s = static_cast<std::size_t>(space.num_samples());
            nodes.resize(ch.count * nn * 3);
            for (std::size_t i = 0; i < ch.count; ++i) {
              const auto conn = blk.element(ch.first + i);
              for (std::size_t k = 0; k < nn; ++k)
                for (std::size_t j = 0; j < 3; ++j)
                  nodes[(i * nn + k) * 3 + j] = mesh.coords[3 * static_cast<std::size_t>(conn[k]) + j];
            }
            samples.resize(ch.count * s);
            errors.resize(ch.count);
            const double ts = now_seconds();
            jacobian_samples(space, SampleMap::curved, nodes.data(), ch.count, report.planar,
                             samples.data(), errors.data(), ws.sample_scratch);
            // First Bézier coefficients of the whole chunk: one matrix-matrix product.
            transposed.resize(ch.count * s);
            for (std::size_t i = 0; i < ch.count; ++i)
              for (std::size_t k = 0; k < s; ++k) transposed[k * ch.count + i] = samples[i * s + k];
            coeffs_t.resize(ch.count * s);
            scratch.resize(2 * ch.count * s);
            space.basis().to_bezier_batch(transposed.data(), ch.count, coeffs_t.data(), scratch.data());
            coeffs.resize(ch.count * s);
            for (std::size_t i = 0; i < ch.count; ++i)
              for (std::size_t k = 0; k < s; ++k) coeffs[i * s + k] = coeffs_t[k * ch.count + i];
            const double batch_share = (now_seconds() - ts) / static_cast<double>(ch.count);
            for (std::size_t i = 0; i < ch.count; ++i) {
              const double te = now_seconds();
              ElementCheck& ec = report.elements[ch.out + i];
              const double* xe = nodes.data() + i * nn * 3;
              ec.bounds = bounds_from_samples(space, samples.data() + i * s, errors[i], xe,
                                              report.planar, bo, ws, coeffs.data() + i * s);
              finish(ec, xe, batch_share + (now_seconds() - te));
            }
          }
        }
        // Counts per type, here rather than in a serial pass over all elements.
        std::array<std::size_t, 4> chunk_counts{};
        for (std::size_t i = 0; i < ch.count; ++i) {
          const ElementCheck& ec = report.elements[ch.out + i];
          chunk_counts[ec.analysed ? static_cast<std::size_t>(ec.bounds.validity) : 3] += 1;
        }
        auto& type_counts = st.counts[type.gmsh_id];
        for (std::size_t k = 0; k < 4; ++k) type_counts[k] += chunk_counts[k];
        const std::size_t d = done.fetch_add(ch.count) + ch.count;
        if (options.progress && omp_get_thread_num() == 0) options.progress(d, total);
      } catch (...) {
#pragma omp critical
        if (!failure) failure = std::current_exception();
      }
    }
  }
  if (failure) std::rethrow_exception(failure);

  for (const ThreadStats& st : stats) {
    report.exact_fallbacks += st.exact;
    for (const auto& [id, c] : st.counts)
      for (std::size_t k = 0; k < 4; ++k) report.counts[id][k] += c[k];
    if (report.stages.size() < st.stages.size()) report.stages.resize(st.stages.size());
    for (std::size_t i = 0; i < st.stages.size(); ++i) {
      report.stages[i].valid += st.stages[i].valid;
      report.stages[i].invalid += st.stages[i].invalid;
      report.stages[i].seconds += st.stages[i].seconds;
    }
  }
  if (report.stages.size() < 2) report.stages.resize(2);
  for (std::size_t i = 0; i < report.stages.size(); ++i) report.stages[i].name = stage_name(i);
  report.seconds = now_seconds() - t0;
  return report;
}

std::size_t CheckReport::count(Validity v) const {
  std::size_t n = 0;
  for (const auto& [id, c] : counts) n += c[static_cast<std::size_t>(v)];
  return n;
}

std::size_t CheckReport::skipped() const {
  std::size_t n = 0;
  for (const auto& [id, c] : counts) n += c[3];
  return n;
}

std::vector<std::size_t> CheckReport::worst(std::size_t n) const {
  std::vector<std::size_t> idx;
  const bool by_distortion = measure == CheckMeasure::distortion;
  const auto key = [&](std::size_t i) {
    const ElementCheck& e = elements[i];
    const double k = by_distortion ? e.distortion.lower : e.ratio_lower;
    return std::isnan(k) ? -INFINITY : k;
  };
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (elements[i].analysed) idx.push_back(i);
  const std::size_t m = std::min(n, idx.size());
  std::partial_sort(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(m), idx.end(),
                    [&](std::size_t a, std::size_t b) {
                      const double ka = key(a), kb = key(b);
                      return ka != kb ? ka < kb : elements[a].tag < elements[b].tag;
                    });
  idx.resize(m);
  return idx;
}

}  // namespace quadval
