// Per-element Jacobian bounds: samples -> first Bézier coefficients -> best-first
// refinement -> exact fallback (Paper III Algorithms 2-3), and the distortion (eq. 3).
#include "quadval/jacobian_bounds.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/jacobian_engine.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/midpoint_probe.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/ratio_refinement.hpp"
#include "bezier/rational_rounding.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
double down(double x) { return next_down(x); }
double up(double x) { return next_up(x); }

// Error bound of the Bézier coefficients computed from samples within err of J (see
// jacobian_bounds.hpp): norm * (err + rounding * max|sample|), rounded up.
double coefficient_error(const BezierBasis& basis, const double* samples, double err) {
  const auto s = static_cast<std::size_t>(basis.size());
  double max_abs = 0;
  for (std::size_t k = 0; k < s; ++k) max_abs = std::max(max_abs, std::abs(samples[k]));
  return up(basis.to_bezier_norm() * (err + basis.to_bezier_rounding() * max_abs) * (1 + 1e-12));
}

// Bézier coefficients of J from samples, and their error bound.
double to_bezier_with_error(const BezierBasis& basis, const double* samples, double err,
                            double* coeffs, std::vector<double>& scratch) {
  scratch.resize(2 * static_cast<std::size_t>(basis.size()));
  basis.to_bezier(samples, coeffs, scratch.data());
  return coefficient_error(basis, samples, err);
}

// a / b rounded toward -inf or +inf (b != 0).
double div_down(double a, double b) { return down(a / b); }
double div_up(double a, double b) { return up(a / b); }

}  // namespace

const char* validity_name(Validity v) noexcept {
  switch (v) {
    case Validity::valid: return "valid";
    case Validity::invalid: return "invalid";
    case Validity::undetermined: return "undetermined";
  }
  return "?";
}

BoundsWorkspace::BoundsWorkspace() : impl_(std::make_unique<Impl>()) {}
BoundsWorkspace::~BoundsWorkspace() = default;

bool jacobian_bounds_supported(const ElementType& type) noexcept {
  return jacobian_supported(type);
}

