#pragma once
/// Mesh-wide Jacobian check (`quadval check`): certified bounds for every element of the
/// mesh's highest dimension, in parallel, with the summary of Paper III §5 (counts per
/// answer and type, worst elements, histogram, the stage table of Table 2) and the
/// per-element outputs (CSV, JSON, mesh fields for VTU/MSH); optionally the certified
/// quality measures mu (mu_bounds.hpp, Paper V) and the scaled Jacobian
/// (scaled_jacobian.hpp).
///
/// Results do not depend on the thread count: elements are processed in fixed chunks
/// and every element's computation is sequential and deterministic.

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <iosfwd>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "quadval/jacobian_bounds.hpp"
#include "quadval/mesh.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

enum class CheckMeasure : std::uint8_t {
  validity,    ///< settle the sign of min J (fastest)
  jacobian,    ///< bounds on min J and max J within the tolerance
  distortion,  ///< as jacobian, plus the distortion min J / J_straight (Paper III eq. 3)
  mu,               ///< validity, plus certified bounds on mu (mu_bounds.hpp)
  scaled_jacobian,  ///< validity, plus certified bounds on the scaled Jacobian
  all,              ///< distortion (jacobian bounds included), mu and the scaled Jacobian
};

/// "validity", "jacobian", "distortion", "mu", "scaled-jacobian", "all" (the CLI's names).
const char* check_measure_name(CheckMeasure m) noexcept;
/// Whether a measure includes mu, the scaled Jacobian, bounds on min/max J, distortion.
bool measures_mu(CheckMeasure m) noexcept;
bool measures_scaled_jacobian(CheckMeasure m) noexcept;
bool measures_jacobian_range(CheckMeasure m) noexcept;
bool measures_distortion(CheckMeasure m) noexcept;

struct CheckOptions {
  CheckMeasure measure = CheckMeasure::validity;
  double rel_tol = 1e-2;  ///< see BoundsOptions
  double abs_tol = 0;
  int max_subdivisions = 1000;
  /// Absolute tolerance of mu and the scaled Jacobian (both at most 1), and their
  /// subdivision limit (max_subdivisions).
  double quality_abs_tol = 1e-2;
  int threads = 0;  ///< at most this many (0: OpenMP's default); fewer when the work is small
  /// Where the estimated work is moderate, start the other threads only once the calling
  /// thread's pace shows them worth their cost (check_mesh.cpp); false: at once, up to the
  /// estimate's count (tests of that count). The answers are the same either way.
  bool threads_on_demand = true;
  /// Worst elements the summary keeps (CheckSummary::worst; at least 10, the JSON's list).
  std::size_t worst = 10;
  /// Called now and then from the calling thread with (elements done, total).
  std::function<void(std::size_t, std::size_t)> progress;
};

/// One analysed (or skipped) element.
struct ElementCheck {
  Tag tag = 0;
  const ElementType* type = nullptr;
  bool analysed = false;  ///< false: skipped (pyramid, or an order beyond the supported ones)
  JacobianBounds bounds;
  /// Scale-free quality: jmin_lower / jmax_upper rounded down (like Gmsh's minJ/maxJ, but
  /// a bound); NaN when not analysed or jmax_upper <= 0. Computed, not stored: a million
  /// elements' results stay small.
  double ratio_lower() const noexcept;
  /// jmin_lower / javg (javg the mean of J): NaN when not analysed or javg <= 0.
  double jmin_over_javg() const noexcept;
};

/// The bounds of a quality measure not computed for an element.
inline constexpr QualityBounds kNotComputed{std::numeric_limits<double>::quiet_NaN(),
                                            std::numeric_limits<double>::quiet_NaN(), 0, false};

/// Per quality measure (mu, scaled Jacobian): how many elements got bounds, how many were
/// skipped (type or order not supported, or the element itself skipped), how many stopped
/// at the subdivision limit before the tolerance.
struct QualityCounts {
  std::size_t computed = 0;
  std::size_t skipped = 0;
  std::size_t tolerance_not_met = 0;
  std::map<int, std::size_t> skipped_types;  ///< Gmsh type id -> skipped count
};

/// Paper III Table 2: how many elements each stage decided and the time it took.
struct StageRow {
  std::string name;           ///< "samples", "Bezier", "1 subdivision", ...
  std::size_t valid = 0;
  std::size_t invalid = 0;
  double seconds = 0;         ///< CPU seconds summed over threads
};

struct CheckReport {
  std::string file;
  CheckMeasure measure = CheckMeasure::validity;
  int dimension = 0;                  ///< the analysed dimension
  bool planar = false;                ///< 2D: all nodes share one z (J with n = +z)
  std::vector<ElementCheck> elements;  ///< elements of that dimension, in block order
  /// Per element of `elements` (same index), only when the measure includes them, else
  /// empty: kept apart so that a validity check of millions of elements stays small.
  /// Entries are NaN / kNotComputed where not computed (type not supported, skipped).
  std::vector<DistortionBounds> distortion;
  std::vector<QualityBounds> mu, sj;
  /// Per Gmsh type id: counts of valid, invalid, undetermined, skipped.
  std::map<int, std::array<std::size_t, 4>> counts;
  std::vector<StageRow> stages;
  std::size_t exact_fallbacks = 0;
  QualityCounts mu_counts, sj_counts;  ///< only for measures that include them
  double seconds = 0;                 ///< wall time of the analysis
  int threads = 1;  ///< threads actually used

