#pragma once
/// Certified bounds on two shape-quality measures of curved elements:
///   mu              the minimum over the element of sqrt(lambda_min / lambda_max) of the
///                   metric W^T W, W = J_p J_i^-1 (thesis, Paper V, eq. 2): mu_bounds.hpp
///   scaled Jacobian the minimum over the element of det / (product of column norms) of
///                   the Jacobian matrix (thesis line 445): scaled_jacobian.hpp
/// This header holds what the two share.
/// Both are refined by Bézier expansion and adaptive subdivision until upper - lower is
/// within the tolerance, with the same engine as the Jacobian bounds (jacobian_bounds.hpp).
///
/// Guarantee: lower <= the exact minimum of the measure over the element <= upper, the
/// node coordinates (doubles) being taken as exact. What is proven, and how rounding is
/// accounted for, is stated in each measure's header.

#include <span>

#include "quadval/element_type.hpp"

namespace quadval {

struct QualityOptions {
  /// Stop refining an element when upper - lower <= abs_tol (both measures are at most 1).
  double abs_tol = 1e-3;
  /// Subdivisions per element (where a subdomain is halved at a time, dim halvings count
  /// as one); reaching it leaves bounds wider than asked (tolerance_met = false), still
  /// certified.
  int max_subdivisions = 1000;
};

struct QualityBounds {
  double lower = 0;  ///< certified: lower <= min of the measure over the element
  double upper = 0;  ///< certified: min of the measure over the element <= upper
  int subdivisions = 0;
  bool tolerance_met = false;
};

}  // namespace quadval
