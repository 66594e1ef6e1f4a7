#pragma once
// Values of J at the midpoints of the domain: the points a first midpoint subdivision makes
// vertices (each factor at a vertex or an edge midpoint, not all at vertices: the edge
// midpoints of a simplex, and the edge, face and cell centres of a quadrangle or
// hexahedron). Curved elements with J <= 0 inside show it there more often than at the
// corners (quad_h0.4_o2: all 28 invalid elements), and a probe costs a few sums of
// coefficients where a subdivision costs a bisection and its bookkeeping. Internal to
// src/analysis.
//
// At an edge midpoint of a simplex factor of degree n only the coefficients on that edge
// count, with the weights C(n, k) / 2^n (vertex: the vertex coefficient, weight 1); a
// tensor point multiplies its factors' weights. The weights are nonnegative and sum to 1,
// so with coefficients within err of the exact ones the value is within err plus the
// rounding of the sum, bounded by gamma(2 terms + 8) * sum w |c| (covering the weights'
// own roundings, a few u relative).
#include <vector>

#include "quadval/bezier_basis.hpp"

namespace quadval {

/// The probe points of a basis as sparse rows: point p has the terms [first[p], first[p + 1])
/// of (index, weight); gamma bounds the rounding of the longest row (see above).
struct MidpointProbeTable {
  std::vector<int> first{0};
  std::vector<int> index;
  std::vector<double> weight;
  double gamma = 0;
};

/// Builds the table of a basis. midpoint_probe_upper takes the common bases' tables from
/// those generated at build time (product_tables.hpp), which tools/gen_product_tables.cpp
/// makes with this function.
MidpointProbeTable build_midpoint_probe_table(const BezierBasis& basis);

/// A certified upper bound of min J over the probe points (+inf when the basis has none):
/// J <= 0 is proven at one of them when it is <= 0.
/// @param coeffs basis.size() Bézier coefficients of J, each within err of the exact ones
double midpoint_probe_upper(const BezierBasis& basis, const double* coeffs, double err);

}  // namespace quadval
