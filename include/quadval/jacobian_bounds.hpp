#pragma once
/// Certified bounds on the Jacobian determinant J of curved elements: validity and
/// distortion. Thesis, Paper III (§2 eq. 3, §4 eqs. 13-22, Algorithms 2-3).
///
/// What J is, per element (derivatives in Gmsh's reference coordinates, lagrange_basis.hpp):
///   3D elements          J = det [X_xi, X_eta, X_zeta]
///   2D elements          J = (X_xi x X_eta) . n, with n = +z when every node of the block
///                        has the same z (planar: J = x_xi y_eta - x_eta y_xi), else n the
///                        unit normal of the straight-sided element as computed in double:
///                        triangle (x1-x0) x (x2-x0), quadrangle (x2-x0) x (x3-x1)
///   1D elements          J = X_xi . t, t the unit vector (x1 - x0) as computed in double
/// A degenerate straight-sided element (n or t zero) gets J = 0: invalid.
///
/// What is guaranteed. J is the exact polynomial defined by the node coordinates as given
/// (doubles, taken as exact) and the exact shape functions. Then, for every element:
///   jmin_lower <= min J <= jmin_upper   and   jmax_lower <= max J <= jmax_upper,
/// with every floating-point rounding accounted for:
///   - J's Bézier coefficients are Bernstein products (Paper V Prop. 4) of the control
///     points of the derivatives of the map, which are exact linear maps of the nodes
///     (computed once per type in rational arithmetic and rounded to double): an a priori
///     bound from the rounded maps' row sums, the node-coordinate range of the element and
///     the rounding of the products and sums (src/analysis/jacobian_product.cpp);
///   - subdivision: exact dyadic matrices, nonnegative rows summing to 1, so each level
///     adds only the rounding of its sums (relative to the largest coefficient);
///   - bounds are finally rounded outward (nextafter).
/// valid means min J > 0 was proven; invalid means a point with J <= 0 was proven (a
/// corner coefficient, i.e. a value of J, is <= 0). When rounding alone keeps the sign
/// open, the element is redone in exact rational arithmetic (GMP) from the same doubles.
/// undetermined means the subdivision limit was reached first; it is never folded into
/// valid or invalid.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "quadval/element_type.hpp"

namespace quadval {

enum class Validity : std::uint8_t { valid, invalid, undetermined };

/// "valid", "invalid", "undetermined"
const char* validity_name(Validity v) noexcept;

enum class BoundsGoal : std::uint8_t {
  validity,  ///< stop as soon as the sign of min J is settled (Algorithm 2-3)
  measure,   ///< also refine min J and max J until their gaps meet the tolerance
};

struct BoundsOptions {
  BoundsGoal goal = BoundsGoal::validity;
  /// measure: stop when upper - lower <= max(abs_tol, rel_tol * max(|jmin_upper|,
  /// |jmax_lower|)) for both min J and max J (and the sign of min J is settled).
  double abs_tol = 0;
  double rel_tol = 1e-2;
  /// Subdivisions per element and per refined quantity (the refinement halves one
  /// subdomain at a time by an edge bisection; dim halvings count as one subdivision);
  /// reaching it gives undetermined (validity) or bounds wider than asked (measure).
  int max_subdivisions = 1000;
  /// Redo an element in exact rational arithmetic when rounding keeps its sign open.
  bool exact_fallback = true;
  /// validity: answer in one pass over the first Bézier coefficients when they decide it
  /// (bit-identical to the general path, which tests compare it with by turning this off).
  bool one_pass_decision = true;
};

struct JacobianBounds {
  double jmin_lower = 0, jmin_upper = 0;  ///< certified: jmin_lower <= min J <= jmin_upper
  double jmax_lower = 0, jmax_upper = 0;  ///< certified: jmax_lower <= max J <= jmax_upper
  /// Mean of J over the reference element (the mean of its Bézier coefficients): an
  /// estimate, within the coefficients' rounding error.
  double javg = 0;
  Validity validity = Validity::undetermined;
  int subdivisions = 0;  ///< subdivisions (for min J, plus for max J when measuring)
  /// Which stage decided validity (Paper III Table 2): 0 the samples (values of J: at the
  /// sample points, the corners, or, in validity checks, the midpoints a first subdivision
  /// would reach), 1 the first Bézier coefficients, 1 + k after k levels of subdivision;
  /// -1 when undetermined.
  int stage = -1;
  bool exact = false;           ///< the exact-arithmetic fallback decided the sign
  bool tolerance_met = true;    ///< measure goal: both gaps within the tolerance
};

/// Scratch memory of the engine: one per thread, reused across elements (STYLE.md §8).
class BoundsWorkspace {
 public:
  BoundsWorkspace();
  ~BoundsWorkspace();
  BoundsWorkspace(const BoundsWorkspace&) = delete;
  BoundsWorkspace& operator=(const BoundsWorkspace&) = delete;
  struct Impl;
  Impl& impl() noexcept { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// True when jacobian_bounds handles this type: Lagrange lines, triangles, quadrangles,
/// tetrahedra, prisms, hexahedra (complete and incomplete) up to max_supported_order, and
/// Bergot's pyramids of orders 1 to 9 (Paper IV: the pyramid as a shrunk cube, whose map
/// is a polynomial in the cube coordinates; src/analysis/pyramid_space.hpp).
bool jacobian_bounds_supported(const ElementType& type) noexcept;

/// Certified bounds of J for one element.
/// @param type   the element type; @pre jacobian_bounds_supported(type)
/// @param nodes  #nodes x 3 coordinates, Gmsh node order
/// @param planar 2D only: use n = +z (see above) instead of the element's own normal
JacobianBounds jacobian_bounds(const ElementType& type, std::span<const double> nodes,
                               const BoundsOptions& options, BoundsWorkspace& workspace,
                               bool planar = false);

/// Bounds of the distortion delta = J / J_straight (Paper III eq. 3), J_straight the
/// Jacobian of the straight-sided element through the vertices (same definition of J).
struct DistortionBounds {
  double lower = 0;  ///< certified lower bound of min delta (NaN when J_straight is not
                     ///< proven positive: inverted or degenerate straight element)
  double upper = 0;  ///< certified upper bound of min delta (a value of delta), or NaN
};

/// Distortion bounds of one element. Simplices: J_straight is constant, so the Jacobian
/// bounds `jb` divide exactly. Quadrangles, prisms, hexahedra and pyramids: J / J_straight is
/// a rational function, whose minimum is refined best-first from the Bézier coefficients
/// of J and J_straight (min_i b_i / c_i <= min J / J_straight when every c_i > 0; Paper V
/// §3.1) until upper - lower <= max(options.abs_tol, options.rel_tol * |upper|) or
/// options.max_subdivisions subdomains were split (then the bounds are wider, still certified).
DistortionBounds distortion_bounds(const ElementType& type, std::span<const double> nodes,
                                   const JacobianBounds& jb, BoundsWorkspace& workspace,
                                   bool planar = false, const BoundsOptions& options = {});

}  // namespace quadval
