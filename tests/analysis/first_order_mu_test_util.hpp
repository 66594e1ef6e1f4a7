#pragma once
// Checks shared by the tests of the first-order mu kernels (trilinear_hex_mu,
// linear_prism_mu, linear_pyramid_mu): against singular values of W through the Lagrange
// basis (mu_test_util.hpp, no code shared with src/analysis/mu_*), and against the general
// path of mu_bounds, whose control matrices come from its own Bernstein products.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "analysis/mu_constant.hpp"
#include "analysis/vertex_metric_ratio.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval::test {

/// The nodes of test element e.
using MakeElement = std::function<std::vector<double>(int e, std::mt19937& rng)>;
using RatioKernel = std::function<CertifiedRatio(std::span<const double>)>;

/// The first-order element of a family.
inline const ElementType& first_order(ElementFamily family) {
  for (const ElementType& t : element_types())
    if (t.family == family && t.order == 1 && t.has_lagrange_basis) return t;
  throw std::logic_error("no first-order element of this family");
}

/// The kernel on `count` elements, those proven valid compared with pointwise R: lower <= R
/// at every point of `points`; upper >= the least value at `vertices` (>= min R) and
/// within rounding of it (Rayleigh quotients at good eigenvectors). Also: at least 98% of
/// the valid ones certified, at least half within 1e-2 in mu, at least `min_valid` valid.
inline void check_against_samples(const ElementType& t, const RatioKernel& kernel, const MakeElement& make, int count,
                                  int min_valid, const std::vector<RefPoint>& points,
                                  const std::vector<RefPoint>& vertices, std::mt19937& rng) {
  const LagrangeBasis& basis = lagrange_basis(t);
  BoundsOptions bounds_options;
  BoundsWorkspace workspace;
  int valid = 0, ok = 0, settled = 0;
  for (int e = 0; e < count; ++e) {
    const auto x = make(e, rng);
    if (jacobian_bounds(t, x, bounds_options, workspace).validity != Validity::valid) continue;
    ++valid;
    const CertifiedRatio r = kernel(x);
    if (!r.ok) continue;
    ++ok;
    ASSERT_LE(0.0, r.lower);
    ASSERT_LE(r.lower, r.upper);
    ASSERT_LE(r.upper, 1.0);
    const SampledMu sampled = sample_mu(basis, x, points);
    ASSERT_FALSE(sampled.j_nonpositive);
    double vertex_min = 1;
    for (const RefPoint& p : vertices) vertex_min = std::min(vertex_min, pointwise_mu(basis, x, p));
    const double vertex_r = vertex_min * vertex_min;
    EXPECT_LE(r.lower, sampled.lo * sampled.lo * (1 + 1e-12)) << "element " << e;
    EXPECT_GE(r.upper, vertex_r * (1 - 1e-12)) << "element " << e;
    EXPECT_LE(r.upper, vertex_r * (1 + 1e-9)) << "element " << e;
    if (std::sqrt(r.upper) - std::sqrt(r.lower) <= 1e-2) ++settled;
  }
  std::printf("[%s mu kernel] %d valid, %d certified, %d within 1e-2\n", std::string(t.name).c_str(), valid, ok,
              settled);
  EXPECT_GE(valid, min_valid);
  EXPECT_GE(ok, valid * 98 / 100);
  EXPECT_GE(settled, valid / 2);
}

/// mu_bounds of one element with the kernels (the default) and with the general path alone
/// (mu_use_constant_path(false)).
struct BothPaths {
  QualityBounds fast, general;
};
inline BothPaths mu_both_paths(const ElementType& t, const std::vector<double>& x, const QualityOptions& opt) {
  BothPaths out;
  out.fast = mu_bounds(t, x, opt, false);
  mu_use_constant_path(false);
  out.general = mu_bounds(t, x, opt, false);
  mu_use_constant_path(true);
  return out;
}

/// Where W is constant, R is its value at any point: the kernel's bounds of a valid
/// element enclose pointwise R at `p` and equal it to 1e-8. False where the element is
/// not proven valid (not checked).
inline bool check_constant_ratio(const ElementType& t, const std::vector<double>& x, const RatioKernel& kernel,
                                 const RefPoint& p, int e) {
  BoundsOptions bo;
  BoundsWorkspace ws;
  if (jacobian_bounds(t, x, bo, ws).validity != Validity::valid) return false;
  const CertifiedRatio r = kernel(x);
  EXPECT_TRUE(r.ok) << "element " << e;
  if (!r.ok) return true;
  const double mu = pointwise_mu(lagrange_basis(t), x, p);
  EXPECT_LE(r.lower, mu * mu * (1 + 1e-12)) << "element " << e;
  EXPECT_GE(r.upper, mu * mu * (1 - 1e-12)) << "element " << e;
  EXPECT_NEAR(r.lower, mu * mu, 1e-8) << "element " << e;
  EXPECT_NEAR(r.upper, mu * mu, 1e-8) << "element " << e;
  return true;
}

/// mu_both_paths on `count` elements: overlapping intervals, and the same bounds to 1e-10
/// where both settle at the root, at least `min_root` times.
inline void check_against_general_path(const ElementType& t, const MakeElement& make, int count, int min_root,
                                       std::mt19937& rng) {
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  int root = 0;
  for (int e = 0; e < count; ++e) {
    const auto [fast, general] = mu_both_paths(t, make(e, rng), opt);
    EXPECT_LE(fast.lower, general.upper) << "element " << e;
    EXPECT_LE(general.lower, fast.upper) << "element " << e;
    if (fast.subdivisions == 0 && general.subdivisions == 0 && fast.upper > 0) {
      ++root;
      EXPECT_NEAR(fast.lower, general.lower, 1e-10) << "element " << e;
      EXPECT_NEAR(fast.upper, general.upper, 1e-10) << "element " << e;
    }
  }
  EXPECT_GE(root, min_root);
}

/// random_element's first-order element (an affine image of the reference one, its nodes
/// moved by up to `amplitude`), at scales from 1e-6 to 1e5.
inline std::vector<double> random_scaled_element(const ElementType& t, int e, double amplitude, std::mt19937& rng) {
  std::vector<double> x = random_element(t, amplitude, rng);
  const double scale = e % 7 == 0 ? 1e-6 : e % 11 == 0 ? 1e5 : 1;
  for (double& v : x) v *= scale;
  return x;
}

}  // namespace quadval::test
