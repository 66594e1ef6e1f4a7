// The measure mu above the orders of its degree-12n certificate (issue 5): every type the
// Jacobian bounds handle is handled, and the types bounded by the control-matrix bound
// alone (mu_space.hpp, mu_control_bound.hpp) are checked against oracles that share no
// code with src/analysis/mu_*: dense sampling of sigma_min / sigma_max of W = J_p J_i^-1
// from the Lagrange shape-function gradients (mu_test_util.hpp), the closed forms of ideal
// and affinely stretched ideal elements, and mirrored (inverted) elements.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "analysis/mu_constant.hpp"
#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

bool area_or_volume(ElementFamily f) {
  switch (f) {
    case ElementFamily::triangle:
    case ElementFamily::quadrangle:
    case ElementFamily::tetrahedron:
    case ElementFamily::prism:
    case ElementFamily::hexahedron:
    case ElementFamily::pyramid: return true;
    default: return false;
  }
}

// The orders mu_bounds handled before issue 5 (the certificate's orders until then).
int old_max_order(ElementFamily f) {
  switch (f) {
    case ElementFamily::triangle:
    case ElementFamily::quadrangle: return 6;
    case ElementFamily::tetrahedron: return 3;
    default: return 2;
  }
}

// Every Lagrange type of 2D/3D families above the old caps that the Jacobian bounds handle.
std::vector<const ElementType*> new_types() {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types())
    if (area_or_volume(t.family) && t.has_lagrange_basis && t.order > old_max_order(t.family) &&
        jacobian_bounds_supported(t))
      out.push_back(&t);
  return out;
}

// The ideal element through x -> a x + b (mu_test_util.hpp), for 2D in the plane z = 0.
std::vector<double> ideal_through(const ElementType& t, const Eigen::Matrix3d& a) {
  return test::affine_ideal_element(t, a, Eigen::Vector3d(0.25, -1.5, t.dim == 3 ? 2.0 : 0.0));
}

TEST(MuHighOrder, EveryTypeOfTheJacobianBoundsIsHandled) {
  int count = 0;
  for (const ElementType& t : element_types()) {
    if (!area_or_volume(t.family) || !t.has_lagrange_basis || t.order < 1) continue;
    SCOPED_TRACE(std::string(t.name));
    EXPECT_EQ(mu_supported(t), jacobian_bounds_supported(t));
    count += mu_supported(t);
  }
  for (ElementFamily f : {ElementFamily::triangle, ElementFamily::quadrangle, ElementFamily::tetrahedron,
                          ElementFamily::prism, ElementFamily::hexahedron, ElementFamily::pyramid})
    EXPECT_EQ(mu_max_order(f), max_supported_order(f)) << family_name(f);
  EXPECT_GT(count, 60);
  // The registry's highest orders are beyond the Jacobian bounds: still refused.
  EXPECT_FALSE(mu_supported(*find_element_type(75)));   // tetrahedron of order 10
  EXPECT_FALSE(mu_supported(*find_element_type(94)));   // hexahedron of order 5
  EXPECT_FALSE(mu_supported(*find_element_type(106)));  // prism of order 5
}

TEST(MuHighOrder, CertificateOnlyWhereItIsAffordable) {
  for (const ElementType* t : new_types()) {
    SCOPED_TRACE(std::string(t->name));
    const MuSpace& space = mu_space(*t);
    EXPECT_EQ(space.has_certificate(), t->order <= mu_certificate_max_order(t->family));
    if (!space.has_certificate()) {
      EXPECT_EQ(space.size(12), 0);  // nothing of the degree-12n data was built
      EXPECT_EQ(space.size(4), 0);
    }
  }
  // The types that had the certificate keep it.
  for (int id : {21, 36, 29, 11, 12, 14, 13}) EXPECT_TRUE(mu_space(*find_element_type(id)).has_certificate()) << id;
}

