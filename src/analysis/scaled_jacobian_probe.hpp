#pragma once
// A certified upper bound of sj(E) at one point found by a local search, for elements
// where J <= 0 was found (scaled_jacobian.hpp). Internal to src/analysis.
//
// Why: the bounds' refinement stops when its least lower bound is within the tolerance of
// its upper bound, and the upper bound comes from the subdomains' corners only. On an
// inverted element whose lower bound is already at (or near) its final value, such as the
// Hadamard floor -s where a fold turns the frame columns at right angles, the corners
// reach the minimum only by subdividing around it: quad_h0.4_o2's four most inverted
// quadrangles took 26-30 subdivisions each (a third of that mesh's scaled-Jacobian time),
// and all four settle with none once the upper bound starts at the minimum.
//
// How: sj is evaluated in floating point at the points of a coarse lattice of the
// reference domain (the degree-4 Lagrange points of each factor) and from the best of them
// a compass search on dyadic points (steps 1/8 down to 1/4096) follows it downhill. The
// value at the final point is then bounded from above with every rounding accounted for:
// each coefficient of J and of the columns is within its a priori error of the exact one
// and the Bernstein basis is nonnegative with sum 1, so the values are too; a basis value
// of one simplex factor (dimension d, degree n) is computed within n + d + 1 roundings
// (the multinomial is an exact integer, the barycentric coordinates of a dyadic point
// exact, the powers products of at most n factors), a tensor product's within one more per
// extra factor, and their sum of N terms with the coefficients within gamma_N of its terms'
// magnitudes (Higham, §3.1): in all within gamma_(N + roundings + 2) of the largest
// coefficient. A frame column sums at most three columns (two more roundings). Only where J
// is negative there, with all its error, does the point give a bound:
// s_lo J_hi / prod (|v| + sqrt(3) e).

#include <array>
#include <span>

#include "analysis/scaled_jacobian_quotient.hpp"
#include "analysis/scaled_jacobian_space.hpp"

namespace quadval {

/// The point a local search ends at (Bézier-domain coordinates, factor by factor: a
/// triangle's (xi_1, xi_2), a quadrangle's (u, v) in [0, 1]^2, a prism's (xi_1, xi_2, t))
/// and a certified upper bound of sj there, or 0 where J < 0 is not certain there (sj(E) <= 0
/// is known on these elements).
struct SjProbe {
  double upper = 0;
  std::array<double, 3> point{};
};

/// The local search from the lattice's best point; it stops early at a point whose
/// estimate is at most `enough` (e.g. a known lower bound plus half the tolerance: the
/// bounds need no better). @pre the element is 3D or planar 2D (|V_k| = |J|), in.j and
/// in.col as for signed_quotient_bounds
SjProbe probe_scaled_jacobian(const ScaledJacobianSpace& space, const QuotientInput& in, double enough);

/// The same from an element's nodes (tests). @pre type.dim >= 2, planar when 2D
SjProbe scaled_jacobian_probe(const ElementType& type, std::span<const double> nodes, double enough);

}  // namespace quadval
