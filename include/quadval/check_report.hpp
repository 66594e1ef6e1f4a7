#pragma once
/// Mesh-wide Jacobian check (`quadval check`): certified bounds for every element of the
/// mesh's highest dimension, in parallel, with the summary of Paper III §5 (counts per
/// answer and type, worst elements, histogram, the stage table of Table 2) and the
/// per-element outputs (CSV, JSON, mesh fields for VTU/MSH).
///
/// Results do not depend on the thread count: elements are processed in fixed chunks
/// and every element's computation is sequential and deterministic.

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "quadval/jacobian_bounds.hpp"
#include "quadval/mesh.hpp"

namespace quadval {

enum class CheckMeasure : std::uint8_t {
  validity,    ///< settle the sign of min J (fastest)
  jacobian,    ///< bounds on min J and max J within the tolerance
  distortion,  ///< as jacobian, plus the distortion min J / J_straight (Paper III eq. 3)
};

struct CheckOptions {
  CheckMeasure measure = CheckMeasure::validity;
  double rel_tol = 1e-2;  ///< see BoundsOptions
  double abs_tol = 0;
  int max_subdivisions = 1000;
  int threads = 0;  ///< 0: OpenMP's default
  /// Called now and then from the calling thread with (elements done, total).
  std::function<void(std::size_t, std::size_t)> progress;
};

/// One analysed (or skipped) element.
struct ElementCheck {
  Tag tag = 0;
  const ElementType* type = nullptr;
  bool analysed = false;  ///< false: skipped (pyramid, or an order beyond the supported ones)
  JacobianBounds bounds;
  DistortionBounds distortion{std::nan(""), std::nan("")};  ///< NaN unless measured
  /// Scale-free quality: jmin_lower / jmax_upper (like Gmsh's minJ/maxJ, but a bound).
  double ratio_lower = std::nan("");
  /// jmin_lower / javg (javg the mean of J): NaN when javg <= 0.
  double jmin_over_javg = std::nan("");
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
  /// Per Gmsh type id: counts of valid, invalid, undetermined, skipped.
  std::map<int, std::array<std::size_t, 4>> counts;
  std::vector<StageRow> stages;
  std::size_t exact_fallbacks = 0;
  double seconds = 0;                 ///< wall time of the analysis
  int threads = 1;

  std::size_t count(Validity v) const;
  std::size_t skipped() const;
  /// Indices of the analysed elements, worst first (lowest ratio_lower or distortion).
  std::vector<std::size_t> worst(std::size_t n) const;
};

/// Analyses every element of the mesh's highest dimension.
/// @throws InputError (file = `file`) for non-finite node coordinates
CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options,
                       const std::string& file = "");

/// Terminal summary: counts per answer and type, stage table, histogram, worst elements.
std::string format_check_summary(const CheckReport& report, std::size_t worst = 10);

/// Per-element CSV: header row, then one row per element of the analysed dimension:
/// tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,
/// subdivisions,distortion_upper,jmin_over_javg,ratio_lower,stage,exact
/// (validity is valid, invalid, undetermined or skipped; type is the Gmsh type id).
std::string check_csv(const CheckReport& report);

/// JSON: {"summary": {...counts, stages...}, "elements": [{...per element...}]}.
std::string check_json(const CheckReport& report);

/// Per-element fields for write_mesh (one value per element of the whole mesh, in block
/// order; NaN for elements not analysed): validity (1 valid, 0 undetermined, -1 invalid,
/// NaN skipped), jmin_lower, jmin_upper, ratio_lower, distortion_lower.
std::vector<std::pair<std::string, std::vector<double>>> check_fields(const Mesh& mesh,
                                                                      const CheckReport& report);

}  // namespace quadval