namespace {

// Bézier coefficients of J of one element by the product path, into coeffs; their error.
double product_coefficients(const JacobianSpace& space, SampleMap map, const double* nodes,
                            bool planar, std::vector<double>& coeffs, BoundsWorkspace::Impl& ws) {
  coeffs.resize(static_cast<std::size_t>(space.basis().size()));
  double err = 0;
  space.product()->coefficients(map, nodes, 1, planar, coeffs.data(), &err, ws.sample_scratch.product);
  return err;
}

// Refinement and answer from the first coefficients in ws.coeffs (error err_b), Algorithm
// 2 lines 3-12 and Algorithm 3. sample_invalid: a value of J <= 0 is already proven;
// value_upper: the smallest proven value of J so far (an upper bound of min J).
JacobianBounds bounds_from_first_coefficients(const JacobianSpace& space, double err_b,
                                              bool sample_invalid, double value_upper,
                                              const double* nodes, bool planar,
                                              const BoundsOptions& options,
                                              BoundsWorkspace::Impl& ws) {
  const BezierBasis& basis = space.basis();
  const auto s = static_cast<std::size_t>(basis.size());
  JacobianBounds out;
  const bool measuring = options.goal == BoundsGoal::measure;
  double sum = 0;
  for (double c : ws.coeffs) sum += c;
  out.javg = sum / static_cast<double>(s);

  double scale = 0;
  for (int v : basis.vertex_indices()) scale = std::max(scale, std::abs(ws.coeffs[static_cast<std::size_t>(v)]));
  const double tol = measuring ? std::max(options.abs_tol, options.rel_tol * scale) : kInf;

  MinRefinement rmin;
  if (sample_invalid && !measuring) {
    // Decided already: keep the first coefficients' bounds, no refinement.
    rmin = refine_minimum(basis, ws.coeffs.data(), err_b, false, kInf, 0, ws);
  } else {
    rmin = refine_minimum(basis, ws.coeffs.data(), err_b, true, tol, options.max_subdivisions, ws);
  }
  out.jmin_lower = rmin.lower;
  out.jmin_upper = std::min(rmin.upper, value_upper);
  out.subdivisions = rmin.subdivisions;
  out.tolerance_met = !measuring || rmin.upper - rmin.lower <= tol;

  if (measuring) {
    // max J = -min(-J): negate (exact) and refine the same way.
    std::vector<double> neg(ws.coeffs.begin(), ws.coeffs.end());
    for (double& c : neg) c = -c;
    const MinRefinement rmax =
        refine_minimum(basis, neg.data(), err_b, false, tol, options.max_subdivisions, ws);
    out.jmax_lower = -rmax.upper;
    out.jmax_upper = -rmax.lower;
    out.subdivisions += rmax.subdivisions;
    out.tolerance_met = out.tolerance_met && rmax.upper - rmax.lower <= tol;
  } else {
    double hi = -kInf, vertex_hi = -kInf;
    for (double c : ws.coeffs) hi = std::max(hi, c);
    for (int v : basis.vertex_indices()) vertex_hi = std::max(vertex_hi, ws.coeffs[static_cast<std::size_t>(v)]);
    out.jmax_upper = up(hi + err_b);
    out.jmax_lower = down(vertex_hi - err_b);
  }

  if (sample_invalid) {
    out.validity = Validity::invalid;
    out.stage = 0;
  } else if (out.jmin_lower > 0) {
    out.validity = Validity::valid;
  } else if (out.jmin_upper <= 0) {
    out.validity = Validity::invalid;
  } else {
    out.validity = Validity::undetermined;
  }
  if (!sample_invalid && out.validity != Validity::undetermined)
    out.stage = rmin.subdivisions == 0 ? 1 : 1 + rmin.depth;

  if (out.validity == Validity::undetermined && rmin.rounding_limited && options.exact_fallback) {
    const std::vector<mpq_class> exact_coeffs =
        space.product() != nullptr
            ? space.product()->exact_coefficients(SampleMap::curved, nodes, planar)
            : exact_to_bezier(basis, exact_jacobian_samples(space, nodes, planar));
    const ExactRefinement ex = exact_validity(basis, exact_coeffs, options.max_subdivisions);
    out.jmin_lower = std::max(out.jmin_lower, round_down(ex.lower));
    out.jmin_upper = std::min(out.jmin_upper, round_up(ex.upper));
    out.validity = ex.validity;
    out.exact = true;
    out.subdivisions += ex.subdivisions;
    if (ex.validity != Validity::undetermined) out.stage = ex.subdivisions == 0 ? 1 : 1 + ex.depth;
  }
  return out;
}

// Stage 0 on coefficients: a vertex coefficient is a value of J.
bool vertex_value_invalid(const BezierBasis& basis, const double* coeffs, double err,
                          double& value_upper) {
  bool invalid = false;
  for (int v : basis.vertex_indices()) {
    const double hi = up(coeffs[static_cast<std::size_t>(v)] + err);
    value_upper = std::min(value_upper, hi);
    if (hi <= 0) invalid = true;
  }
  return invalid;
}

// The validity answer when the first coefficients decide it, in one pass over them: a
// vertex value J <= 0 proven (invalid, stage 0) or every coefficient proven positive
// (valid, stage 1), nearly every element of a mesh. The same bounds, bit for bit, as
// bounds_from_first_coefficients computes for these cases (the same sums and extrema in the
// same order; refine_minimum returns its root bounds without splitting); false when a
// refinement is needed, or a coefficient is not finite.
bool decided_by_first_coefficients(const BezierBasis& basis, const double* coeffs, double err,
                                   JacobianBounds& out) {
  const auto s = static_cast<std::size_t>(basis.size());
  double lo = coeffs[0], hi = -kInf, sum = 0;
  for (std::size_t i = 0; i < s; ++i) {
    sum += coeffs[i];
    lo = std::min(lo, coeffs[i]);
    hi = std::max(hi, coeffs[i]);
  }
  double vertex_lo = kInf, vertex_hi = -kInf, value_upper = kInf;
  bool invalid = false;
  for (int v : basis.vertex_indices()) {
    const double c = coeffs[static_cast<std::size_t>(v)];
    const double value_hi = up(c + err);
    value_upper = std::min(value_upper, value_hi);
    if (value_hi <= 0) invalid = true;
    vertex_lo = std::min(vertex_lo, c);
    vertex_hi = std::max(vertex_hi, c);
  }
  if (!std::isfinite(sum) || !std::isfinite(lo) || !std::isfinite(hi)) return false;
  const double jmin_lower = down(lo - err);
  if (!invalid && !(jmin_lower > 0)) return false;
  out.javg = sum / static_cast<double>(s);
  out.jmin_lower = jmin_lower;
  out.jmin_upper = std::min(up(vertex_lo + err), value_upper);
  out.jmax_upper = up(hi + err);
  out.jmax_lower = down(vertex_hi - err);
  out.subdivisions = 0;
  out.tolerance_met = true;
  out.exact = false;
  out.validity = invalid ? Validity::invalid : Validity::valid;
  out.stage = invalid ? 0 : 1;
  return true;
}

}  // namespace

