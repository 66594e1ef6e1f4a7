#pragma once
/// Certified bounds on the minimum of the scaled Jacobian of curved elements, the quality
/// measure the thesis names as the most wanted extension of its method (line 445).
///
/// Definition. J_p(xi) is the Jacobian matrix of the element map (columns c_j = dX/dxi_j,
/// derivatives in Gmsh's reference coordinates, lagrange_basis.hpp) and J(xi) the Jacobian
/// determinant with the conventions of jacobian_bounds.hpp (3D det J_p; 2D (c_1 x c_2) . n
/// with n = +z when `planar`, else the straight element's unit normal; 1D c_1 . t).
/// A *frame* E_k is a constant matrix of reference edge vectors with det E_k = 1; the
/// frame's columns at xi are v_kj = J_p E_k e_j. The pointwise scaled Jacobian is
///   sj(xi) = min over frames k of  s * sign(J(xi)) * |V_k| / prod_j |v_kj|,
/// |V_k| = |det [v_k1 v_k2 v_k3]| = |J| in 3D, |v_k1 x v_k2| = |c_1 x c_2| in 2D (the area
/// of the parallelogram, not its projection on n: a curved surface element is not
/// penalised for its tilt), |v_k1 . t| in 1D; sign(0) = 0 and sj = 0 where a column
/// vanishes. Frames and the normalisation s per family:
///   quadrangle, hexahedron  E = identity: sj = det J_p / (|c_1||c_2|(|c_3|)), s = 1
///   triangle   the 3 corner frames (edges leaving corner k of the reference triangle,
///              counter-clockwise), s = 2/sqrt(3)
///   tetrahedron the 4 corner frames (edges leaving corner k, ordered to det E_k = 1),
///              s = sqrt(2)
///   prism      the 3 triangle-corner frames in (xi, eta) times the axis c_3, s = 2/sqrt(3)
///   line       E = 1: sj = (c_1 . t) / |c_1|, the cosine of the angle between the tangent
///              and the chord direction t, s = 1
///   pyramid    the 4 base-corner frames: at base vertex k of Gmsh's reference pyramid the
///              half base edges to the next and the previous base vertex and the edge to
///              the apex (e.g. corner 0: (1,0,0), (0,1,0), (1,1,1)), s = sqrt(2); at a
///              straight pyramid whose base is a parallelogram this is the minimum of the
///              four corner-tetrahedron values sqrt(2) det[e_next, e_prev, e_apex] /
///              (|e_next| |e_prev| |e_apex|). The columns are polynomials in the cube
///              coordinates (u, v, t) (mu_bounds.hpp, "Pyramids"): sj is bounded over the
///              closed cube, whose face t = 0 holds the limits along the rays into the apex
///              (the apex itself, where J_p is undefined, is never evaluated); sj(E) is the
///              infimum over the pyramid minus its apex, which is that minimum.
/// At a straight-sided simplex this is the classic corner scaled Jacobian (the frames of
/// the affinely mapped reference element are its corner edge frames). The element value
/// is sj(E) = min over the element of sj(xi).
/// Ideal value 1: unit square/cube, any rectangle/box, equilateral triangle, regular
/// tetrahedron, right prism on an equilateral triangle, the pyramid with a square base and
/// equilateral triangular faces; a parallelogram gives the sine of its angle. Range: sj <= 1 for quadrangles, hexahedra, triangles, prisms and lines (the
/// smallest corner angle of a triangle is at most 60 degrees); for tetrahedra sj <= 1
/// held on every tetrahedron we sampled (10^6 random and 10^6 near-regular ones) but we
/// know no proof, so nothing is clamped: a value is reported as computed. Below, sj >= -s
/// (Hadamard): an inverted element takes the most negative corner, e.g. -2/sqrt(3) for an
/// inverted right triangle, -sqrt(2) for an inverted corner tetrahedron. Negative values
/// mean J < 0 there. Pyramids: one corner value reaches sqrt(2) where that corner's three
/// edges are orthogonal, and sj <= 1 is not proven for the minimum over the corners
/// either: nothing is clamped, sj lies in [-sqrt(2), sqrt(2)] (Hadamard).
///
/// What is guaranteed. The node coordinates (doubles) are taken as exact. Then
///   lower <= sj(E) <= upper.
/// Method (Paper V §3.1): N = |V|^2 (= J^2 in 3D and planar 2D) and D_k = prod_j |v_kj|^2
/// are polynomials of twice the degree of J; on a subdomain where J > 0 is proven (all
/// Bézier coefficients of J positive), sj^2 >= s^2 min_k min_i N_i / D_k,i (relaxation:
/// r D_k <= N when r D_k,i <= N_i for every coefficient, all D_k,i > 0), and on any other
/// subdomain sj >= -s sqrt(max_k max_i N_i / D_k,i) (and >= -s by Hadamard). In 3D, on
/// an element not proven valid, a frame whose D_k is not proven positive on the whole
/// element also gets the Hadamard bound with its column a most likely to vanish divided
/// out: |V_k| <= |v_ka| |v_kb x v_kc|, so sj_k >= -s sqrt(max_i H_i / G_i) with H = |v_kb x
/// v_kc|^2 and G = |v_kb|^2 |v_kc|^2 (both times 1 in the space of |v_ka|^2, to reach the
/// squared space).
/// The Bézier coefficients of N, D_k and J come from Bernstein products (Paper V Prop. 4)
/// of those of the columns c_j in their own degrees, which are an exact linear map of the
/// nodes (the Jacobian product path's derivative maps, rounded once from exact
/// rationals): no ill-conditioned Lagrange-to-Bézier conversion of the high-degree space
/// is involved. Every coefficient carries an a priori bound on its rounding error (the
/// map's row sums, the products' convex weights, the averages of the bisections), and
/// every bound is rounded outward.
/// First, on an element where J > 0 is proven and |V_k| = J (3D, planar 2D, 1D), a
/// cheaper stage bounds sj >= s J_lo / prod_j max_i |V_kj,i| from J and the frame columns in
/// their own degrees (convex hull), exact on straight-sided simplices and parallelepipeds;
/// it settles the straight and barely curved elements that make up most of a curved mesh,
/// and its bounds tighten the ones below when it does not (src/analysis/
/// scaled_jacobian_quotient.hpp). On a 3D or planar 2D element where J <= 0 was found, a
/// signed first stage: sj >= s min(0, min_k min_i J_i / L_k,i) with
/// L_k = prod_j (v_kj . d_kj) <= prod_j |v_kj| (d_kj unit vectors along the columns' mean
/// directions; L_k's coefficients proven positive), in J's degree, refined a few times.
/// Either stage bounds each frame on its own; a frame whose bound is already within the
/// tolerance of the stage's upper bound is left out of the products and leaves below (on
/// warped_tetrahedron_o3: 576 of the 1,396 frames of the 349 elements that get there).
/// Before it, on valid elements, closed forms or fixed-size
/// formulas: straight-sided simplices (the edges, widened by the straight-sided margin),
/// bilinear quadrangles in a plane z = const (sj is least at a corner:
/// src/analysis/bilinear_quad_quality.hpp), first-order hexahedra (the root's N / D bound:
/// trilinear_hex_sj.hpp) and first-order pyramids (this first stage: linear_pyramid_sj.hpp);
/// where they fall short of the tolerance, the general path follows.
/// upper is the minimum of sj at points (the corners of the subdomains, where a Bézier
/// coefficient is a value), rounded up by their error bounds. Refinement is best-first
/// (the subdomain with the smallest lower bound is halved by one edge bisection,
/// bezier/bernstein_bisection.hpp; dim bisections count as one subdivision) until upper -
/// lower <= abs_tol or max_subdivisions subdivisions were made.
///
/// Folds. Where a frame column v_ka vanishes at a point p of a fold (J changes sign
/// there), D_k(p) = 0 and sj has no limit at p: the N / D_k bound stays at -s however small
/// the subdomain around p. The Hadamard bound above does not: it tends to -s sin(v_kb(p),
/// v_kc(p)), the infimum of sj_k near p when the direction of v_ka takes every value
/// there, so the refinement closes on it (mixed_h0.6_o2's folded pyramid 1419: 33
/// subdivisions to the tolerance 1e-2, where the N / D_k bound alone ended 1000
/// subdivisions at the floor). Where two
/// columns of a frame vanish at one point, even G does; the refinement then stops early,
/// with tolerance_met false and the true bounds, once the subdomain with the smallest
/// bound is proven unable to rise above the floor however far it is split: one of its
/// corners has J <= 0 (certified) and every coefficient of some D_k (and of its G, if it
/// has one) is at most its error bound (bisection never raises the largest coefficient
/// nor lowers the error bound). Only the upper bound could then still move, and it is
/// bounded below by sj(E): the stop can only end early an element whose sj(E) lies within
/// abs_tol of the floor.