// Dense sampling: the sampled minimum of mu_pw is never below the certified lower bound,
// the certified upper bound is never above the sampled maximum (it is a value of mu_pw at
// a subdomain corner, up to rounding), and the gap closes to the tolerance.
TEST(MuHighOrder, SampledMinimumNeverBelowLowerBound) {
  std::mt19937 rng(505);
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  opt.max_subdivisions = 300;
  int elements = 0, sampled = 0, met = 0;
  for (const ElementType* t : new_types()) {
    SCOPED_TRACE(std::string(t->name));
    const LagrangeBasis& basis = lagrange_basis(*t);
    const auto pts = test::dense_points(t->family, t->dim == 3 ? 6 : 14, t->dim == 3 ? 120 : 80, rng);
    const int count = t->dim == 3 ? 3 : 6;
    int type_met = 0, type_valid = 0;
    for (int e = 0; e < count; ++e) {
      const auto x = test::smooth_random_element(*t, e % 3 == 0 ? 0.03 : (e % 3 == 1 ? 0.1 : 0.2), rng);
      const QualityBounds b = mu_bounds(*t, x, opt, true);
      ++elements;
      ASSERT_LE(b.lower, b.upper);
      ASSERT_GE(b.lower, 0.0);
      ASSERT_LE(b.upper, 1.0);
      if (b.tolerance_met) {
        ++met, ++type_met;
        EXPECT_LE(b.upper - b.lower, opt.abs_tol);
      }
      const auto [lo, hi, negative] = test::sample_mu(basis, x, pts);
      if (negative) {
        EXPECT_EQ(b.lower, 0.0) << "a sample with J <= 0 in an element with mu > 0";
        continue;
      }
      if (b.upper == 0) continue;  // certified invalid where the samples missed it
      ++sampled, ++type_valid;
      EXPECT_GE(lo, b.lower - 1e-13) << "element " << e << " [" << b.lower << ", " << b.upper << "]";
      EXPECT_LE(b.upper, hi + 1e-13) << "element " << e;
      EXPECT_GT(b.lower, 0.0) << "element " << e;
    }
    EXPECT_GE(type_valid, count - 1);
    EXPECT_GE(type_met, count - 1);
  }
  std::printf("[mu high order] %d elements, %d sampled, %d within tolerance\n", elements, sampled, met);
}

// mu of an ideal element under a similarity is 1; under x -> diag(s) x it is the ratio of
// the smallest to the largest stretch. Both with the constant-W closed form and without
// it (then the control-matrix bound settles it: all control matrices are equal).
TEST(MuHighOrder, IdealAndStretchedIdealElements) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (const ElementType* t : new_types()) {
    SCOPED_TRACE(std::string(t->name));
    // W's a priori rounding bound grows with the derivative maps' row sums (Lagrange
    // derivatives of order 8-9 reach ~1e4, as for the Jacobian: pyramid_jacobian_test.cpp),
    // so the pyramids of orders 8 and 9 are asked what they can give (gap ~3e-5 measured).
    const double tol = t->order >= 8 ? 1e-4 : 1e-6;
    QualityOptions opt;
    opt.abs_tol = tol;
    const Eigen::Matrix3d similar = 3.5 * (t->dim == 3 ? rotation : turn);
    Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
    stretch(0, 0) = 1.7;
    stretch(1, 1) = t->dim == 3 ? 2.5 : 0.3;
    stretch(2, 2) = t->dim == 3 ? 0.3 : 1.0;
    const double want = t->dim == 3 ? 0.3 / 2.5 : 0.3 / 1.7;
    for (bool constant_path : {true, false}) {
      mu_use_constant_path(constant_path);
      const QualityBounds one = mu_bounds(*t, ideal_through(*t, similar), opt, true);
      EXPECT_TRUE(one.tolerance_met) << constant_path;
      EXPECT_GE(one.lower, 1 - tol) << constant_path;
      EXPECT_LE(one.upper, 1.0);
      const QualityBounds s = mu_bounds(*t, ideal_through(*t, stretch), opt, true);
      EXPECT_TRUE(s.tolerance_met) << constant_path;
      EXPECT_LE(s.lower, want) << constant_path;
      EXPECT_GE(s.upper, want) << constant_path;
      EXPECT_LE(s.upper - s.lower, tol) << constant_path;
    }
    mu_use_constant_path(true);
  }
}

// A mirrored ideal element has J < 0 everywhere: mu = 0 exactly. A mildly curved element
// with its nodes mirrored too (J < 0 at every sample, checked here) gets 0 as well.
TEST(MuHighOrder, InvertedElementsGetZero) {
  std::mt19937 rng(77);
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  for (const ElementType* t : new_types()) {
    SCOPED_TRACE(std::string(t->name));
    Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity();
    mirror(1, 1) = -1;
    const QualityBounds r = mu_bounds(*t, ideal_through(*t, mirror), opt, true);
    EXPECT_EQ(r.lower, 0.0);
    EXPECT_EQ(r.upper, 0.0);
    EXPECT_TRUE(r.tolerance_met);

    auto x = test::smooth_random_element(*t, 0.05, rng);
    for (std::size_t i = 1; i < x.size(); i += 3) x[i] = -x[i];
    const LagrangeBasis& basis = lagrange_basis(*t);
    bool all_negative = true;
    for (const auto& p : test::dense_points(t->family, 4, 20, rng))
      all_negative = all_negative && test::jacobian_at(basis, x, p, true) < 0;
    ASSERT_TRUE(all_negative);
    const QualityBounds c = mu_bounds(*t, x, opt, true);
    EXPECT_EQ(c.lower, 0.0);
    EXPECT_EQ(c.upper, 0.0);
  }
}

}  // namespace
}  // namespace quadval
