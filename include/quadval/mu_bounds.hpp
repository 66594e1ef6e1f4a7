#pragma once
/// Certified bounds on the quality measure mu of curved elements (thesis, Paper V).
///
/// Definition. At each point of the reference element let J_p be the Jacobian matrix of
/// the element map (derivatives in Gmsh's reference coordinates, lagrange_basis.hpp;
/// 3 x dim) and J_i the constant Jacobian matrix from Gmsh's reference element to the
/// ideal element of the family:
///   triangle     equilateral triangle of side 1
///   quadrangle   unit square
///   tetrahedron  regular tetrahedron of edge 1
///   hexahedron   unit cube
///   prism        right prism on an equilateral triangle of side 1, height 1
///   pyramid      unit square base, equilateral triangular faces (apex height 1/sqrt 2)
/// (vertex i of the reference element goes to vertex i of the ideal; only the shape of the
/// ideal matters, mu being scale invariant). With W = J_p J_i^-1 (3 x dim) and
/// M = W^T W (Paper V eq. 2), the pointwise measure is
///   mu_pw = sqrt(lambda_min(M) / lambda_max(M)) = sigma_min(W) / sigma_max(W)
/// and  mu(E) = min over the element of mu_pw  when J > 0 everywhere on E,
///      mu(E) = 0                              when J <= 0 somewhere on E,
/// J the Jacobian determinant with the sign conventions of jacobian_bounds.hpp (2D
/// elements in 3D: W is 3 x 2 and the sign is that of (X_xi x X_eta) . n; `planar`
/// selects n = +z). Lines: mu = 1 when valid (W has one singular value), 0 otherwise.
/// mu is invariant under similarities of the element and under renumberings of its nodes
/// that keep the orientation (the ideal element has the symmetry group of the reference).
///
/// What is guaranteed. The node coordinates (doubles) are taken as exact. Validity is
/// first settled with jacobian_bounds() (validity goal): invalid gives [0, 0] (mu = 0);
/// undetermined gives lower = 0 and upper from values of mu_pw (tolerance_met only when
/// upper <= abs_tol). For a valid element:
///   lower <= mu(E) <= upper,
/// with every floating-point rounding accounted for:
///   - W's control values: exact rational maps from the nodes (Lagrange-to-Bézier of the
///     geometry, Bernstein derivative, degree elevation) rounded once, J_i^-1 within 3u,
///     and an a priori bound gamma_{N+dim+9} sum_c |J_i^-1| Gamma_c R on every value;
///   - subdivision: exact dyadic matrices (rounding of their sums added per level);
///   - products (Paper V Prop. 4, src/bezier/bernstein_product.hpp): convex combinations
///     of f_i g_j, error bounded by the factors' errors and gamma_k;
///   - a sign test on a control value passes only when it exceeds its error bound, and
///     every reported number is rounded outward.
/// lower: per subdomain, first the control-matrix bound (src/analysis/mu_control_bound.hpp):
///   lambda_min - r lambda_max is concave in M and M(x) is a convex combination of the
///   Bézier control matrices M_k of M = W^T W (degree 2n, Prop. 4), so
///   R >= min_k lambda_min(M_k) / lambda_max(M_k), each ratio from a certified eigenvalue
///   enclosure (closed form 2x2; 3x3: trigonometric approximation certified by Sylvester's
///   criterion, else Gershgorin at approximate eigenvectors with Ostrowski's theorem). It
///   converges quadratically under subdivision and settles almost every subdomain. A
///   subdomain's control matrices are certified only down to what settles the element.
///   Only in an element split 24 times already (48 for tetrahedra; types with the
///   certificate only: order <=
///   mu_certificate_max_order), and where that bound falls short, the exact
///   certificate: the largest r (bisection) with R >= r, R = mu_pw^2:
///   2D (Paper V §4): a^2 = q^2 / (s^2 + t^2) >= rho from the control values (§3.1), then
///      R >= (sqrt rho - 1) / (sqrt rho + 1);
///   3D: R >= r  <=>  A >= 0 and A^2 - X^2 >= 0, A and X^2 polynomials in
///      (q, p^2, det(M - qI)) or in the invariants of M (src/analysis/mu_metric.hpp), both
///      certified nonnegative from their control values (Prop. 5). This is an exact
///      pointwise equivalence (no closed form, no Newton step, nothing left unproven); it
///      replaces the (a, K) bounding box and bounding curve of Paper V §5-6, whose bounds
///      converge only linearly at a fold of the (a, K) image and lose all information on w
///      near the ideal element (w = (K - a^3 + 3a) / 2 cancels).
///   Constant W (straight-sided simplices, parallelograms, parallelepipeds, detected from
///   W's control values with their error bound): R >= the closed-form bound of one 2x2 or
///   3x3 metric (Gershgorin discs of V^T M V at approximate eigenvectors V, Ostrowski's
///   theorem for V's non-orthogonality; src/analysis/mu_constant.hpp), no subdivision.
///   Bilinear quadrangles in a plane z = const (valid, order 1 or straight-sided): mu is
///   least at a corner, so the corners' closed forms bound it, widened by the
///   straight-sided margin (src/analysis/bilinear_quad_quality.hpp, which proves it).
/// upper: the minimum over the corners of all subdomains of an upper bound of mu_pw there
///   (Rayleigh quotients of W at approximate eigenvectors of W^T W, enclosed in interval
///   fashion: lambda_min <= |W v|^2 / |v|^2 <= lambda_max for any v).
/// Pyramids (every order). Bergot's map is rational in (xi, eta, zeta), but in the cube
///   coordinates u = (xi/t + 1)/2, v = (eta/t + 1)/2, t = 1 - zeta (bezier/pyramid_basis.hpp)
///   the columns X_xi, X_eta, X_zeta of J_p (Gmsh's directions) are polynomials of degrees
///   (r-1, r, r-1), (r, r-1, r-1), (r, r, r-1) (src/analysis/pyramid_space.hpp): W is a
///   polynomial, bounded and continuous on the closed cube, and is taken there in the
///   tensor Bernstein space of degree r per axis, split like a hexahedron's. The cube minus
///   its face t = 0 maps one-to-one onto the pyramid minus its apex; the face t = 0 collapses
///   onto the apex, where J_p has no value (its limit depends on the ray (u, v)) and nothing
///   is evaluated: that face holds only the limits of W along the rays. So, with W and J
///   extended continuously to the closed cube (as the Jacobian engine takes J),
///     mu(E) = inf over the pyramid minus its apex of mu_pw = min over the closed cube,
///   because mu_pw is continuous where W is nonsingular (J > 0 on the closed cube) and the
///   points with t > 0 are dense. Every bound above is a bound of that minimum; the corner
///   values on t = 0 used by `upper` are limits of values inside the element, hence still
///   upper bounds of the infimum. A limit J <= 0 on t = 0 counts as J <= 0 (mu = 0).
/// Refinement is best-first (the subdomain with the smallest lower bound is halved by one
/// bisection, src/bezier/bernstein_bisection.hpp; dim bisections count as one
/// subdivision) until upper - lower <= abs_tol or max_subdivisions subdivisions were
/// made; tolerance_met says which. A first-order hexahedron is refined the same way in its
/// own kernel (src/analysis/trilinear_hex_mu.hpp), the general path taking over where that
/// fails.

