#pragma once
// Samples of the Jacobian determinant at the Lagrange points of its Bézier space, for many
// elements of one type at once (matrix-matrix products, DESIGN.md "Batching"), each with
// an a priori bound on its rounding error; and the same in exact rational arithmetic.
// Thesis, Paper III §4.4 (Algorithm 2, lines 1-2).
#include <gmpxx.h>

#include <array>
#include <span>
#include <vector>

#include "analysis/jacobian_space.hpp"

namespace quadval {

/// The reference vector of a 1D or 2D element (jacobian_bounds.hpp): unit tangent
/// (x1 - x0) of a line; for 2D, +z when planar, else the unit normal of the straight-sided
/// element. Zero when degenerate. Unused (zero) for 3D elements.
/// @param nodes #nodes x 3 of one element
std::array<double, 3> reference_direction(const ElementType& type, const double* nodes,
                                          bool planar) noexcept;

/// Scratch of jacobian_samples, reused across calls.
struct SampleScratch {
  std::vector<double> coords;  // #nodes x (3 * count), column-major
  std::vector<double> deriv[3];
  ProductScratch product;       // spaces without sample gradients
  std::vector<double> coeffs, transposed, scratch;
};

/// J at every sample of every element of a batch, and a bound on each element's error.
/// Spaces without sample gradients (JacobianSpace::has_sample_gradients) evaluate the
/// product coefficients (jacobian_product.hpp) at the points instead; `tight` is then moot.
/// @param nodes   count x #nodes x 3 coordinates (Gmsh node order)
/// @param samples out: count x num_samples (element-major)
/// @param errors  out: count; |computed - exact| <= errors[e] for every sample of e
/// @param planar  2D: n = +z
/// @param tight   bound each sample from its own derivative magnitudes (about 3x the
///                work of the samples, far sharper for elements much smaller than
///                (Gamma R)^dim); else one cheap bound per element from Gamma R
void jacobian_samples(const JacobianSpace& space, SampleMap map, const double* nodes,
                      std::size_t count, bool planar, double* samples, double* errors,
                      SampleScratch& scratch, bool tight = false);

/// Exact J at every sample of one element, from its double coordinates as exact rationals.
/// @param nodes #nodes x 3
/// @pre space.has_sample_gradients()
std::vector<mpq_class> exact_jacobian_samples(const JacobianSpace& space, const double* nodes,
                                              bool planar);

}  // namespace quadval
