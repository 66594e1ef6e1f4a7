#pragma once
// Fast certified path for first-order elements (issue 3, speed): the Bézier coefficients
// of J written directly from the vertices, with an a priori rounding-error bound, for
// whole chunks of elements at once (structure of arrays, no allocation, vectorisable).
// Internal to src/analysis. Elements whose sign the coefficients do not settle are left
// to the general path (jacobian_bounds.cpp), which is unchanged.
//
// J is the same J as the general path (jacobian_bounds.hpp), in Gmsh reference
// coordinates: the [-1, 1] directions of quadrangles and hexahedra contribute an exact
// factor 1/2 each. Degrees (Paper III Table 1): linear triangle and tetrahedron J is
// constant; bilinear quadrangle (1,1); trilinear hexahedron (2,2,2), 27 coefficients;
// first-order pyramid (1,1) in (u, v) (Paper IV §4.1 says (2,2); see below), 4.
//
// Hexahedron, on [0,1]^3 with vertex X_abc (a, b, c in {0,1}; Gmsh node order 0..7 is
// abc = 000 100 110 010 001 101 111 011): with the edge vectors
//   eu_bc = X_1bc - X_0bc,  ev_ac = X_a1c - X_a0c,  ew_ab = X_ab1 - X_ab0,
// X_u = sum_bc eu_bc B_b(v) B_c(w) (B_0 = 1-t, B_1 = t), likewise X_v, X_w, so
//   J = sum det[eu_bc, ev_a'c', ew_a"b"] B_a'(u) B_a"(u) B_b(v) B_b"(v) B_c(w) B_c'(w),
// and B_i B_j = B^2_{i+j} / binom(2, i+j) gives the degree-(2,2,2) coefficient
//   c_ijk = mean over {a' + a" = i, b + b" = j, c + c' = k} of det[eu_bc, ev_a'c', ew_a"b"]
// (1, 2, 4 or 8 determinants), times 1/8 for Gmsh's [-1,1]^3. Corner coefficients (i, j,
// k in {0, 2}) are single determinants: the values of J at the vertices.
// Quadrangle likewise: c_ab = (eu_b x ev_a) . z / 4, each a corner value.
//
// Pyramid (5 nodes; Paper IV §4.1: J depends only on xi/(1-zeta), eta/(1-zeta)). In the
// cube coordinates of bezier/pyramid_basis.hpp, t = 1 - zeta, u = (xi/t + 1)/2,
// v = (eta/t + 1)/2, Bergot's first-order map is x = t B(u, v) + (1 - t) A, with A the
// apex (node 4) and B(u, v) = sum_ab P_ab B_a(u) B_b(v) the bilinear map of the base
// (P_ab: Gmsh nodes 0..3 as for the quadrangle). Then x_u = t B_u, x_v = t B_v,
// x_t = B - A, and d(xi, eta, zeta)/d(u, v, t) has determinant (2t)(2t)(-1) = -4 t^2, so
//   J = t^2 det[B_u, B_v, B - A] / (-4 t^2) = det[B_u, B_v, A - B] / 4
// for every t in (0, 1] (the apex excluded). Paper IV counts degree (2, 2) in (u, v) (9
// coefficients), but J is bilinear: B_u does not depend on u, B_v = B_v(0) + u B_uv and
// A - B = (A - B(0, v)) - u B_u, so
//   det[B_u, B_v, A - B] = det[B_u, B_v(0) + u B_uv, A - B(0, v)]   (det[B_u, ., B_u] = 0)
// is linear in u, and likewise in v. Its degree-(1, 1) Bézier coefficients are its values
// at the corners, i.e. along the four lateral edges: with eu_b = P_1b - P_0b,
// ev_a = P_a1 - P_a0, w_ab = A - P_ab,
//   c_ab = det[eu_b, ev_a, w_ab] / 4   (index a + 2 b),
// and min J over the pyramid is min c_ab exactly: the fast path decides every pyramid
// whose corner values are not within err of 0, both ways, with jmin known to 2 err. (The
// degree-(2, 2) coefficients of the enriched basis are these, degree-elevated.) The
// reference pyramid, P_ab = (2a-1, 2b-1, 0), A = (0, 0, 1): det[(2,0,0), (0,2,0),
// (1-2a, 1-2b, 1)] / 4 = 1.
//
// Rounding-error bound (u = 2^-53, no underflow or overflow; see below). A computed edge
// is e (1 + d), |d| <= u. A 3x3 determinant a . (b x c) computed from computed edges
// differs from the exact one by at most gamma_5 perm|A~| + gamma_3 perm|A| <= 8.01 u P,
// P = ||a||_1 ||b||_1 ||c||_1 >= perm|A| (each of the 6 products suffers at most 5
// roundings; the edges add 3 more relative errors). Summing m <= 8 such determinants and
// scaling by 2^-k (exact) adds gamma_7 max|det~| <= 7.01 u (1 + 8.01 u) P. So every
// coefficient is within 15.1 u P of the exact one, P = Lu Lv Lw with L the largest 1-norm
// of an edge of that direction. The computed P~ (two roundings in each 1-norm, two in
// the product) satisfies P <= (1 + 9u) P~; we use err = 32 u P~ times the reference
// scaling, rounded up: a margin of 2 that also covers the gradual-underflow case below.
// Tetrahedron (one determinant, 8.01 u P) and triangle (a 2x2 determinant, 4.01 u P) use
// the same err = 32 u P~. Pyramid: one determinant per coefficient, of three computed
// differences (eu, ev, w: one rounding each), so 8.01 u P as for the tetrahedron, times
// the exact 1/4: err = 32 u P~ / 4, P~ = Lu Lv Lw, Lw the largest 1-norm of the w_ab.
// Underflow/overflow: the fast path is taken only when every L lies in [2^-200, 2^200];
// then an underflowing product (absolute error <= 2^-1075) times a factor <= 2^200 costs
// <= 2^-870 << u P (P >= 2^-600), and nothing overflows; otherwise (or for a non-finite
// coordinate) the element goes to the general path.
// Outward rounding: err is rounded up, and every bound built from a coefficient and err
// is rounded one ulp outward (next_up / next_down, outward_rounding.hpp).
#include <cstddef>