JacobianBounds bounds_from_coefficients(const JacobianSpace& space, const double* coeffs,
                                        double err, const double* nodes, bool planar,
                                        const BoundsOptions& options, BoundsWorkspace::Impl& ws) {
  if (options.goal == BoundsGoal::validity && options.one_pass_decision) {
    JacobianBounds out;
    if (decided_by_first_coefficients(space.basis(), coeffs, err, out)) return out;
  }
  const auto s = static_cast<std::size_t>(space.basis().size());
  ws.coeffs.assign(coeffs, coeffs + s);
  double value_upper = kInf;
  bool invalid = vertex_value_invalid(space.basis(), coeffs, err, value_upper);
  // Validity, where the coefficients leave the sign open: J at the midpoints before any
  // subdivision (midpoint_probe.hpp); a value J <= 0 there decides the element as a sample
  // would (stage 0).
  if (!invalid && options.goal == BoundsGoal::validity && !(down(least_value(coeffs, s) - err) > 0)) {
    value_upper = std::min(value_upper, midpoint_probe_upper(space.basis(), coeffs, err));
    invalid = value_upper <= 0;
  }
  return bounds_from_first_coefficients(space, err, invalid, value_upper, nodes, planar, options, ws);
}

JacobianBounds bounds_from_samples(const JacobianSpace& space, const double* samples,
                                   double err, const double* nodes, bool planar,
                                   const BoundsOptions& options, BoundsWorkspace::Impl& ws,
                                   const double* root_coeffs) {
  const BezierBasis& basis = space.basis();
  const auto s = static_cast<std::size_t>(basis.size());

  // Stage 0 (Algorithm 2, lines 3-4): a sample is a value of J.
  bool sample_invalid = false;
  double value_upper = kInf;
  for (std::size_t k = 0; k < s; ++k) {
    const double hi = up(samples[k] + err);
    value_upper = std::min(value_upper, hi);
    if (hi <= 0) sample_invalid = true;
  }

  // Stage 1: the first Bézier coefficients (eq. 18).
  double err_b;
  const bool measuring = options.goal == BoundsGoal::measure;
  if (!space.has_sample_gradients()) {
    // No well-conditioned conversion from samples: the product path, from the nodes.
    err_b = product_coefficients(space, SampleMap::curved, nodes, planar, ws.coeffs, ws);
    if (vertex_value_invalid(basis, ws.coeffs.data(), err_b, value_upper)) sample_invalid = true;
  } else {
    ws.coeffs.resize(s);
    if (root_coeffs != nullptr) {
      std::copy(root_coeffs, root_coeffs + s, ws.coeffs.begin());
      err_b = coefficient_error(basis, samples, err);
    } else {
      err_b = to_bezier_with_error(basis, samples, err, ws.coeffs.data(), ws.scratch);
    }
    if (measuring || !sample_invalid) {
      double lo = kInf;
      for (double c : ws.coeffs) lo = std::min(lo, c);
      if (measuring || !(down(lo - err_b) > 0)) {
        // Not settled by the cheap per-element error bound: redo this element with a
        // sharper bound before refining: the product path (per-coordinate magnitudes,
        // no conversion norm), or for pyramids the per-sample bound.
        double tight_b;
        if (space.product() != nullptr) {
          tight_b = product_coefficients(space, SampleMap::curved, nodes, planar, ws.tight_coeffs, ws);
        } else {
          ws.tight_samples.resize(s);
          double tight_err = 0;
          jacobian_samples(space, SampleMap::curved, nodes, 1, planar, ws.tight_samples.data(),
                           &tight_err, ws.sample_scratch, /*tight=*/true);
          ws.tight_coeffs.resize(s);
          tight_b = to_bezier_with_error(basis, ws.tight_samples.data(), tight_err,
                                         ws.tight_coeffs.data(), ws.scratch);
        }
        if (tight_b < err_b) {
          err_b = tight_b;
          ws.coeffs = ws.tight_coeffs;
        }
      }
    }
  }
  return bounds_from_first_coefficients(space, err_b, sample_invalid, value_upper, nodes, planar,
                                        options, ws);
}

