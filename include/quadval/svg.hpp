#pragma once
/// SVG pictures for reports: a surface mesh coloured by a per-element value with a colour bar,
/// and histograms (Paper I Fig. 15 shows those of the quad quality eta and of the normalized
/// edge length l^h). Plain SVG 1.1, viewable in any browser; every file goes through
/// write_file_atomically.

#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "quadval/mesh.hpp"

namespace quadval {

/// Perceptually uniform colour map (viridis, piecewise linear through 9 of its samples):
/// t = 0 dark purple, 0.5 teal, 1 yellow; t is clamped to [0, 1], NaN gives grey.
std::array<unsigned char, 3> colour_map(double t) noexcept;

struct MeshSvgOptions {
  std::string title;            ///< drawn above the mesh
  std::string value_name;       ///< label of the colour bar, e.g. "eta"
  double value_min = 0.0;       ///< colour bar range; values outside are clamped
  double value_max = 1.0;
  int width = 900;              ///< drawing width in pixels; the height follows the aspect ratio
  bool draw_edges = true;       ///< thin dark element edges
};

/// SVG text of the 2D elements (triangles and quadrangles, any order: corners drawn) of
/// `mesh`, one <polygon> per element, filled with colour_map((v - min) / (max - min)) of its
/// value. Elements of other dimensions are not drawn.
/// A planar mesh (all z equal) is drawn in its (x, y) plane; otherwise in an isometric view
/// from (1, 1, 1), far elements first.
/// @param values  one per element of the mesh in block order (block 0's elements, then
///                block 1's ...), as io.hpp's ElementField; NaN draws grey
/// @pre values.size() == mesh.num_elements() (QV_ASSERT)
std::string mesh_svg(const Mesh& mesh, std::span<const double> values,
                     const MeshSvgOptions& options);

/// mesh_svg written atomically to `path`.
void write_mesh_svg(const Mesh& mesh, std::span<const double> values,
                    const std::filesystem::path& path, const MeshSvgOptions& options);

/// Bin counts: value v goes to bin floor((v - lo) / (hi - lo) * bins), clamped to
/// [0, bins - 1] (so hi itself and values above it land in the last bin, values below lo in
/// the first); NaN values are not counted. @pre lo < hi, bins >= 1.
std::vector<std::size_t> histogram_counts(std::span<const double> values, double lo, double hi,
                                          int bins);

struct HistogramSvgOptions {
  std::string title;
  std::string x_label;          ///< e.g. "eta" or "l^h"
  double lo = 0.0, hi = 1.0;    ///< range of the x axis
  int bins = 20;
  /// Vertical reference lines with their labels, e.g. {1.0, "ideal"} for l^h.
  std::vector<std::pair<double, std::string>> markers;
  int width = 640, height = 400;
};

/// SVG text of the histogram of `values` (histogram_counts), with the count, mean, minimum
/// and maximum written under the title, how many values were clamped into the end bins, and
/// the y axis in percent of the counted values.
std::string histogram_svg(std::span<const double> values, const HistogramSvgOptions& options);

/// histogram_svg written atomically to `path`.
void write_histogram_svg(std::span<const double> values, const std::filesystem::path& path,
                         const HistogramSvgOptions& options);

}  // namespace quadval