#include <span>

#include "quadval/element_type.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval {

/// True when mu_bounds handles this type: every type jacobian_bounds_supported() accepts
/// (lines, triangles and quadrangles to order 10, tetrahedra, prisms and hexahedra to 4,
/// pyramids to 9; complete and incomplete). The exact degree-12n certificate exists only up
/// to mu_certificate_max_order (src/analysis/mu_space.hpp: tetrahedra 3, prisms,
/// hexahedra and pyramids 2); above, the control-matrix bound alone bounds mu.
bool mu_supported(const ElementType& type) noexcept;

/// Certified bounds of mu(E) for one element. Thread-safe (thread_local scratch) and
/// deterministic.
/// @param type    the element type; @pre mu_supported(type) (QV_ASSERT otherwise)
/// @param nodes   #nodes x 3 coordinates, Gmsh node order; @pre nodes.size() == 3 * #nodes
/// @param options abs_tol (> 0) and max_subdivisions
/// @param planar  2D only: J's sign with n = +z (jacobian_bounds.hpp)
/// Thesis, Paper V §2-4 (2D), §5 (3D quantities); see above for the 3D certificate.
QualityBounds mu_bounds(const ElementType& type, std::span<const double> nodes,
                        const QualityOptions& options, bool planar = false);

}  // namespace quadval
