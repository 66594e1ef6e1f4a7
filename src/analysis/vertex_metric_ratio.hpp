#pragma once
// Bounds of R = lambda_min / lambda_max of M = W^T W over an element whose W has degree 1
// in each factor of its reference domain (a first-order pyramid in cube coordinates, a
// first-order prism), from W's control values at the domain's vertices alone, in SIMD
// lanes (symmetric3_lanes.hpp). Internal to src/analysis; used by linear_pyramid_mu.cpp
// and linear_prism_mu.cpp (trilinear_hex_mu.cpp does the same with the hexahedron's own
// faster products).
//
// M has degree 2 in each factor: its control value at a point p is the mean of
// W(q)^T W(q') over the vertex pairs (q, q') whose multi-indices sum to p (Paper V Prop. 4;
// a simplex factor's pair (i, j) gives e_i + e_j, a line's gives l + l'). The lower bound is
// the least certified ratio of those control matrices (the concavity argument of
// mu_control_bound.hpp); the upper bound, Rayleigh quotients of W at the vertices (values
// of W there), at the eigenvectors of their metrics (the control values at the points
// q + q).
//
// Rounding: each control value is a mean of at most 4 sums of 3 products, within gamma_10
// of their terms' magnitudes (at most 3 b^2, b >= every |W| entry), plus the propagated
// entry errors 3 (2 b + delta) delta.
#include <array>

#include "analysis/lane_vector.hpp"
#include "analysis/straight_simplex_mu.hpp"
#include "quadval/error.hpp"

namespace quadval {

struct CertifiedRatio {
  double lower = 0, upper = 1;  ///< lower <= min R <= upper over the element, where ok
  bool ok = false;              ///< false: a certification failed; use the general path
};

/// The vertices and M's control points of a reference domain, and the lane slots of the
/// points: the vertices' own points (q + q) first, slot q for vertex q, then the others;
/// the spare slots of the last block of 8 repeat slot 0.
struct VertexProducts {
  static constexpr int kSlots = 32;
  int vertices = 0;  ///< at most 8
  int points = 0;    ///< M's control points, at most kSlots
  int slots = 0;     ///< points rounded up to whole blocks of 8
  /// Per slot: the vertex pairs (q, q') summing to its point, as q * vertices + q' (at most 4),
  /// their count, and 1 / count.
  std::array<std::array<int, 4>, kSlots> pairs{};
  std::array<int, kSlots> pair_count{};
  std::array<double, kSlots> inverse_count{};
};

/// The domain with these vertices and points, pair_point(q, q') the point of a pair.
template <class PairPoint>
VertexProducts vertex_products(int vertices, int points, PairPoint pair_point) {
  VertexProducts d;
  d.vertices = vertices;
  d.points = points;
  d.slots = (points + 7) / 8 * 8;
  std::array<int, VertexProducts::kSlots> slot_point{};
  std::array<bool, VertexProducts::kSlots> placed{};
  int s = 0;
  for (int q = 0; q < vertices; ++q) {
    slot_point[static_cast<std::size_t>(s++)] = pair_point(q, q);
    placed[static_cast<std::size_t>(pair_point(q, q))] = true;
  }
  for (int p = 0; p < points; ++p)
    if (!placed[static_cast<std::size_t>(p)]) slot_point[static_cast<std::size_t>(s++)] = p;
  for (; s < d.slots; ++s) slot_point[static_cast<std::size_t>(s)] = slot_point[0];
  for (s = 0; s < d.slots; ++s) {
    auto& count = d.pair_count[static_cast<std::size_t>(s)];
    for (int q = 0; q < vertices; ++q)
      for (int r = 0; r < vertices; ++r)
        if (pair_point(q, r) == slot_point[static_cast<std::size_t>(s)]) {
          QV_ASSERT(count < 4, "more than 4 vertex pairs at a point");
          d.pairs[static_cast<std::size_t>(s)][static_cast<std::size_t>(count++)] = q * vertices + r;
        }
    d.inverse_count[static_cast<std::size_t>(s)] = 1.0 / count;
  }
  return d;
}

/// R's bounds from W's control values w[j][q][c] (column j, vertex q, coordinate c), each
/// within delta of the exact one, every |entry| at most b. Not ok where a vertex's metric
/// is not certified positive definite or its eigenvalue step fails; lower is 0 where
/// another control matrix is not certified positive definite.
CertifiedRatio vertex_metric_ratio(const VertexProducts& domain, const double (*w)[8][3], double delta, double b);

/// The lane part of vertex_metric_ratio, for callers with their own products
/// (trilinear_hex_mu.cpp): R's bounds from M's control values m[e][s] (entries m00, m11,
/// m22, m01, m02, m12; slot s, vertex q's own point at slot q, `slots` a multiple of 8),
/// each within err of the exact one, and W's vertex values w[j][q][c] within delta. A
/// caller for whom a lower bound of `enough` settles the question gets no higher one where
/// the cheap test alone proves that.
CertifiedRatio control_matrix_ratio(const double (*m)[VertexProducts::kSlots], int slots, int vertices,
                                    const double (*w)[8][3], double err, double delta, double enough = 1);

/// columns_ratio's closed form for a constant W, one element per lane (col[c][q][k]: its
/// column c at vertex q < vertices, coordinate k; rounding[c] as columns_ratio's): bit l of
/// ok is set where lane l's columns agree at every vertex to 1e-9 of their largest entry and
/// the closed form succeeds; its bounds are then those of columns_ratio, which takes them
/// from here (the element in both lanes of W = 2) where also lower <= upper.
template <int W>
StraightSimplexRatio<W> constant_columns_ratio(const Lanes<W> (*col)[8][3], int vertices, const Lanes<W>* rounding,
                                               const std::array<double, 9>& jinv);
extern template StraightSimplexRatio<2> constant_columns_ratio<2>(const Lanes<2> (*)[8][3], int, const Lanes<2>*,
                                                                  const std::array<double, 9>&);
extern template StraightSimplexRatio<kNativeLanes> constant_columns_ratio<kNativeLanes>(
    const Lanes<kNativeLanes> (*)[8][3], int, const Lanes<kNativeLanes>*, const std::array<double, 9>&);

/// R's bounds for W = J Jinv (any common scale of J), from J's columns' control values at
/// the vertices, col[c][q][k], each entry within rounding[c] of the exact one. Where the
/// columns agree at every vertex to 1e-9 (W constant: a pyramid's parallelogram base, a
/// prism's translated top), the closed form of straight_simplex_mu.hpp with each column's
/// spread as its margin; else W's control values (a sum of 3 products per entry, within
/// sum_c |Jinv_cj| (rounding[c] + 4u |col_c|)) go to vertex_metric_ratio.
CertifiedRatio columns_ratio(const VertexProducts& domain, const double (*col)[8][3], const double* rounding,
                             const std::array<double, 9>& jinv);

}  // namespace quadval
