#pragma once
// A dense row-major map without its zero entries, row by row in the same order, for the
// per-element maps from node coordinates to Bézier coefficients (jacobian_product.hpp,
// mu_space.hpp, scaled_jacobian_space.hpp): the same terms summed in the same order as over the dense
// row, so the same result bit for bit (a zero entry times a finite difference adds a
// zero, which leaves a sum started at +0 unchanged), without a multiply or a test per zero.
// Between 27% (quadratic hexahedra) and 64% (quartic triangles) of the entries are nonzero.
// The map is also kept dense in blocks of four rows, summed in SIMD lanes
// (four_rows_times_points, the same bits again), which is faster where the rows are short
// chains of additions. Internal to src/analysis.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "analysis/lane_vector.hpp"

namespace quadval {

/// The node differences x_i - x_0 of four elements, element l in lane l (d[2 i + a]:
/// coordinate a < 2 of node i, as rows_times_planar_lanes takes them), and each element's
/// range max_{i, a < 3} |x_i,a - x_0,a| as the per-element maps take it. false where an
/// element is not in a plane z = const or its range is not finite.
inline bool planar_differences(const std::array<std::span<const double>, 4>& nodes, std::size_t nn, Lanes<4>* d,
                               Lanes<4>& range) {
  for (std::size_t l = 0; l < 4; ++l) {
    const double* x = nodes[l].data();
    double r = 0;
    for (std::size_t i = 0; i < nn; ++i) {
      for (std::size_t a = 0; a < 3; ++a) r = std::max(r, std::abs(x[3 * i + a] - x[a]));
      if (x[3 * i + 2] - x[2] != 0) return false;
      d[2 * i][l] = x[3 * i] - x[0];
      d[2 * i + 1][l] = x[3 * i + 1] - x[1];
    }
    if (!(r < std::numeric_limits<double>::infinity())) return false;
    range[l] = r;
  }
  return true;
}

struct SparseRows {
  std::vector<std::uint32_t> start;  ///< row r: entries [start[r], start[r + 1])
  std::vector<std::uint32_t> node;   ///< the column (node) of each entry
  std::vector<double> value;
  /// The same map dense, four rows side by side: dense4[(b * columns + i) * 4 + l] is the
  /// entry of row 4 b + l and node i (0 past the last row).
  std::vector<double> dense4;
  std::size_t columns = 0;