#include "analysis/lane_vector.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {

/// The first-order types with a fast path (check_mesh, validity goal).
enum class LinearKind : std::uint8_t { none, triangle, quadrangle, tetrahedron, hexahedron, pyramid };

/// The fast-path kind of `type`: triangles and quadrangles only when `planar` (J with n =
/// +z; the general path's unit normal of a non-planar element is not handled here).
LinearKind linear_kind(const ElementType& type, bool planar) noexcept;

/// Number of vertices (2D: x, y only are read) of a kind.
int linear_num_vertices(LinearKind kind) noexcept;

/// Largest chunk linear_validity_chunk accepts.
inline constexpr std::size_t kLinearChunk = 256;
/// Distance between the rows of its coordinates (soa below): a chunk and a cache line more,
/// so that the rows do not map to the same few sets of the L1 cache, as rows 2 KiB apart
/// do (an element's 24 hexahedron coordinates then evicted each other while gathered).
inline constexpr std::size_t kLinearRow = kLinearChunk + 8;

/// Bézier coefficients of J of one first-order element and their common error bound.
/// @param nodes  #vertices x 3 coordinates, Gmsh node order
/// @param coeffs out: 1 (triangle, tetrahedron), 4 (quadrangle, and pyramid in (u, v):
///               index a + 2 b) or 27 (hexahedron: index i + 3 j + 9 k) coefficients
/// @return err with |coeffs[n] - exact| <= err for every n, or +inf when outside the
///         range where the bound holds (then the coefficients are not to be used)
double linear_jacobian_coefficients(LinearKind kind, const double* nodes, double* coeffs) noexcept;

/// J's coefficient of kNativeLanes tetrahedra or triangles (kind) from their edges
/// (edges[3 c + j]: coordinate j of x_{c+1} - x_0, computed from the nodes; c < 3 or 2),
/// lane by lane: linear_jacobian_coefficients(kind, ...) of each element alone, the same
/// bits wherever that returns a finite err (elsewhere err is +inf or NaN).
/// @param j out: the coefficients
/// @return the error bounds
Lanes<kNativeLanes> linear_simplex_jacobian_lanes(LinearKind kind, const Lanes<kNativeLanes>* edges,
                                                  Lanes<kNativeLanes>& j) noexcept;

/// The fast validity check of a chunk of first-order elements.
/// @param soa     coordinates by vertex, axis, element: soa[(v * 3 + axis) * row + e],
///                #vertices * 3 rows (entries e >= count are read, in groups of 8, and their
///                results dropped: any values will do)
/// @param count   elements, at most kLinearChunk
/// @param out     count results; out[e] is written only where decided[e]
/// @param decided out: true where the coefficients settled the sign: valid (stage 1, all
///                coefficients > err) or invalid (stage 0, a vertex value proven <= 0).
///                Bounds are as the general path's stage-1 bounds: jmin in [min c - err,
///                min vertex c + err], jmax in [max vertex c - err, max c + err], outward.
/// @param margins optional, kLinearChunk entries (as soa, those past count are read):
///                element e's J differs from its vertices' first-order J by at most
///                margins[e] (straight_sided.hpp), which widens err; +inf decides nothing
/// @param row     distance between the rows of soa, >= count rounded up to a multiple of 8
void linear_validity_chunk(LinearKind kind, const double* soa, std::size_t count,
                           JacobianBounds* out, bool* decided, const double* margins = nullptr,
                           std::size_t row = kLinearRow) noexcept;

}  // namespace quadval
