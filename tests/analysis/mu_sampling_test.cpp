// Dense sampling oracle of the certified measure mu: on random curved elements of every
// handled family and order, sigma_min / sigma_max of W = J_p J_i^-1 from Eigen's SVD at a
// lattice and random points (mu_test_util.hpp, no code shared with src/analysis/mu_*) is
// never below the certified lower bound, and the bounds are consistent.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdio>
#include <random>

#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

struct Count {
  int elements = 0, valid = 0, met = 0;
};

TEST(MuSampling, SampledMinimumNeverBelowLowerBound) {
  std::mt19937 rng(2024);
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  opt.max_subdivisions = 200;
  Count total;
  for (const ElementType& t : element_types()) {
    // Above mu_certificate_max_order: mu_high_order_test.cpp.
    if (t.family == ElementFamily::line || !mu_supported(t) || t.order > 3 ||
        t.order > mu_certificate_max_order(t.family))
      continue;
    SCOPED_TRACE(std::string(t.name));
    const LagrangeBasis& basis = lagrange_basis(t);
    // Fewer elements where the certificate is costly (degree 12 n in 3D).
    const bool heavy = t.dim == 3 && (t.order >= 2 && t.family != ElementFamily::tetrahedron);
    const int count = heavy ? 12 : (t.dim == 3 ? 60 : 150);
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 60, rng);
    Count c;
    for (int e = 0; e < count; ++e) {
      const double amplitude = ((e % 3 == 0) ? 0.02 : (e % 3 == 1 ? 0.08 : 0.15)) / t.order;
      const auto x = test::random_element(t, amplitude, rng);
      const QualityBounds b = mu_bounds(t, x, opt, true);
      ++c.elements;
      ASSERT_LE(b.lower, b.upper);
      ASSERT_GE(b.lower, 0.0);
      ASSERT_LE(b.upper, 1.0);
      if (b.tolerance_met) {
        ++c.met;
        EXPECT_LE(b.upper - b.lower, opt.abs_tol);
      }
      if (b.upper == 0) continue;  // invalid: mu = 0
      const auto [lo, hi, negative] = test::sample_mu(basis, x, pts);
      if (negative) {
        EXPECT_EQ(b.lower, 0.0) << "a sample with J <= 0 in an element with mu > 0";
        continue;
      }
      ++c.valid;
      EXPECT_GE(lo, b.lower - 1e-13) << "element " << e;
      EXPECT_LE(b.upper, hi + 1e-13) << "element " << e;
    }
    total.elements += c.elements;
    total.valid += c.valid;
    total.met += c.met;
    EXPECT_GE(c.valid, c.elements / 2);
    EXPECT_GE(c.met, c.elements * 9 / 10);
  }
  std::printf("[mu sampling] %d elements, %d valid and sampled, %d within tolerance\n",
              total.elements, total.valid, total.met);
}

// Near-ideal, flat and needle-like curved elements: the two ends of the measure, where the
// certificate switches between its two forms (mu_metric.hpp).
TEST(MuSampling, NearIdealFlatAndNeedleElements) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  QualityOptions opt;
  opt.abs_tol = 1e-3;
  opt.max_subdivisions = 400;
  for (const ElementType& t : element_types()) {
    if (t.family == ElementFamily::line || !mu_supported(t) || t.order > 2) continue;
    SCOPED_TRACE(std::string(t.name));
    const LagrangeBasis& basis = lagrange_basis(t);
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 60, rng);
    const double shapes[3][3] = {{1, 1, 1}, {1, 1, 0.05}, {1, 0.05, 0.05}};
    for (int k = 0; k < (t.dim == 3 ? 3 : 2); ++k) {
      Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
      const double* sh = shapes[k];
      if (t.dim == 2) {
        a(0, 0) = sh[0];
        a(1, 1) = k == 0 ? 1.0 : 0.05;
      } else {
        for (int i = 0; i < 3; ++i) a(i, i) = sh[i];
      }
      const double smallest = t.dim == 2 ? a(1, 1) : sh[2];
      auto x = test::affine_ideal_element(t, a, Eigen::Vector3d(0.5, -1, 0));
      for (std::size_t i = 0; i < x.size(); ++i)
        if (!(t.dim == 2 && i % 3 == 2)) x[i] += 2e-3 * smallest / t.order * u(rng);
      const QualityBounds b = mu_bounds(t, x, opt, true);
      double lo = 1, hi = 0;
      for (const auto& p : pts) {
        const double m = test::pointwise_mu(basis, x, p);
        lo = std::min(lo, m);
        hi = std::max(hi, m);
      }
      EXPECT_TRUE(b.tolerance_met) << "shape " << k << ": " << b.lower << " " << b.upper;
      EXPECT_GE(lo, b.lower - 1e-13) << "shape " << k;
      EXPECT_LE(b.upper, hi + 1e-13) << "shape " << k;
      EXPECT_GT(b.lower, 0.5 * smallest) << "shape " << k;
    }
  }
}

}  // namespace
}  // namespace quadval