  static SparseRows of(const std::vector<double>& dense, std::size_t rows, std::size_t columns) {
    SparseRows m;
    m.columns = columns;
    m.dense4.assign((rows + 3) / 4 * columns * 4, 0.0);
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t i = 0; i < columns; ++i) m.dense4[((r / 4) * columns + i) * 4 + r % 4] = dense[r * columns + i];
    m.start.reserve(rows + 1);
    m.start.push_back(0);
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t i = 0; i < columns; ++i)
        if (const double v = dense[r * columns + i]; v != 0) {
          m.node.push_back(static_cast<std::uint32_t>(i));
          m.value.push_back(v);
        }
      m.start.push_back(static_cast<std::uint32_t>(m.node.size()));
    }
    return m;
  }

  /// Row r times the three coordinates of d (d[3 i + a] for node i), each summed from +0
  /// in node order: out[a] = sum_i entry(r, i) d[3 i + a].
  void row_times_points(std::size_t r, const double* d, double out[3]) const {
    double s0 = 0, s1 = 0, s2 = 0;  // in scalars: GCC 12 stored and reloaded out[] per term
    for (std::uint32_t t = start[r]; t < start[r + 1]; ++t) {
      const double g = value[t];
      const double* p = d + 3 * static_cast<std::size_t>(node[t]);
      s0 += g * p[0];
      s1 += g * p[1];
      s2 += g * p[2];
    }
    out[0] = s0;
    out[1] = s1;
    out[2] = s2;
  }
  /// The same where every node's third coordinate is 0 (planar elements in z = const,
  /// as differences x_i - x_0): out[2] = +0, what its sum gives, without computing it.
  void row_times_flat_points(std::size_t r, const double* d, double out[3]) const {
    double s0 = 0, s1 = 0;
    for (std::uint32_t t = start[r]; t < start[r + 1]; ++t) {
      const double g = value[t];
      const double* p = d + 3 * static_cast<std::size_t>(node[t]);
      s0 += g * p[0];
      s1 += g * p[1];
    }
    out[0] = s0;
    out[1] = s1;
    out[2] = 0;
  }
  /// Every row times the x and y of four point sets at once, set l in lane l (d[2 i + a]:
  /// coordinate a of node i): out[a * rows() + r] = sum_i entry(r, i) d[2 i + a], each lane
  /// the bits of row_times_flat_points on its set (nonzero entries in node order).
  void rows_times_planar_lanes(const Lanes<4>* d, Lanes<4>* out) const {
    const std::size_t n = rows();
    for (std::size_t r = 0; r < n; ++r) {
      Lanes<4> s0{}, s1{};
      for (std::uint32_t t = start[r]; t < start[r + 1]; ++t) {
        const double g = value[t];
        const Lanes<4>* p = d + 2 * static_cast<std::size_t>(node[t]);
        s0 += g * p[0];
        s1 += g * p[1];
      }
      out[r] = s0;
      out[n + r] = s1;
    }
  }
  /// Rows 4 b .. 4 b + 3 at once (lane l: row 4 b + l; lanes past the last row give +0)
  /// times the first NX coordinates of d: out[a] = sum_i entry(row, i) d[3 i + a] over every
  /// node in order, zeros included. For finite d the same bits as row_times_points: a zero
  /// entry adds +-0, which leaves a sum started at +0 unchanged. Four independent sums per
  /// coordinate instead of one chain of additions per row: quartic triangles have 64% of
  /// their entries nonzero, and the rows' chains, not the multiplies, were the cost.
  /// Measured (quadval_bench, one thread, two binaries interleaved 6 times x 3 repetitions,
  /// medians of 18): plate_tri_h0.05 mu 100.8 -> 93.3 ms, sj 128.0 -> 123.5 ms;
  /// plate_quad_h0.08 mu 16.4 -> 16.0 ms, sj 15.9 -> 15.2 ms; the shared meshes within
  /// +-2.5% (warped_hexahedron_o2, 27% nonzero, included).
  template <int NX>
  void four_rows_times_points(std::size_t b, const double* d, Lanes<4>* out) const {
    const double* g = dense4.data() + b * columns * 4;
    for (int a = 0; a < NX; ++a) out[a] = Lanes<4>{};
    for (std::size_t i = 0; i < columns; ++i) {
      const Lanes<4> e = load_lanes<4>(g + 4 * i);
      for (int a = 0; a < NX; ++a) out[a] += e * d[3 * i + static_cast<std::size_t>(a)];
    }
  }

  std::size_t rows() const { return start.size() - 1; }

  /// Every row times d: out[a * rows() + r] = row_times_points(r, d)[a], where flat (every
  /// d[3 i + 2] is 0) out[2 * rows() + r] = +0 without computing it. Four rows at a time
  /// where every d is finite (`finite`: the same bits), row by row otherwise (where a zero
  /// entry times an infinite d would give NaN).
  void times_points(const double* d, bool flat, bool finite, double* out) const {
    const std::size_t n = rows();
    if (!finite) {
      for (std::size_t r = 0; r < n; ++r) {
        double sum[3];
        if (flat)
          row_times_flat_points(r, d, sum);
        else
          row_times_points(r, d, sum);
        for (std::size_t a = 0; a < 3; ++a) out[a * n + r] = sum[a];
      }
      return;
    }
    for (std::size_t r0 = 0; r0 < n; r0 += 4) {
      Lanes<4> sum[3] = {};
      if (flat)
        four_rows_times_points<2>(r0 / 4, d, sum);
      else
        four_rows_times_points<3>(r0 / 4, d, sum);
      for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t l = 0; l < 4 && r0 + l < n; ++l) out[a * n + r0 + l] = sum[a][l];
    }
  }
};

}  // namespace quadval