  /// Element i's distortion, mu and scaled-Jacobian bounds (NaN when not computed).
  DistortionBounds distortion_of(std::size_t i) const noexcept;
  QualityBounds mu_of(std::size_t i) const noexcept;
  QualityBounds sj_of(std::size_t i) const noexcept;

  std::size_t count(Validity v) const;
  std::size_t skipped() const;
  /// Indices of the analysed elements, worst first (lowest ratio_lower or distortion).
  std::vector<std::size_t> worst(std::size_t n) const;
  /// Indices of the elements with mu (sj = false) or scaled-Jacobian (sj = true) bounds,
  /// worst first by their lower bound (ties by tag).
  std::vector<std::size_t> worst_quality(std::size_t n, bool sj) const;
};

/// Histogram of a scale-free quality: one bin below 0, bins of 0.1 from 0 to 0.9, one bin
/// from 0.9 up; NaN values are counted apart.
struct QualityHistogram {
  static constexpr std::size_t kBins = 11;
  std::array<std::size_t, kBins> bins{};
  std::size_t values = 0;     ///< values added, NaN excepted (what the bars are relative to)
  std::size_t undefined = 0;  ///< NaN values
  void add(double q) noexcept;
  /// "< 0", "[0.0, 0.1)", ..., ">= 0.9".
  static std::string label(std::size_t bin);
  bool operator==(const QualityHistogram&) const = default;
};

/// One element of a worst list, with what the summaries print about it.
struct WorstElement {
  std::size_t index = 0;  ///< position among the analysed elements (CheckReport::elements)
  Tag tag = 0;
  const ElementType* type = nullptr;
  double key = 0;         ///< what the list is ordered by, lowest first (NaN lowest of all)
  JacobianBounds bounds;  ///< the element's Jacobian bounds (validity, jmin)
  QualityBounds quality = kNotComputed;  ///< mu / scaled-Jacobian lists: the bounds listed
};

/// The `capacity` lowest elements of a stream, ordered by (key, tag, index) with NaN keys
/// lowest: a bounded heap, so a million elements cost `capacity` entries, and the result
/// does not depend on the order the elements are offered in.
class WorstList {
 public:
  explicit WorstList(std::size_t capacity = 10) : capacity_(capacity) {}
  void offer(const WorstElement& e);
  /// False only when an element of this key cannot enter the list (it is full and its
  /// highest key is lower): a test before building the element, on every element.
  bool may_take(double key) const noexcept {
    return heap_.size() < capacity_ || (!heap_.empty() && !(key > heap_.front().key));
  }
  /// The kept elements, lowest first.
  std::vector<WorstElement> sorted() const;
  std::size_t capacity() const noexcept { return capacity_; }

 private:
  std::size_t capacity_;
  std::vector<WorstElement> heap_;  // max-heap: the highest kept element on top
};

/// The summary of mu or of the scaled Jacobian over the elements that got bounds.
struct QualitySummary {
  QualityCounts counts;
  QualityHistogram histogram;  ///< of the lower bounds
  double lower_sum = 0;        ///< sum of the lower bounds, in element order
  WorstList worst;             ///< lowest lower bounds (key = lower)
};

/// What the terminal and JSON summaries need, kept while the elements stream by
/// (check_mesh_streamed), or computed from a stored report (summarize).
struct CheckSummary {
  std::string file;
  CheckMeasure measure = CheckMeasure::validity;
  int dimension = 0;
  bool planar = false;
  std::size_t elements = 0;  ///< elements of the analysed dimension
  std::map<int, std::array<std::size_t, 4>> counts;  ///< as CheckReport::counts
  std::vector<StageRow> stages;
  std::size_t exact_fallbacks = 0;
  /// Wall time of the analysis, a sink's time excluded, but never less than its set-up plus
  /// the threads' analysing time over the thread count (other threads go on while the
  /// calling thread runs the sink).
  double seconds = 0;
  int threads = 1;
  /// Of the analysed elements' scale-free quality: distortion lower bound when measured,
  /// else ratio_lower (NaN: undefined).
  QualityHistogram histogram;
  WorstList worst;  ///< by that quality (key), NaN first
  QualitySummary mu, sj;  ///< only for measures that include them

  std::size_t count(Validity v) const;
  std::size_t skipped() const;
};

/// The summary of a stored report, computed from all its elements at once (sorting, not a
/// heap): the reference that check_mesh_streamed's summary is tested against.
/// @param worst how many worst elements to keep (at least 10 are kept)
CheckSummary summarize(const CheckReport& report, std::size_t worst = 10);

