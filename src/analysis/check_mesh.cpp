// check_mesh: the batched, threaded analysis of a whole mesh (Paper III §4.4: samples and
// first Bézier coefficients for many elements at once; only the undecided few are
// subdivided). Fixed chunks of one block make the results independent of the threads.
// Chunks are grouped in batches of kCheckBatch elements: one batch of results exists at a
// time, handed to the sink and folded into the summary before the next one starts, so the
// memory beyond the mesh does not grow with it.
#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <span>
#include <thread>
#include <type_traits>
#include <utility>

#include "analysis/jacobian_engine.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/bilinear_quad_quality.hpp"
#include "analysis/check_summary.hpp"
#include "analysis/linear_jacobian.hpp"
#include "analysis/linear_pyramid_mu.hpp"
#include "analysis/linear_pyramid_sj.hpp"
#include "analysis/trilinear_hex_sj.hpp"
#include "analysis/straight_sided.hpp"
#include "analysis/mu_constant.hpp"
#include "analysis/mu_space.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "analysis/stage_clock.hpp"
#include "analysis/straight_simplex_mu.hpp"
#include "analysis/worker_threads.hpp"
#include "quadval/check_report.hpp"
#include "quadval/error.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

// Elements per chunk, the unit of work a thread claims: whole SIMD chunks for the
// first-order fast path; fewer for the others, whose per-thread scratch (nodes and J
// coefficients of a chunk) is first touched, page by page, within the timed analysis
// (tri_h0.4_o4: 0.34 -> 0.29 ms with 64 instead of 256). 16 instead of 64 (CLI, 2 threads,
// medians of 11 alternating runs): sj of warped_prism_o2 -5%, but its mu +7% and
// tets_h0.8_o2's mu and sj +8-9%, the others within 4%; not kept.
constexpr std::size_t kFastChunk = kLinearChunk;
constexpr std::size_t kChunk = 64;
constexpr std::size_t kRow = kChunk + 8;  // straight-sided chunks' vertex rows, a cache line apart
static_assert(kChunk <= kFastChunk);
static_assert(kCheckBatch % kFastChunk == 0 && kCheckBatch % kChunk == 0);

struct CoordinateRange {
  bool finite = true;
  std::array<double, 3> lo{}, hi{};
};

// Finiteness and per-axis range of x, y, z triples in one vectorised pass (x * 0 is NaN
// exactly when x is infinite or NaN; min and max then only matter when all are finite).
// The flat array is read 3 registers (kNativeLanes triples) at a time into 3 running
// minima, maxima and probes, position p of a block holding axis p % 3: contiguous vector
// loads, not a gather per axis (which took 12-22 us of a first check of tri_h0.4_o4's
// 8,291 nodes). Named register accumulators: the same pass over arrays of 8-double
// vectors kept them in memory on AVX2 (tri_h0.4_o4: 100 us; now 6 us).
CoordinateRange coordinate_range(const std::vector<double>& coords) {
  CoordinateRange r;
  const std::size_t size = coords.size() / 3 * 3;
  if (size == 0) return r;
  const double* c = coords.data();
  constexpr std::size_t kL = kNativeLanes;
  constexpr std::size_t kBlock = 3 * kL;
  using V = Lanes<kL>;
  double first[kBlock];  // the first triple at every position
  for (std::size_t p = 0; p < kBlock; ++p) first[p] = c[p % 3];
  V lo0 = load_lanes<kL>(first), lo1 = load_lanes<kL>(first + kL), lo2 = load_lanes<kL>(first + 2 * kL);
  V hi0 = lo0, hi1 = lo1, hi2 = lo2, probe0{}, probe1{}, probe2{};
  std::size_t i = 0;
  for (; i + kBlock <= size; i += kBlock) {
    const V a = load_lanes<kL>(c + i), b = load_lanes<kL>(c + i + kL), d = load_lanes<kL>(c + i + 2 * kL);
    lo0 = vmin(lo0, a);
    hi0 = vmax(hi0, a);
    probe0 += a * 0;
    lo1 = vmin(lo1, b);
    hi1 = vmax(hi1, b);
    probe1 += b * 0;
    lo2 = vmin(lo2, d);
    hi2 = vmax(hi2, d);
    probe2 += d * 0;
  }
  double flat_lo[kBlock], flat_hi[kBlock], flat_probe[kBlock];
  const auto spill = [](double* out, const V& x, const V& y, const V& z) {
    std::memcpy(out, &x, sizeof x);
    std::memcpy(out + kL, &y, sizeof y);
    std::memcpy(out + 2 * kL, &z, sizeof z);
  };
  spill(flat_lo, lo0, lo1, lo2);
  spill(flat_hi, hi0, hi1, hi2);
  spill(flat_probe, probe0, probe1, probe2);
  double probe = 0;
  r.lo = {c[0], c[1], c[2]};
  r.hi = r.lo;
  for (std::size_t p = 0; p < kBlock; ++p) {
    r.lo[p % 3] = std::min(r.lo[p % 3], flat_lo[p]);
    r.hi[p % 3] = std::max(r.hi[p % 3], flat_hi[p]);
    probe += flat_probe[p];
  }
  for (; i < size; ++i) {  // the last triples, one coordinate at a time
    r.lo[i % 3] = std::min(r.lo[i % 3], c[i]);
    r.hi[i % 3] = std::max(r.hi[i % 3], c[i]);
    probe += c[i] * 0;
  }
  r.finite = probe == 0;
  return r;
}

// Storage for n records, left unconstructed: each record is constructed whole by the
// thread that analyses its element, so the calling thread does not first touch (and
// page-fault) all of it alone: that took 0.45 ms of a 3 ms check of 9,647 elements.
template <class T>
class Slots {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  struct Free {
    void operator()(T* p) const noexcept { ::operator delete(p, std::align_val_t(alignof(T))); }
  };

 public:
  Slots() = default;
  explicit Slots(std::size_t n)
      : data_(n == 0 ? nullptr : static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(alignof(T))))),
        size_(n) {}
  bool empty() const noexcept { return size_ == 0; }
  std::span<T> all() const noexcept { return {data_.get(), size_}; }
  /// The first n records, once constructed.
  std::span<const T> first(std::size_t n) const noexcept { return {data_.get(), n}; }

 private:
  std::unique_ptr<T, Free> data_;
  std::size_t size_ = 0;
};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Per-thread accumulators, merged at the end (sums are order-independent integers; the
// times, in stage_ticks, are only reported).
struct ThreadStats {
  CheckSummary summary;  // histograms and worst lists of this thread's elements
  std::vector<StageRow> stages;
  std::size_t exact = 0;
  std::map<int, std::array<std::size_t, 4>> counts;  // as CheckReport::counts
  QualityCounts mu, sj;
  double busy = 0;  // seconds spent analysing chunks (not waiting, not in the sink)
  void add(int stage, Validity v, double ticks) {
    const auto row = static_cast<std::size_t>(stage < 0 ? 0 : stage);
    if (stages.size() <= row) stages.resize(row + 1);
    if (v == Validity::valid) ++stages[row].valid;
    if (v == Validity::invalid) ++stages[row].invalid;
    stages[row].seconds += ticks;  // converted to seconds when merged
  }
};

std::string stage_name(std::size_t i) {
  if (i == 0) return "samples";
  if (i == 1) return "Bezier";
  return std::to_string(i - 1) + (i == 2 ? " subdivision" : " subdivisions");
}

}  // namespace