#include <span>

#include "quadval/element_type.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// True when scaled_jacobian_bounds handles this type: Lagrange lines, triangles,
/// quadrangles, tetrahedra, prisms, hexahedra and pyramids (complete and incomplete) up to
/// the orders of scaled_jacobian_max_order.
bool scaled_jacobian_supported(const ElementType& type) noexcept;

/// Highest order handled per family: the Jacobian bounds' orders (max_supported_order:
/// lines, triangles and quadrangles 10, tetrahedra, prisms and hexahedra 4) and pyramids
/// 4 (columns of degree r per cube axis, N and D_k of degree 6r: 15625 coefficients per
/// vector at r = 4, 166375 at the Jacobian's r = 9); 0 for the other families. N and D_k
/// have twice the degree of J (a tetrahedron of order 4: 1330 coefficients per vector, a
/// hexahedron 12167), subdivided by bisection without matrices.
int scaled_jacobian_max_order(ElementFamily family) noexcept;

/// Certified bounds of sj(E) (definition above) for one element. Thread-safe
/// (thread_local scratch) and deterministic.
/// @param type    @pre scaled_jacobian_supported(type) (QV_ASSERT otherwise)
/// @param nodes   #nodes x 3 coordinates, Gmsh node order; @pre size 3 * #nodes
/// @param options abs_tol (> 0) and max_subdivisions
/// @param planar  2D only: n = +z for the sign of J (jacobian_bounds.hpp)
QualityBounds scaled_jacobian_bounds(const ElementType& type, std::span<const double> nodes,
                                     const QualityOptions& options, bool planar = false);

}  // namespace quadval