/// Consecutive analysed elements, handed out in element order by check_mesh_streamed.
struct CheckBatch {
  std::size_t first = 0;  ///< index of elements[0] among the analysed elements
  std::span<const ElementCheck> elements;
  std::span<const DistortionBounds> distortion;  ///< same length, or empty when not measured
  std::span<const QualityBounds> mu, sj;          ///< likewise
  DistortionBounds distortion_of(std::size_t i) const noexcept;
  QualityBounds mu_of(std::size_t i) const noexcept;
  QualityBounds sj_of(std::size_t i) const noexcept;
};
using CheckSink = std::function<void(const CheckBatch&)>;

/// Elements per batch of check_mesh_streamed (a multiple of its chunks, of 64 or 256).
inline constexpr std::size_t kCheckBatch = 16384;

/// Analyses every element of the mesh's highest dimension, keeping only the summary: the
/// elements go in batches of kCheckBatch, each handed to `sink` (when given) from the
/// calling thread, in element order, once done, then dropped. Memory beyond the mesh: a few
/// batches of results and the bounded worst lists, whatever the mesh size; with no sink and
/// no mu or scaled Jacobian, only a chunk of results per thread. Results (and the batches'
/// contents) do not depend on the thread count.
/// @throws InputError (file = `file`) for non-finite node coordinates; whatever `sink` throws
CheckSummary check_mesh_streamed(const Mesh& mesh, const CheckOptions& options,
                                 const std::string& file = "", const CheckSink& sink = {});

/// Analyses every element of the mesh's highest dimension and keeps every result
/// (check_mesh_streamed with a sink that stores the batches).
/// @throws InputError (file = `file`) for non-finite node coordinates
CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options,
                       const std::string& file = "");

/// Terminal summary: counts per answer and type, stage table, histogram, worst elements;
/// for mu and the scaled Jacobian also min/mean of the lower bounds, a histogram, the
/// worst elements and the skipped counts.
std::string format_check_summary(const CheckSummary& summary, std::size_t worst = 10);
/// The same for a stored report (format_check_summary(summarize(report, worst), worst)).
std::string format_check_summary(const CheckReport& report, std::size_t worst = 10);

/// Per-element CSV: header row, then one row per element of the analysed dimension:
/// tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,
/// subdivisions,distortion_upper,jmin_over_javg,ratio_lower,stage,exact,
/// mu_lower,mu_upper,sj_lower,sj_upper
/// (validity is valid, invalid, undetermined or skipped; type is the Gmsh type id; nan
/// where a value was not computed).
std::string check_csv(const CheckReport& report);
/// check_csv's header line, and its rows for one batch (appended to `out`): check_csv is
/// the header and the rows of all batches, in order.
std::string check_csv_header();
void append_check_csv_rows(std::string& out, const CheckBatch& batch);

/// JSON: {"summary": {...counts, stages, and "mu" / "scaled_jacobian": {computed,
/// skipped, tolerance_not_met, worst_tags} when measured...}, "elements": [{...per
/// element, with "mu" / "sj": {lower, upper, subdivisions, tolerance_met} when computed}]}.
std::string check_json(const CheckReport& report);

/// check_json written as the elements stream by: the document's "elements" array comes
/// first (keys are sorted), so rows go out batch by batch and the summary at the end; the
/// bytes equal check_json's for the same results.
class CheckJsonWriter {
 public:
  explicit CheckJsonWriter(std::ostream& out);
  void add(const CheckBatch& batch);
  void finish(const CheckSummary& summary);

 private:
  std::ostream* out_;
  bool any_ = false;
};

/// Per-element fields for write_mesh (one value per element of the whole mesh, in block
/// order; NaN for elements not analysed): validity (1 valid, 0 undetermined, -1 invalid,
/// NaN skipped), jmin_lower, jmin_upper, ratio_lower, distortion_lower, and mu_lower /
/// sj_lower when the measure includes them.
std::vector<std::pair<std::string, std::vector<double>>> check_fields(const Mesh& mesh,
                                                                      const CheckReport& report);

/// check_fields filled batch by batch: only the fields are kept (one double per element and
/// field), never the per-element records.
class CheckFieldCollector {
 public:
  /// @param mesh borrowed; must outlive the collector and be the mesh being checked
  CheckFieldCollector(const Mesh& mesh, CheckMeasure measure);
  void add(const CheckBatch& batch);
  /// The fields, as check_fields returns them; the collector is empty afterwards.
  std::vector<std::pair<std::string, std::vector<double>>> take();

 private:
  struct Run {  // analysed elements [first, first + count) sit at mesh-wide [offset, ...)
    std::size_t first, count, offset;
  };
  CheckMeasure measure_;
  std::vector<Run> runs_;
  std::vector<std::pair<std::string, std::vector<double>>> fields_;
};

}  // namespace quadval