CheckSummary check_mesh_streamed(const Mesh& mesh, const CheckOptions& options, const std::string& file,
                                 const CheckSink& sink) {
  const double t0 = now_seconds();
  const StageClockRate tick_rate;
  double sink_seconds = 0;
  CheckSummary report = empty_summary(file, options.measure, options.worst);
  report.dimension = mesh.dimension();
  // One pass over the coordinates: finite, and their range per axis.
  const CoordinateRange range = coordinate_range(mesh.coords);
  if (!range.finite) throw InputError::in_file(file, "a node coordinate is not finite");
  // J multiplies three lengths, and mu and the scaled Jacobian square it (N = J^2, D_k =
  // prod |v|^2): beyond this span they would overflow double precision, and no bound
  // printed could be a true one.
  constexpr double kMaxSpan = 1e40;
  for (std::size_t axis = 0; axis < 3 && !mesh.coords.empty(); ++axis)
    if (range.hi[axis] - range.lo[axis] > kMaxSpan)
      throw InputError::in_file(file, fmt::format("the node coordinates span {:g} along an axis, beyond {:g}: J and "
                                                  "the squared quantities of mu and the scaled Jacobian (six lengths "
                                                  "multiplied) would overflow double precision; rescale the mesh",
                                                  range.hi[axis] - range.lo[axis], kMaxSpan));

  // Planar 2D: every node of every 2D block has the same z (at once when all nodes do).
  if (report.dimension == 2) {
    report.planar = true;
    if (range.lo[2] != range.hi[2]) {
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
  }

  BoundsOptions bo;
  bo.goal = measures_jacobian_range(options.measure) ? BoundsGoal::measure : BoundsGoal::validity;
  bo.rel_tol = options.rel_tol;
  bo.abs_tol = options.abs_tol;
  bo.max_subdivisions = options.max_subdivisions;

  const bool want_mu = measures_mu(options.measure);
  const bool want_sj = measures_scaled_jacobian(options.measure);
  const bool want_distortion = measures_distortion(options.measure);
  QualityOptions qo;
  qo.abs_tol = options.quality_abs_tol;
  qo.max_subdivisions = options.max_subdivisions;

  // First-order fast path (linear_jacobian.hpp) for validity, and for mu and the scaled
  // Jacobian, which need only the sign of J (their closed forms of straight-sided elements
  // take the margins it computes); measuring J's range refines further.
  const bool fast_path = options.measure == CheckMeasure::validity || options.measure == CheckMeasure::mu ||
                         options.measure == CheckMeasure::scaled_jacobian;

  // Work list: (block, first element) chunks of the analysed dimension.
  struct Chunk {
    std::size_t block, first, count, out;
  };
  std::vector<Chunk> chunks;
  std::size_t total = 0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& blk = mesh.blocks[b];
    if (blk.type->dim != report.dimension) continue;
    const std::size_t size =
        fast_path && linear_kind(*blk.type, report.planar) != LinearKind::none ? kFastChunk : kChunk;
    for (std::size_t e = 0; e < blk.size(); e += size)
      chunks.push_back({b, e, std::min(size, blk.size() - e), total + e});
    total += blk.size();
  }
  report.elements = total;
  // Batches: runs of whole chunks, at most kCheckBatch elements each (chunks never span
  // blocks, so a batch may hold fewer). Batch b holds chunks [batches[b], batches[b + 1]).
  std::vector<std::size_t> batches;
  for (std::size_t c = 0; c < chunks.size(); ++c)
    if (batches.empty() || chunks[c].out + chunks[c].count - chunks[batches.back()].out > kCheckBatch)
      batches.push_back(c);
  const std::size_t num_batches = batches.size();
  batches.push_back(chunks.size());
  std::vector<std::size_t> batch_of(chunks.size()), batch_first(num_batches), batch_size(num_batches);
  for (std::size_t b = 0; b < num_batches; ++b) {
    for (std::size_t c = batches[b]; c < batches[b + 1]; ++c) batch_of[c] = b;
    batch_first[b] = chunks[batches[b]].out;
    batch_size[b] = chunks[batches[b + 1] - 1].out + chunks[batches[b + 1] - 1].count - batch_first[b];
  }
  // Results of batch b live in buffer b % kInFlight until the calling thread has handed
  // them out (flushed): threads go on with later batches meanwhile, with no barrier.
  // Batches are needed only by a sink, and by the sums of mu and sj (taken in element
  // order); otherwise each thread keeps its chunk's results in a buffer of its own, reused
  // chunk after chunk: fresh memory costs a page fault per 4 KiB on first touch (about
  // 2 us here), and the records of a 10,000-element mesh fill 230 pages.
  const bool batched = static_cast<bool>(sink) || want_mu || want_sj;
  constexpr std::size_t kInFlight = 4;
  struct Buffer {
    Slots<ElementCheck> elements;
    Slots<DistortionBounds> distortion;  // per-element measures only when measured
    Slots<QualityBounds> mu, sj;
  };
  const auto make_buffer = [&](std::size_t capacity) {
    Buffer buf;
    buf.elements = Slots<ElementCheck>(capacity);
    buf.distortion = Slots<DistortionBounds>(measures_distortion(options.measure) ? capacity : 0);
    buf.mu = Slots<QualityBounds>(want_mu ? capacity : 0);
    buf.sj = Slots<QualityBounds>(want_sj ? capacity : 0);
    return buf;
  };
  std::vector<Buffer> buffers;
  for (std::size_t b = 0; batched && b < std::min(kInFlight, num_batches); ++b)
    buffers.push_back(make_buffer(std::min(total, kCheckBatch)));

  // Build the shared spaces up front (once per type, outside the parallel region), except
  // for fast-path types: their space is built (thread-safely) only if an element needs it.
  // Meanwhile estimate the work: for validity about 1 ns per node x J coefficient of an
  // element (the derivative maps and products), about 64 ns per fast-path element;
  // measuring (J range, mu, scaled Jacobian) refines much further: some 50 times that.
  const double weight = bo.goal == BoundsGoal::measure || want_mu || want_sj ? 50 : 1;
  double work = 0;
  std::vector<double> element_work(mesh.blocks.size(), 0.0);  // per block, per element
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& blk = mesh.blocks[b];
    if (blk.type->dim != report.dimension || !jacobian_supported(*blk.type)) continue;
    if (fast_path && linear_kind(*blk.type, report.planar) != LinearKind::none)
      element_work[b] = 64;
    else
      element_work[b] = static_cast<double>(blk.type->num_nodes) * jacobian_space(*blk.type).basis().size();
    work += static_cast<double>(blk.size()) * element_work[b];
  }
  work *= weight;
  // The order in which chunks are claimed: batch by batch (the buffers' hand-out relies on
  // it), and within a batch the costliest type's chunks first, so that they are not left
  // for last while the other threads go idle (mixed_h0.6_o2's sj on 2 threads: its
  // quadratic pyramids came last, one chunk of 16.6 ms while the other thread waited).
  std::vector<std::size_t> claim_order(chunks.size());
  std::iota(claim_order.begin(), claim_order.end(), std::size_t{0});
  for (std::size_t b = 0; b < num_batches; ++b)
    std::stable_sort(claim_order.begin() + static_cast<std::ptrdiff_t>(batches[b]),
                     claim_order.begin() + static_cast<std::ptrdiff_t>(batches[b + 1]),
                     [&](std::size_t x, std::size_t y) { return element_work[chunks[x].block] > element_work[chunks[y].block]; });
  // Validity of curved blocks: the straight-sided elements' margins (straight_sided.hpp).
  std::vector<std::unique_ptr<const StraightSidedMargin>> straight_of(mesh.blocks.size());
  for (std::size_t b = 0; b < mesh.blocks.size() && fast_path; ++b) {
    const ElementType& type = *mesh.blocks[b].type;
    if (type.dim != report.dimension || !jacobian_supported(type) || linear_kind(type, report.planar) != LinearKind::none)
      continue;
    auto straight = std::make_unique<const StraightSidedMargin>(type, jacobian_space(type), report.planar);
    if (straight->kind() != LinearKind::none) straight_of[b] = std::move(straight);
  }
  // Threads at most: each extra one costs its start (about 0.1 ms, worker_threads.hpp) and
  // the closing join, and more when the cores are busy (results do not depend on it), so
  // one thread per kWorkPerThread units (about 1 ms), and never more than chunks; they
  // start only once the work shows it is worth them (below).
  constexpr double kWorkPerThread = 1e6;
  const int requested = options.threads > 0 ? options.threads : omp_get_max_threads();
  const auto useful = static_cast<std::size_t>(std::max(1.0, std::ceil(work / kWorkPerThread)));
  const int threads = static_cast<int>(
      std::max<std::size_t>(1, std::min({static_cast<std::size_t>(requested), chunks.size(), useful})));
  std::vector<ThreadStats> stats(static_cast<std::size_t>(threads));
  for (ThreadStats& st : stats) st.summary = empty_summary(file, options.measure, options.worst);
  std::atomic<std::size_t> done{0};
  std::exception_ptr failure;
  std::atomic<bool> failed{false};
  std::atomic<std::size_t> next_chunk{0};  // chunks are claimed in claim_order
  std::atomic<std::size_t> flushed{0};     // batches handed out so far
  const auto remaining = std::make_unique<std::atomic<std::size_t>[]>(num_batches);  // chunks left
  for (std::size_t b = 0; b < num_batches; ++b) remaining[b] = batches[b + 1] - batches[b];
  std::mutex failure_mutex;
  const auto fail = [&](std::exception_ptr e) {
    const std::lock_guard<std::mutex> lock(failure_mutex);
    if (!failure) failure = e;
    failed = true;
  };
  // On the calling thread (thread 0): hands out every finished batch, in order.
  const auto flush_ready = [&] {
    for (std::size_t b = flushed.load(std::memory_order_relaxed);
         b < num_batches && !failed && remaining[b].load(std::memory_order_acquire) == 0; ++b) {
      const Buffer& buf = buffers[b % buffers.size()];
      CheckBatch out;
      out.first = batch_first[b];
      out.elements = buf.elements.first(batch_size[b]);
      if (!buf.distortion.empty()) out.distortion = buf.distortion.first(batch_size[b]);
      if (!buf.mu.empty()) out.mu = buf.mu.first(batch_size[b]);
      if (!buf.sj.empty()) out.sj = buf.sj.first(batch_size[b]);
      add_sums(report, out);  // in element order
      if (sink) {
        const double ts = now_seconds();
        try {
          sink(out);
        } catch (...) {
          fail(std::current_exception());
        }
        sink_seconds += now_seconds() - ts;
      }
      flushed.store(b + 1, std::memory_order_release);  // its buffer may now be reused
    }
  };

  // A thread waiting on another (a batch's last chunk, a buffer to be handed out) sleeps in
  // short steps rather than yielding in a loop: on an element that takes seconds the
  // yields cost a core in system time (mixed_h0.6_o2, scaled Jacobian, 2 threads: 0.10 s
  // of system time in a 0.20 s run). A step delays a flush by at most 20 microseconds.
  const auto pause = [] { std::this_thread::sleep_for(std::chrono::microseconds(20)); };

  // The other threads start at once where the estimate is large, else only once the
  // calling thread's progress shows the work worth them (run_on_threads_on_demand): when
  // the rest, at its pace so far, would take it alone more than kMoreThreadsAbove, judged
  // from kJudgeAfter of work on, the pace measured from half that on (the first elements
  // pay for set-ups and cold code). The estimate cannot tell a mesh of straight elements
  // from one of inverted curved ones: mu of the shared curved meshes, estimate and one
  // thread's time: tri_h0.4_o4 2.1e7 and 0.8 ms, hex_box_N20 2.6e7 and 35 ms,
  // warped_prism_o2 3.5e7 and 6.4 ms. On the small ones two threads from the start took
  // longer than one (CLI, medians of 21 alternating runs): quad_h0.4_o2 sj 1.02 vs 0.84 ms,
  // mu 0.64 vs 0.53; tri_h0.4_o4 sj 1.03 vs 0.90, mu 0.77 vs 0.47; warped_pyramid_o1 sj
  // 0.72 vs 0.62 ms. On demand everywhere cost the medium ones 0.2-0.4 ms (tets_h0.8_o2 mu
  // 4.4 -> 4.8 ms), hence the immediate start above kStartAtOnce.
  constexpr double kStartAtOnce = 3e7, kMoreThreadsAbove = 2e-3, kJudgeAfter = 0.4e-3;
  const double setup_seconds = now_seconds() - t0;
  const int threads_used = run_on_threads_on_demand(threads, [&](int thread, const std::function<void()>& more) {
    const bool master = thread == 0;
    // The calling thread's count of finished elements while it is alone, and the point
    // from which its pace is measured.
    std::size_t alone_done = 0, paced_from = 0;
    bool asked = !master || threads == 1;
    if (!asked && (work >= kStartAtOnce || !options.threads_on_demand)) {
      more();
      asked = true;
    }
    double pace_from = 0;
    const double alone_from = now_seconds();
    const auto maybe_more = [&] {
      if (asked) return;
      const double now = now_seconds();
      if (pace_from == 0) {
        if (now - alone_from >= 0.5 * kJudgeAfter) {
          pace_from = now;
          paced_from = alone_done;
        }
        return;
      }
      if (now - alone_from < kJudgeAfter || alone_done <= paced_from) return;
      const double left = static_cast<double>(total - std::min(total, alone_done));
      if ((now - pace_from) / static_cast<double>(alone_done - paced_from) * left > kMoreThreadsAbove) {
        more();
        asked = true;
      }
    };
    BoundsWorkspace workspace;
    auto& ws = workspace.impl();
    ThreadStats& st = stats[static_cast<std::size_t>(thread)];
    std::vector<double> nodes, errors, coeffs, soa, margins, betas, element_nodes;
    std::vector<std::size_t> rest;
    std::vector<JacobianBounds> fast_bounds;
    bool decided[kLinearChunk];
    std::vector<QualityBounds> lane_mu, lane_sj, lane_planar_mu, lane_straight_sj;
    std::vector<double> validity_ticks;
    std::vector<char> lane_sj_done, lane_mu_planar_done;
    unsigned lane_mu_done[kLinearChunk / kNativeLanes], lane_straight_sj_done[kLinearChunk / kNativeLanes];
    const Buffer own = batched ? Buffer{} : make_buffer(kFastChunk);  // the largest chunk
    for (;;) {
      const std::size_t claimed = next_chunk.fetch_add(1, std::memory_order_relaxed);
      if (claimed >= chunks.size() || failed) break;
      const std::size_t c = claim_order[claimed];
      const std::size_t batch = batch_of[c];
      // Wait for this batch's buffer: the batch kInFlight before it must be handed out.
      // Its chunks were all claimed before this one, so this always ends.
      while (batched && batch >= flushed.load(std::memory_order_acquire) + buffers.size() && !failed) {
        if (master) flush_ready();
        else pause();
      }
      if (failed) break;
      const Buffer& buf = batched ? buffers[batch % buffers.size()] : own;
      // Where this chunk's results start: in its batch's buffer, or at the start of `own`.
      const std::size_t first = batched ? batch_first[batch] : chunks[c].out;
      const std::span<ElementCheck> elements = buf.elements.all();
      const std::span<DistortionBounds> distortion = buf.distortion.all();
      const std::span<QualityBounds> mu = buf.mu.all();
      const std::span<QualityBounds> sj = buf.sj.all();
      const double busy_from = now_seconds();
      {
        try {
          Chunk ch = chunks[c];
          ch.out -= first;  // index into the results' buffer
          const ElementBlock& blk = mesh.blocks[ch.block];
          const ElementType& type = *blk.type;
          // Fresh records (the results' slots are reused from batch to batch).
          for (std::size_t i = 0; i < ch.count; ++i) {
            ElementCheck& ec = *std::construct_at(&elements[ch.out + i]);
            ec.tag = blk.tags[ch.first + i];
            ec.type = &type;
            if (!distortion.empty()) distortion[ch.out + i] = DistortionBounds{NAN, NAN};
            if (!mu.empty()) mu[ch.out + i] = kNotComputed;
            if (!sj.empty()) sj[ch.out + i] = kNotComputed;
          }
          const LinearKind fast = fast_path ? linear_kind(type, report.planar) : LinearKind::none;
          if (!jacobian_supported(type))  // skipped elements are skipped for mu and sj too
            for (QualityCounts* qc : {want_mu ? &st.mu : nullptr, want_sj ? &st.sj : nullptr})
              if (qc) {
                qc->skipped += ch.count;
                qc->skipped_types[type.gmsh_id] += ch.count;
              }
          if (jacobian_supported(type)) {
            const auto nn = static_cast<std::size_t>(type.num_nodes);
            // mu or the scaled Jacobian of one element, or a skip said so.
            const auto quality = [&](bool supported, QualityBounds& out, QualityCounts& qc, const double* xe,
                                     const KnownMargin* known, auto bounds_of) {
              if (!supported) {
                ++qc.skipped;
                ++qc.skipped_types[type.gmsh_id];
                return;
              }
              out = bounds_of(type, std::span<const double>(xe, nn * 3), qo, report.planar, known);
              ++qc.computed;
              if (!out.tolerance_met) ++qc.tolerance_not_met;
              maybe_more();
            };
            // mu and the scaled Jacobian of an element whose validity is known (mu given
            // when the chunk's lanes computed it).
            const auto qualities = [&](std::size_t index, const double* xe, Validity v, const KnownMargin* known,
                                       const QualityBounds* mu_given = nullptr,
                                       const QualityBounds* sj_given = nullptr) {
              if (want_mu && mu_given) {
                mu[index] = *mu_given;
                ++st.mu.computed;
                if (!mu_given->tolerance_met) ++st.mu.tolerance_not_met;
              } else if (want_mu)
                quality(mu_supported(type), mu[index], st.mu, xe, known,
                        [v](const ElementType& t, std::span<const double> x, const QualityOptions& q, bool planar,
                            const KnownMargin* k) { return mu_bounds_given(t, x, q, planar, v, k); });
              if (want_sj && sj_given) {
                sj[index] = *sj_given;
                ++st.sj.computed;
                if (!sj_given->tolerance_met) ++st.sj.tolerance_not_met;
              } else if (want_sj)
                quality(scaled_jacobian_supported(type), sj[index], st.sj, xe, known,
                        [v](const ElementType& t, std::span<const double> x, const QualityOptions& q, bool planar,
                            const KnownMargin* k) { return scaled_jacobian_bounds_given(t, x, q, planar, v, k); });
            };
            // What every analysed element gets once its bounds are known.
            // known: the element's straight-sided margin when its chunk computed it.
            const auto finish = [&](std::size_t index, const double* xe, double ticks,
                                    const KnownMargin* known = nullptr, const QualityBounds* mu_given = nullptr,
                                    const QualityBounds* sj_given = nullptr) {
              ElementCheck& ec = elements[index];
              ec.analysed = true;
              const JacobianBounds& b = ec.bounds;
              if (want_distortion)
                distortion[index] = distortion_from(jacobian_space(type), xe, report.planar, b, ws, bo);
              qualities(index, xe, b.validity, known, mu_given, sj_given);
              if (b.exact) ++st.exact;
              st.add(b.stage, b.validity, ticks);
              ++alone_done;
            };
            // Elements i0 .. i0 + kNativeLanes - 1 of a first-order chunk, one per lane: their
            // first `values` vertex coordinates from `soa` (vertex v / 3, axis v % 3) into x; bit l
            // of the result set where lane l's element is proven valid (spare lanes: a copy).
            const auto vertex_lanes = [&](std::size_t i0, std::size_t count, std::size_t values,
                                          Lanes<kNativeLanes>* x) {
              unsigned valid = 0;
              for (std::size_t l = 0; l < static_cast<std::size_t>(kNativeLanes); ++l) {
                const std::size_t i = i0 + l < count ? i0 + l : i0;
                for (std::size_t v = 0; v < values; ++v) x[v][l] = soa[v * kLinearRow + i];
                if (i0 + l < count && decided[i] && fast_bounds[i].validity == Validity::valid) valid |= 1u << l;
              }
              return valid;
            };
            // mu of a first-order chunk's valid pyramids with a parallelogram base (W
            // constant; linear_pyramid_mu.hpp) and the scaled Jacobian's root bound of all of
            // its valid pyramids (linear_pyramid_sj.hpp), W = kNativeLanes at a time, into
            // lane_mu and lane_straight_sj as straight_lanes_of below.
            const auto pyramid_lanes_of = [&](const ElementType& t, std::size_t count) {
              lane_mu.resize(kLinearChunk);
              lane_straight_sj.resize(kLinearChunk);
              const bool mu_wanted = want_mu && mu_supported(t);
              const bool sj_wanted = want_sj && scaled_jacobian_supported(t) && scaled_jacobian_straight_path_enabled();
              constexpr std::size_t kW = kNativeLanes;
              for (std::size_t i0 = 0; i0 < count; i0 += kW) {
                Lanes<kW> x[15];
                const unsigned valid = vertex_lanes(i0, count, 15, x);
                lane_mu_done[i0 / kW] = valid == 0 || !mu_wanted
                                            ? 0u
                                            : valid & linear_pyramid_mu_lanes(t, x, qo.abs_tol, lane_mu.data() + i0);
                lane_straight_sj_done[i0 / kW] =
                    valid == 0 || !sj_wanted ? 0u
                                             : valid & linear_pyramid_sj_lanes(scaled_jacobian_space(t), x, qo.abs_tol,
                                                                              lane_straight_sj.data() + i0);
              }
            };
            // The scaled Jacobian of a first-order chunk's valid hexahedra, W = kNativeLanes at a
            // time (trilinear_hex_sj.hpp), into lane_straight_sj as straight_lanes_of below;
            // their mu goes element by element.
            const auto hexahedron_lanes_of = [&](const ElementType& t, std::size_t count) {
              lane_straight_sj.resize(kLinearChunk);
              constexpr std::size_t kW = kNativeLanes;
              const bool wanted = scaled_jacobian_supported(t) && scaled_jacobian_straight_path_enabled();
              for (std::size_t i0 = 0; i0 < count; i0 += kW) {
                Lanes<kW> x[24];
                const unsigned valid = vertex_lanes(i0, count, 24, x);
                lane_straight_sj_done[i0 / kW] =
                    valid == 0 || !wanted ? 0u
                                          : valid & trilinear_hex_sj_lanes(x, qo.abs_tol, lane_straight_sj.data() + i0);
                lane_mu_done[i0 / kW] = 0;
              }
            };
            // mu and the scaled Jacobian of a chunk's valid straight-sided tetrahedra, planar
            // triangles and planar bilinear quadrangles (decided by linear_validity_chunk,
            // vertices in `soa` by vertex and axis, rows of `row`, z not read in 2D; betas
            // and js: the straight-sided margins of the columns, 3 per element, and of J, or
            // none for first-order ones), W = kNativeLanes at a time (straight_simplex_mu.hpp,
            // straight_simplex_sj_lanes, bilinear_quad_quality.hpp): bit i % W of
            // lane_mu_done[i / W] set where lane_mu[i] holds element i's mu as mu_bounds_given
            // would compute it, likewise lane_straight_sj_done and lane_straight_sj for the
            // scaled Jacobian.
            const auto straight_lanes_of = [&](const ElementType& t, std::size_t row, const double* betas,
                                               const double* js, std::size_t count) {
              const bool tet = t.family == ElementFamily::tetrahedron;
              const bool quad = t.family == ElementFamily::quadrangle;
              if (t.family == ElementFamily::pyramid) {  // order 1 only (straight_lanes_for)
                pyramid_lanes_of(t, count);
                return;
              }
              if (t.family == ElementFamily::hexahedron) {  // likewise
                hexahedron_lanes_of(t, count);
                return;
              }
              const bool lane_mu_wanted = want_mu && mu_supported(t) && (!quad || mu_constant_path_enabled());
              const bool lane_sj_wanted =
                  want_sj && scaled_jacobian_supported(t) && (!quad || scaled_jacobian_straight_path_enabled());
              const std::size_t edge_values = tet ? 9 : 6;  // 3 or 2 edges, x y z each
              lane_mu.resize(kLinearChunk);
              lane_straight_sj.resize(kLinearChunk);
              constexpr std::size_t kW = kNativeLanes;
              for (std::size_t i0 = 0; i0 < count; i0 += kW) {
                Lanes<kW> edges[9] = {}, margin[3] = {}, j_margin{};
                unsigned valid = 0;
                for (std::size_t l = 0; l < kW; ++l) {
                  const std::size_t i = i0 + l < count ? i0 + l : i0;  // spare lanes: a copy
                  if (quad) {
                    for (std::size_t v = 0; v < 8; ++v)  // x, y of vertex v / 2
                      edges[v][l] = soa[(3 * (v / 2) + v % 2) * row + i];
                  } else {
                    for (std::size_t v = 0; v < edge_values; ++v)  // vertex v / 3 + 1 minus vertex 0, axis v % 3
                      if (tet || v % 3 != 2)  // a planar triangle's z edges: x - x = +0, as computed alone
                        edges[v][l] = soa[(3 + v) * row + i] - soa[(v % 3) * row + i];
                  }
                  for (std::size_t c = 0; c < 3 && betas; ++c) margin[c][l] = betas[3 * i + c];
                  if (js) j_margin[l] = js[i];
                  if (i0 + l < count && decided[i] && fast_bounds[i].validity == Validity::valid &&
                      (!betas || std::isfinite(margins[i])))
                    valid |= 1u << l;
                }
                QualityBounds* mu_out = lane_mu.data() + i0;
                QualityBounds* sj_out = lane_straight_sj.data() + i0;
                lane_mu_done[i0 / kW] =
                    valid == 0 || !lane_mu_wanted ? 0u
                    : quad ? valid & bilinear_quad_mu_lanes(edges, margin, j_margin, qo.abs_tol, mu_out)
                           : valid & straight_simplex_mu_lanes(t, edges, margin, qo.abs_tol, mu_out);
                lane_straight_sj_done[i0 / kW] =
                    valid == 0 || !lane_sj_wanted ? 0u
                    : quad ? valid & bilinear_quad_sj_lanes(edges, margin, j_margin, qo.abs_tol, sj_out)
                           : valid & straight_simplex_sj_lanes(t, edges, margin, j_margin, qo.abs_tol, sj_out);
              }
            };
            // Whether a chunk of that first-order kind (or, first_order false, straight-sided
            // elements of it) has results in straight_lanes_of's lanes: pyramids and
            // hexahedra only at order 1.
            const auto straight_lanes_for = [&](LinearKind kind, bool first_order) {
              return ((want_mu || want_sj) && (kind == LinearKind::tetrahedron || kind == LinearKind::triangle ||
                                                kind == LinearKind::quadrangle)) ||
                     (first_order && (want_mu || want_sj) && kind == LinearKind::pyramid) ||
                     (first_order && want_sj && kind == LinearKind::hexahedron);
            };
            const auto lane_of = [&](const unsigned* done, std::vector<QualityBounds>& lane, std::size_t i) {
              return ((done[i / kNativeLanes] >> (i % kNativeLanes)) & 1u) != 0 ? &lane[i] : nullptr;
            };
            // mu and the scaled Jacobian of an element decided by the first-order chunk, from
            // its nodes, where its chunk's lanes (straight_lanes_of) did not settle them.
            const auto first_order_qualities = [&](std::size_t index, std::size_t element, Validity v,
                                                   const KnownMargin* known, const QualityBounds* mu_given,
                                                   const QualityBounds* sj_given) __attribute__((noinline)) {
              const auto conn = blk.element(element);
              element_nodes.resize(nn * 3);
              for (std::size_t k = 0; k < nn; ++k)
                for (std::size_t j = 0; j < 3; ++j)
                  element_nodes[k * 3 + j] = mesh.coords[3 * static_cast<std::size_t>(conn[k]) + j];
              qualities(index, element_nodes.data(), v, known, mu_given, sj_given);
            };
            // `finish` for an element decided by the first-order chunk (linear_jacobian.hpp),
            // which never takes the exact fallback: the bookkeeping, and mu and the scaled
            // Jacobian from the chunk's lanes or else from the element's nodes (with the
            // chunk's straight-sided margin, if it has one). Inlined and kept small, the rest
            // out of line: it runs per element of every first-order chunk (with `qualities`
            // inlined here, validity of 178k first-order tetrahedra took 9% longer; as a call,
            // mu of 384k took 3-5% longer).
            const auto finish_first_order = [&](std::size_t index, std::size_t element, const JacobianBounds& b,
                                                double ticks, const KnownMargin* known,
                                                bool in_lanes) __attribute__((always_inline)) {
              ElementCheck& ec = elements[index];
              ec.bounds = b;
              ec.analysed = true;
              st.add(b.stage, b.validity, ticks);
              ++alone_done;
              if (!want_mu && !want_sj) return;
              const std::size_t i = index - ch.out;
              const QualityBounds* mu_given = in_lanes && want_mu ? lane_of(lane_mu_done, lane_mu, i) : nullptr;
              const QualityBounds* sj_given =
                  in_lanes && want_sj ? lane_of(lane_straight_sj_done, lane_straight_sj, i) : nullptr;
              if ((want_mu && !mu_given) || (want_sj && !sj_given)) {
                first_order_qualities(index, element, b.validity, known, mu_given, sj_given);
                return;
              }
              // Both from the lanes, whose results always meet the tolerance.
              if (mu_given) {
                mu[index] = *mu_given;
                ++st.mu.computed;
              }
              if (sj_given) {
                sj[index] = *sj_given;
                ++st.sj.computed;
              }
            };
            if (fast != LinearKind::none) {
              // First-order fast path (linear_jacobian.hpp): the coefficients straight from
              // the vertices; the few it leaves open go one by one to the general path.
              const std::uint64_t ts = stage_ticks();
              const auto nv = static_cast<std::size_t>(linear_num_vertices(fast));
              soa.resize(nv * 3 * kLinearRow);
              const double* coords = mesh.coords.data();
              for (std::size_t i = 0; i < ch.count; ++i) {
                const NodeIndex* conn = blk.element(ch.first + i).data();
                double* to = soa.data() + i;
                for (std::size_t k = 0; k < nv; ++k) {
                  const double* x = coords + 3 * static_cast<std::size_t>(conn[k]);
                  to[(k * 3) * kLinearRow] = x[0];
                  to[(k * 3 + 1) * kLinearRow] = x[1];
                  to[(k * 3 + 2) * kLinearRow] = x[2];
                }
              }
              fast_bounds.resize(ch.count);
              linear_validity_chunk(fast, soa.data(), ch.count, fast_bounds.data(), decided);
              const double share = static_cast<double>(stage_ticks() - ts) / static_cast<double>(ch.count);
              const bool straight_lanes = straight_lanes_for(fast, true);
              if (straight_lanes)  // outside the stage times
                straight_lanes_of(type, kLinearRow, nullptr, nullptr, ch.count);
              nodes.resize(nn * 3);
              errors.resize(1);
              for (std::size_t i = 0; i < ch.count; ++i) {
                ElementCheck& ec = elements[ch.out + i];
                const auto conn = blk.element(ch.first + i);
                if (decided[i]) {
                  finish_first_order(ch.out + i, ch.first + i, fast_bounds[i], share, nullptr, straight_lanes);
                  continue;
                }
                const std::uint64_t te = stage_ticks();
                const JacobianSpace& space = jacobian_space(type);
                coeffs.resize(static_cast<std::size_t>(space.basis().size()));
                for (std::size_t k = 0; k < nn; ++k)
                  for (std::size_t j = 0; j < 3; ++j)
                    nodes[k * 3 + j] = mesh.coords[3 * static_cast<std::size_t>(conn[k]) + j];
                jacobian_coefficients(space, nodes.data(), 1, report.planar, coeffs.data(),
                                      errors.data(), ws.sample_scratch.product);
                ec.bounds = bounds_from_coefficients(space, coeffs.data(), errors[0], nodes.data(),
                                                     report.planar, bo, ws);
                finish(ch.out + i, nodes.data(), share + static_cast<double>(stage_ticks() - te));
              }
            } else {
              // The product path (jacobian_product.hpp): the chunk's Bézier coefficients of J
              // straight from its nodes, then each element's bounds exactly as jacobian_bounds
              // computes them (bit-identical; tests/analysis/jacobian_batch_test.cpp).
              const JacobianSpace& space = jacobian_space(type);
              const auto s = static_cast<std::size_t>(space.basis().size());
              // Validity: straight-sided elements first, by the first-order fast path with
              // a margin (straight_sided.hpp), from the mesh: their vertices by vertex and
              // axis (rows of kRow); the rest, listed in `rest`, go on below with their nodes
              // element by element.
              std::size_t left = 0;
              rest.resize(ch.count);
              bool straight_lanes = false;
              // Whether margins and betas hold every element's margin (curved ones' too:
              // infinite), which mu and the scaled Jacobian then need not compute again
              // (quadval_bench, one thread, 6 x 3 interleaved runs, medians: plate_quad_h0.08
              // mu 15.6 -> 14.8 ms, sj 15.6 -> 15.3 ms; plate_tri_h0.05 mu 90.6 -> 87.0 ms,
              // sj 125.5 -> 121.0 ms).
              bool margins_known = false;
              const auto known_margin = [&](std::size_t i) {
                KnownMargin k;
                k.margin = margins[i];
                std::copy_n(betas.begin() + static_cast<std::ptrdiff_t>(3 * i), 3, k.beta.begin());
                return k;
              };
              if (const StraightSidedMargin* straight = straight_of[ch.block].get()) {
                const std::uint64_t ts = stage_ticks();
                const double* coords = mesh.coords.data();
                const NodeIndex* first_conn = blk.element(ch.first).data();
                margins.resize(kChunk);
                betas.resize(3 * kChunk);
                straight->margins(coords, first_conn, ch.count, margins.data(),
                                  want_mu || want_sj ? betas.data() : nullptr);
                margins_known = want_mu || want_sj;
                if (std::any_of(margins.begin(), margins.begin() + static_cast<std::ptrdiff_t>(ch.count),
                                [](double m) { return std::isfinite(m); })) {
                  const auto nv = static_cast<std::size_t>(linear_num_vertices(straight->kind()));
                  const std::size_t axes = type.dim == 2 ? 2 : 3;  // planar 2D reads x and y
                  soa.resize(nv * 3 * kRow);
                  for (std::size_t v = 0; v < nv; ++v) {
                    const NodeIndex* conn = first_conn + v;
                    double* to = soa.data() + v * 3 * kRow;
                    for (std::size_t i = 0; i < ch.count; ++i, conn += nn) {
                      const double* x = coords + 3 * static_cast<std::size_t>(*conn);
                      for (std::size_t j = 0; j < axes; ++j) to[j * kRow + i] = x[j];
                    }
                  }
                  fast_bounds.resize(ch.count);
                  linear_validity_chunk(straight->kind(), soa.data(), ch.count, fast_bounds.data(), decided,
                                        margins.data(), kRow);
                  straight_lanes = straight_lanes_for(straight->kind(), false);
                } else {
                  std::fill(decided, decided + ch.count, false);  // a chunk of curved elements
                }
                const double share = static_cast<double>(stage_ticks() - ts) / static_cast<double>(ch.count);
                if (straight_lanes)  // outside the stage times
                  straight_lanes_of(type, kRow, betas.data(), margins.data(), ch.count);
                for (std::size_t i = 0; i < ch.count; ++i) {
                  if (!decided[i]) {
                    rest[left++] = i;
                    continue;
                  }
                  const KnownMargin known = known_margin(i);
                  finish_first_order(ch.out + i, ch.first + i, fast_bounds[i], share,
                                     want_mu || want_sj ? &known : nullptr, straight_lanes);
                }
              } else {
                for (std::size_t i = 0; i < ch.count; ++i) rest[left++] = i;
              }
              // mu and the scaled Jacobian of the valid elements of `rest` (their nodes in
              // `nodes`, their validity known), four at a time: lane_sj_done[k] where
              // lane_sj[k] holds element k's, likewise lane_mu_planar_done and lane_planar_mu;
              // else it needs the element's own call.
              const auto planar_lanes = [&] {
                lane_sj_done.assign(left, 0);
                lane_sj.resize(left);
                lane_mu_planar_done.assign(left, 0);
                lane_planar_mu.resize(left);
                for (std::size_t k = 0; k < left;) {
                  std::array<std::size_t, 4> group{};
                  std::size_t count = 0;
                  for (; k < left && count < 4; ++k)
                    if (elements[ch.out + rest[k]].bounds.validity == Validity::valid) group[count++] = k;
                  if (count == 0) break;
                  std::array<std::span<const double>, 4> x;
                  std::array<KnownMargin, 4> known_of{};
                  std::array<const KnownMargin*, 4> known{};
                  for (std::size_t l = 0; l < 4; ++l) {
                    const std::size_t g = group[std::min(l, count - 1)];  // spare lanes: a copy
                    x[l] = std::span<const double>(nodes.data() + g * nn * 3, nn * 3);
                    if (margins_known) {
                      known_of[l] = known_margin(rest[g]);
                      known[l] = &known_of[l];
                    }
                  }
                  std::array<QualityBounds, 4> out;
                  if (want_sj && scaled_jacobian_supported(type)) {
                    const unsigned done = scaled_jacobian_valid_planar4(type, x, qo, known, out);
                    for (std::size_t l = 0; l < count; ++l)
                      if ((done >> l) & 1u) {
                        lane_sj[group[l]] = out[l];
                        lane_sj_done[group[l]] = 1;
                      }
                  }
                  if (want_mu && mu_supported(type)) {
                    const unsigned done = mu_valid_planar4(type, x, qo, known, out);
                    for (std::size_t l = 0; l < count; ++l)
                      if ((done >> l) & 1u) {
                        lane_planar_mu[group[l]] = out[l];
                        lane_mu_planar_done[group[l]] = 1;
                      }
                  }
                }
              };
              nodes.resize(left * nn * 3);
              for (std::size_t k = 0; k < left; ++k) {
                const auto conn = blk.element(ch.first + rest[k]);
                for (std::size_t i = 0; i < nn; ++i)
                  for (std::size_t j = 0; j < 3; ++j)
                    nodes[(k * nn + i) * 3 + j] = mesh.coords[3 * static_cast<std::size_t>(conn[i]) + j];
              }
              // A tail of 2 or more elements is padded to a whole lane block with copies
              // of the last element: one block costs less than two elements one by one
              // (a lane's results do not depend on the others').
              constexpr std::size_t kLanes = JacobianProduct::kLanes;
              const std::size_t padded = left % kLanes >= 2 ? (left + kLanes - 1) / kLanes * kLanes : left;
              if (padded > left) {
                nodes.resize(std::max(nodes.size(), padded * nn * 3));
                for (std::size_t k = left; k < padded; ++k)
                  std::copy_n(nodes.data() + (left - 1) * nn * 3, nn * 3, nodes.data() + k * nn * 3);
              }
              coeffs.resize(padded * s);
              errors.resize(padded);
              const std::uint64_t ts = stage_ticks();
              if (left > 0)
                jacobian_coefficients(space, nodes.data(), padded, report.planar, coeffs.data(), errors.data(),
                                      ws.sample_scratch.product);
              std::uint64_t te = stage_ticks();
              const double batch_share = static_cast<double>(te - ts) / static_cast<double>(std::max<std::size_t>(left, 1));
              // One clock read per element when `finish` is only bookkeeping (its time then
              // counts in the next element's stage); mu, the scaled Jacobian and distortion
              // in `finish` are kept out of the stage times.
              const bool light_finish = !want_mu && !want_sj && !want_distortion;
              // mu and the scaled Jacobian of valid planar 2D elements four at a time
              // (mu_valid_planar4, scaled_jacobian_valid_planar4: the same bounds), once the
              // validity of all of them is known.
              const bool in_lanes = (want_sj || want_mu) && report.planar && type.dim == 2;
              if (in_lanes) {
                validity_ticks.resize(left);
                for (std::size_t k = 0; k < left; ++k) {
                  elements[ch.out + rest[k]].bounds = bounds_from_coefficients(
                      space, coeffs.data() + k * s, errors[k], nodes.data() + k * nn * 3, report.planar, bo, ws);
                  const std::uint64_t done_at = stage_ticks();
                  validity_ticks[k] = batch_share + static_cast<double>(done_at - te);
                  te = done_at;
                }
                planar_lanes();
              }
              for (std::size_t k = 0; k < left; ++k) {
                const std::size_t i = rest[k];
                ElementCheck& ec = elements[ch.out + i];
                const double* xe = nodes.data() + k * nn * 3;
                const KnownMargin known = margins_known ? known_margin(i) : KnownMargin{};
                if (in_lanes) {
                  finish(ch.out + i, xe, validity_ticks[k], margins_known ? &known : nullptr,
                         lane_mu_planar_done[k] ? &lane_planar_mu[k] : nullptr, lane_sj_done[k] ? &lane_sj[k] : nullptr);
                  continue;
                }
                ec.bounds = bounds_from_coefficients(space, coeffs.data() + k * s, errors[k], xe,
                                                     report.planar, bo, ws);
                const std::uint64_t done_at = stage_ticks();
                finish(ch.out + i, xe, batch_share + static_cast<double>(done_at - te), margins_known ? &known : nullptr);
                te = light_finish ? done_at : stage_ticks();
              }
            }
          }
          // Counts per type, here rather than in a serial pass over all elements.
          std::array<std::size_t, 4> chunk_counts{};
          for (std::size_t i = 0; i < ch.count; ++i) {
            const ElementCheck& ec = elements[ch.out + i];
            chunk_counts[ec.analysed ? static_cast<std::size_t>(ec.bounds.validity) : 3] += 1;
          }
          auto& type_counts = st.counts[type.gmsh_id];
          for (std::size_t k = 0; k < 4; ++k) type_counts[k] += chunk_counts[k];
          // Histograms and worst lists too (order-independent; merged after the loop).
          CheckBatch mine;
          mine.first = first;
          mine.elements = elements;
          if (!distortion.empty()) mine.distortion = distortion;
          if (!mu.empty()) mine.mu = mu;
          if (!sj.empty()) mine.sj = sj;
          add_elements(st.summary, mine, ch.out, ch.out + ch.count);
          const std::size_t d = done.fetch_add(ch.count) + ch.count;
          if (options.progress && master) options.progress(d, total);
        } catch (...) {
          fail(std::current_exception());
        }
      }
      st.busy += now_seconds() - busy_from;
      maybe_more();
      remaining[batch].fetch_sub(1, std::memory_order_acq_rel);  // publishes the results
      if (master && batched) flush_ready();
    }
    if (master && batched)
      while (!failed && flushed.load(std::memory_order_relaxed) < num_batches) {
        flush_ready();
        if (flushed.load(std::memory_order_relaxed) < num_batches) pause();
      }
  });
  report.threads = threads_used;
  if (failure) std::rethrow_exception(failure);

  const double seconds_per_tick = tick_rate.seconds_per_tick();
  for (const ThreadStats& st : stats) {
    merge_summary(report, st.summary);
    report.exact_fallbacks += st.exact;
    for (auto [from, to] : {std::pair{&st.mu, &report.mu.counts}, std::pair{&st.sj, &report.sj.counts}}) {
      to->computed += from->computed;
      to->skipped += from->skipped;
      to->tolerance_not_met += from->tolerance_not_met;
      for (const auto& [id, n] : from->skipped_types) to->skipped_types[id] += n;
    }
    for (const auto& [id, c] : st.counts)
      for (std::size_t k = 0; k < 4; ++k) report.counts[id][k] += c[k];
    if (report.stages.size() < st.stages.size()) report.stages.resize(st.stages.size());
    for (std::size_t i = 0; i < st.stages.size(); ++i) {
      report.stages[i].valid += st.stages[i].valid;
      report.stages[i].invalid += st.stages[i].invalid;
      report.stages[i].seconds += st.stages[i].seconds * seconds_per_tick;
    }
  }
  if (report.stages.size() < 2) report.stages.resize(2);
  for (std::size_t i = 0; i < report.stages.size(); ++i) report.stages[i].name = stage_name(i);
  // The sink's time is left out; but while the calling thread runs it, the other threads go
  // on analysing, so the wall time less the sink's can fall far below the analysis's own
  // (1M elements to CSV on 2 threads: 0.006 s). Never less than the set-up plus the
  // threads' work shared over them, which is what the analysis takes without a sink.
  double busy = 0;
  for (const ThreadStats& st : stats) busy += st.busy;
  report.seconds = std::max(now_seconds() - t0 - sink_seconds, setup_seconds + busy / threads_used);
  return report;
}

CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options, const std::string& file) {
  CheckReport report;
  std::size_t total = 0;
  for (const ElementBlock& b : mesh.blocks)
    if (b.type->dim == mesh.dimension()) total += b.size();
  report.elements.reserve(total);
  const bool want_distortion = measures_distortion(options.measure);
  const bool want_mu = measures_mu(options.measure), want_sj = measures_scaled_jacobian(options.measure);
  const CheckSummary summary = check_mesh_streamed(mesh, options, file, [&](const CheckBatch& b) {
    report.elements.insert(report.elements.end(), b.elements.begin(), b.elements.end());
    if (want_distortion) report.distortion.insert(report.distortion.end(), b.distortion.begin(), b.distortion.end());
    if (want_mu) report.mu.insert(report.mu.end(), b.mu.begin(), b.mu.end());
    if (want_sj) report.sj.insert(report.sj.end(), b.sj.begin(), b.sj.end());
  });
  report.file = summary.file;
  report.measure = summary.measure;
  report.dimension = summary.dimension;
  report.planar = summary.planar;
  report.counts = summary.counts;
  report.stages = summary.stages;
  report.exact_fallbacks = summary.exact_fallbacks;
  report.mu_counts = summary.mu.counts;
  report.sj_counts = summary.sj.counts;
  report.seconds = summary.seconds;
  report.threads = summary.threads;
  return report;
}

