#pragma once
// The adaptive engine: best-first subdivision of Bézier coefficients with certified
// (rounding-aware) bounds, and its exact rational twin. Thesis, Paper III §4.2 (eqs. 20-22)
// and Algorithms 2-3, refined best-first as issue 3 asks (split the subdomain holding the
// smallest coefficient).
#include <gmpxx.h>

#include <limits>
#include <vector>

#include "bezier/bernstein_bisection.hpp"
#include "analysis/jacobian_samples.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {

struct BoundsWorkspace::Impl {
  struct Leaf {
    double lower;  // certified lower bound of the polynomial on this subdomain
    double err;    // |computed - exact| bound of every coefficient
    int slot;      // coefficients at pool[slot * size]
    int depth;     // subdivisions from the root (levels halvings make one)
    BisectionState state;
  };
  SampleScratch sample_scratch;
  std::vector<double> samples, errors, coeffs, scratch, straight_samples, straight_coeffs;
  std::vector<double> tight_samples, tight_coeffs, first_coeffs;
  std::vector<double> pool;
  std::vector<int> free_slots;
  std::vector<Leaf> heap;
  // The bisection of the last basis refined (a lookup per element, a key vector, a lock
  // and a map, was a tenth of the subdivision stage on quad_h0.4_o2).
  const BezierBasis* bisection_basis = nullptr;
  const BernsteinBisection* bisection = nullptr;
};

/// Result of refining the minimum of a polynomial given by Bézier coefficients.
struct MinRefinement {
  double lower = 0;          // certified lower bound of the minimum
  double upper = 0;          // certified upper bound of the minimum (a value)
  int subdivisions = 0;
  int depth = 0;             // deepest subdivision level created
  bool settled = false;      // stop criterion met (sign and/or tolerance)
  bool rounding_limited = false;  // a split leaf had its minimum within 8 err of zero
};

/// Refines min of sum b_i B_i best-first.
/// @param coeffs    size() coefficients, each within err of the exact ones
/// @param need_sign stop only once lower > 0 or upper <= 0
/// @param tol       stop only once upper - lower <= tol (infinity: no tolerance)
MinRefinement refine_minimum(const BezierBasis& basis, const double* coeffs, double err,
                             bool need_sign, double tol, int max_subdivisions,
                             BoundsWorkspace::Impl& ws);

/// Exact Bézier coefficients from exact samples (factor by factor, exact T).
std::vector<mpq_class> exact_to_bezier(const BezierBasis& basis, std::vector<mpq_class> samples);

/// Exact validity by the same best-first subdivision in rational arithmetic.
struct ExactRefinement {
  Validity validity = Validity::undetermined;
  mpq_class lower, upper;  // exact bounds of min J at the end
  int subdivisions = 0;
  int depth = 0;
};
ExactRefinement exact_validity(const BezierBasis& basis, std::vector<mpq_class> coeffs,
                               int max_subdivisions);

/// The whole per-element analysis from batched samples (Algorithm 2, then refinement;
/// exact fallback when rounding keeps the sign open).
/// @param samples num_samples values of J, each within err of the exact one
/// @param nodes   the element's #nodes x 3 coordinates (for the exact fallback)
/// @param root_coeffs the samples' Bézier coefficients when already computed (batched
///        BezierBasis::to_bezier_batch, bit-identical to to_bezier), else nullptr
JacobianBounds bounds_from_samples(const JacobianSpace& space, const double* samples,
                                   double err, const double* nodes, bool planar,
                                   const BoundsOptions& options, BoundsWorkspace::Impl& ws,
                                   const double* root_coeffs = nullptr);

/// The same from first Bézier coefficients (jacobian_coefficients, or
/// JacobianProduct::coefficients): stage 0 uses the vertex coefficients (values of J).
/// @param coeffs basis().size() coefficients of J, each within err of the exact ones
/// @pre space.product() != nullptr (for the exact fallback)
JacobianBounds bounds_from_coefficients(const JacobianSpace& space, const double* coeffs,
                                        double err, const double* nodes, bool planar,
                                        const BoundsOptions& options, BoundsWorkspace::Impl& ws);

/// Bézier coefficients of J for `count` elements of one type at once (the product path,
/// jacobian_product.hpp), element-major, with per-element error bounds: what `check`
/// feeds to bounds_from_coefficients, chunk by chunk.
/// @param nodes count x #nodes x 3; @param coeffs out: count x basis().size();
/// @param errors out: count.  @pre space.product() != nullptr
inline void jacobian_coefficients(const JacobianSpace& space, const double* nodes,
                                  std::size_t count, bool planar, double* coeffs,
                                  double* errors, ProductScratch& scratch) {
  space.product()->coefficients(SampleMap::curved, nodes, count, planar, coeffs, errors, scratch);
}

/// Distortion bounds (see jacobian_bounds.hpp) of one element with bounds jb.
DistortionBounds distortion_from(const JacobianSpace& space, const double* nodes, bool planar,
                                 const JacobianBounds& jb, BoundsWorkspace::Impl& ws,
                                 const BoundsOptions& options);


}  // namespace quadval