DistortionBounds distortion_from(const JacobianSpace& space, const double* nodes, bool planar,
                                 const JacobianBounds& jb, BoundsWorkspace::Impl& ws,
                                 const BoundsOptions& options) {
  const BezierBasis& basis = space.basis();
  const auto s = static_cast<std::size_t>(basis.size());
  DistortionBounds d{std::nan(""), std::nan("")};
  // J_straight: its Bézier coefficients in J's space (the product path; pyramids: samples
  // of the straight-sided element, then converted).
  double err_c;
  if (space.product() != nullptr) {
    err_c = product_coefficients(space, SampleMap::straight, nodes, planar, ws.straight_coeffs, ws);
  } else {
    ws.straight_samples.resize(s);
    ws.straight_coeffs.resize(s);
    double err_s = 0;
    jacobian_samples(space, SampleMap::straight, nodes, 1, planar, ws.straight_samples.data(),
                     &err_s, ws.sample_scratch, /*tight=*/true);
    err_c = to_bezier_with_error(basis, ws.straight_samples.data(), err_s,
                                 ws.straight_coeffs.data(), ws.scratch);
  }
  const auto& c = ws.straight_coeffs;
  double c_lo = kInf, c_hi = -kInf;
  for (double x : c) {
    c_lo = std::min(c_lo, x);
    c_hi = std::max(c_hi, x);
  }
  c_lo = down(c_lo - err_c);
  c_hi = up(c_hi + err_c);
  if (!(c_lo > 0)) return d;  // straight element not proven positive: no distortion

  const ElementFamily f = space.type().family;
  const bool simplex = f == ElementFamily::line || f == ElementFamily::triangle ||
                       f == ElementFamily::tetrahedron;
  if (simplex) {
    // J_straight is constant: in [c_lo, c_hi].
    d.lower = div_down(jb.jmin_lower, jb.jmin_lower >= 0 ? c_hi : c_lo);
    d.upper = div_up(jb.jmin_upper, jb.jmin_upper >= 0 ? c_lo : c_hi);
    return d;
  }
  // J / J_s is a rational function: its minimum refined best-first (ratio_refinement.hpp).
  double err_b;
  if (space.product() != nullptr) {
    err_b = product_coefficients(space, SampleMap::curved, nodes, planar, ws.coeffs, ws);
  } else {
    ws.samples.resize(s);
    double err = 0;
    jacobian_samples(space, SampleMap::curved, nodes, 1, planar, ws.samples.data(), &err,
                     ws.sample_scratch, /*tight=*/true);
    ws.coeffs.resize(s);
    err_b = to_bezier_with_error(basis, ws.samples.data(), err, ws.coeffs.data(), ws.scratch);
  }
  const RatioRefinement r = refine_ratio_minimum(basis, ws.coeffs.data(), err_b, c.data(), err_c,
                                                 options.abs_tol, options.rel_tol,
                                                 options.max_subdivisions);
  if (!r.positive) return d;
  d.lower = r.lower;
  d.upper = r.upper;
  return d;
}

JacobianBounds jacobian_bounds(const ElementType& type, std::span<const double> nodes,
                               const BoundsOptions& options, BoundsWorkspace& workspace,
                               bool planar) {
  QV_ASSERT(jacobian_bounds_supported(type), "no Jacobian bounds for " << type.name);
  QV_ASSERT(nodes.size() == static_cast<std::size_t>(type.num_nodes) * 3,
            "nodes " << nodes.size() << " for " << type.name);
  const JacobianSpace& space = jacobian_space(type);
  auto& ws = workspace.impl();
  if (space.product() != nullptr) {
    std::vector<double>& coeffs = ws.first_coeffs;
    const double err = product_coefficients(space, SampleMap::curved, nodes.data(), planar, coeffs, ws);
    return bounds_from_coefficients(space, coeffs.data(), err, nodes.data(), planar, options, ws);
  }
  ws.samples.resize(static_cast<std::size_t>(space.num_samples()));
  ws.errors.resize(1);
  jacobian_samples(space, SampleMap::curved, nodes.data(), 1, planar, ws.samples.data(),
                   ws.errors.data(), ws.sample_scratch);
  const std::vector<double> samples = ws.samples;
  return bounds_from_samples(space, samples.data(), ws.errors[0], nodes.data(), planar, options, ws);
}

DistortionBounds distortion_bounds(const ElementType& type, std::span<const double> nodes,
                                   const JacobianBounds& jb, BoundsWorkspace& workspace,
                                   bool planar, const BoundsOptions& options) {
  QV_ASSERT(jacobian_bounds_supported(type), "no Jacobian bounds for " << type.name);
  return distortion_from(jacobian_space(type), nodes.data(), planar, jb, workspace.impl(), options);
}

}  // namespace quadval