DistortionBounds CheckReport::distortion_of(std::size_t i) const noexcept {
  return distortion.empty() ? DistortionBounds{NAN, NAN} : distortion[i];
}

QualityBounds CheckReport::mu_of(std::size_t i) const noexcept {
  return mu.empty() ? kNotComputed : mu[i];
}

QualityBounds CheckReport::sj_of(std::size_t i) const noexcept {
  return sj.empty() ? kNotComputed : sj[i];
}

double ElementCheck::ratio_lower() const noexcept {
  if (!analysed || !(bounds.jmax_upper > 0)) return std::nan("");
  return next_down(bounds.jmin_lower / bounds.jmax_upper);
}

double ElementCheck::jmin_over_javg() const noexcept {
  if (!analysed || !(bounds.javg > 0)) return std::nan("");
  return bounds.jmin_lower / bounds.javg;
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

namespace {

// The indices of the n elements with the smallest keys among those `included`; ties by tag,
// then by index.
template <class Key, class Included>
std::vector<std::size_t> smallest(const std::vector<ElementCheck>& elements, std::size_t n,
                                  Key key, Included included) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (included(i)) idx.push_back(i);
  const std::size_t m = std::min(n, idx.size());
  std::partial_sort(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(m), idx.end(),
                    [&](std::size_t a, std::size_t b) {
                      const double ka = key(a), kb = key(b);
                      if (ka != kb) return ka < kb;
                      return elements[a].tag != elements[b].tag ? elements[a].tag < elements[b].tag : a < b;
                    });
  idx.resize(m);
  return idx;
}

}  // namespace

std::vector<std::size_t> CheckReport::worst_quality(std::size_t n, bool sj) const {
  const auto key = [&](std::size_t i) { return (sj ? sj_of(i) : mu_of(i)).lower; };
  return smallest(elements, n, key, [&](std::size_t i) { return !std::isnan(key(i)); });
}

std::vector<std::size_t> CheckReport::worst(std::size_t n) const {
  const bool by_distortion = measures_distortion(measure);
  const auto key = [&](std::size_t i) {
    const double k = by_distortion ? distortion_of(i).lower : elements[i].ratio_lower();
    return std::isnan(k) ? -INFINITY : k;
  };
  return smallest(elements, n, key, [&](std::size_t i) { return elements[i].analysed; });
}

}  // namespace quadval
