#pragma once
// The scaled-Jacobian bound of scaled_jacobian.hpp (Paper V §3.1: sj^2 >= min_i N_i / D_i
// on a valid element, N = J^2 and D = |c_1|^2 |c_2|^2 |c_3|^2 in Bernstein form) for a
// first-order hexahedron at its root, with fixed-size formulas instead of the general
// path's product tables: its columns are bilinear, c_1 in (eta, zeta) with the four
// xi-edges as control points (halved), and likewise c_2, c_3, so
//   J   (degree 2 per axis, 27 coefficients): convex combinations of the 64 determinants
//       det[e_1, e_2, e_3] of one xi-, one eta- and one zeta-edge (weights 1, 1/2, 1/4,
//       1/8: exact),
//   |c_j|^2 (degree 2 in its two axes, 9): convex combinations of dot products of edges,
//   N, D (degree 4 per axis, 125): Bernstein products, weights C(2,i) C(2,j) / C(4,i+j),
//       computed as scaled convolutions.
// The edges' halving scales J by 8 and D by 64 and leaves N / D alone, so edges are used
// as they are. Upper bound: sj at the 8 corners (the three edges there). Most valid
// first-order hexahedra of a mesh are settled here at the default tolerance (hex_box: 99%);
// the rest go on to the general path. The check runs it four hexahedra at a time, one per
// SIMD lane, each lane with the operations of the element alone (64,000 perturbed
// hexahedra, BM_CheckLinearHexQuality, one thread: 96.6 -> 38.4 ms). Internal to
// src/analysis.
//
// Rounding (u = 2^-53), each bound rounded up, widened by 1e-12 relative and by 2^-1000 for
// gradual underflow (the edges' 1-norms must lie in [2^-100, 2^100], else the general path):
//  - an edge's coordinates: one difference each, within 1.01u of the exact ones;
//  - a determinant, as e_1 . (e_2 x e_3): within 16u T, T the sum of the magnitudes of its
//    six triple products (inputs 3.1u, the products and sums gamma_5);
//  - J: a convex combination with exact weights: within 16u T_max + gamma_8 max|det|;
//  - a dot product of edges: within 8u (|e|_1 |e'|_1); |c_j|^2: gamma_4 more of its terms;
//  - a product of coefficients with errors e_f, e_g and magnitudes m_f, m_g: within
//    e_f m_g + (m_f + e_f) e_g, and the product's own rounding (as a scaled convolution:
//    the coefficient products, sums of at most 27 terms, the division by C(4, k) per axis
//    as 3 products): gamma_40 m_f m_g (m_h for a third factor alike).

#include <optional>
#include <span>

#include "analysis/lane_vector.hpp"
#include "quadval/element_type.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// Certified bounds of sj(E) for a first-order hexahedron proven valid (J > 0 on the whole
/// element), from its root's N / D bound and corner values; nothing when a D coefficient is
/// not proven positive or upper - lower > tol (then the general path, which subdivides).
/// @param x 8 x 3 coordinates, Gmsh node order
std::optional<QualityBounds> trilinear_hex_sj_bounds(std::span<const double> x, double tol);

/// The same for kNativeLanes hexahedra, one per lane (x[3 v + k]: vertex v's coordinate k,
/// Gmsh order), each with the bits trilinear_hex_sj_bounds gives it alone (which runs the same
/// lane code, its element in both lanes of two): bit l of the result set where out[l] holds
/// lane l's bounds, the others as nothing above.
unsigned trilinear_hex_sj_lanes(const Lanes<kNativeLanes>* x, double tol, QualityBounds* out);

}  // namespace quadval
