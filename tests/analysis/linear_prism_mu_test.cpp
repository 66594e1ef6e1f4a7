// The lane kernel of mu for first-order prisms (src/analysis/linear_prism_mu.hpp): against
// singular values of W sampled densely and at the vertices (Eigen's SVD through the
// Lagrange basis, mu_test_util.hpp: no code shared with src/analysis/mu_*), the constant W
// of a translated top, and the general path of mu_bounds, whose control matrices come from
// its own Bernstein products.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "analysis/linear_prism_mu.hpp"
#include "analysis/mu_constant.hpp"
#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

const ElementType& prism6() {
  for (const ElementType& t : element_types())
    if (t.family == ElementFamily::prism && t.num_nodes == 6) return t;
  throw std::logic_error("no first-order prism");
}

const std::array<double, 9>& jinv() { return mu_space(prism6()).ideal_inverse(); }

// A random first-order prism (random_element), at scales from 1e-6 to 1e5; every fourth
// one flattened to a boundary-layer cell (its top 50 times closer to its bottom).
std::vector<double> random_prism(int e, double amplitude, std::mt19937& rng) {
  std::vector<double> x = test::random_element(prism6(), amplitude, rng);
  if (e % 4 == 3)
    for (std::size_t n = 3; n < 6; ++n)
      for (std::size_t k = 0; k < 3; ++k) x[3 * n + k] = x[3 * (n - 3) + k] + 0.02 * (x[3 * n + k] - x[3 * (n - 3) + k]);
  const double scale = e % 7 == 0 ? 1e-6 : e % 11 == 0 ? 1e5 : 1;
  for (double& v : x) v *= scale;
  return x;
}

TEST(LinearPrismMu, BoundsEncloseSampledAndVertexValues) {
  std::mt19937 rng(59);
  const ElementType& t = prism6();
  const LagrangeBasis& basis = lagrange_basis(t);
  const auto points = test::dense_points(ElementFamily::prism, 10, 200, rng);
  const auto vertices = reference_vertices(ElementFamily::prism);
  BoundsOptions bounds_options;
  BoundsWorkspace workspace;
  int valid = 0, ok = 0, settled = 0;
  for (int e = 0; e < 600; ++e) {
    const double amplitude = e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.1 : 0.25;
    const auto x = random_prism(e, amplitude, rng);
    if (jacobian_bounds(t, x, bounds_options, workspace).validity != Validity::valid) continue;
    ++valid;
    const CertifiedRatio r = linear_prism_ratio(x, jinv());
    if (!r.ok) continue;
    ++ok;
    ASSERT_LE(0.0, r.lower);
    ASSERT_LE(r.lower, r.upper);
    ASSERT_LE(r.upper, 1.0);
    const test::SampledMu sampled = test::sample_mu(basis, x, points);
    ASSERT_FALSE(sampled.j_nonpositive);
    double vertex_min = 1;
    for (const RefPoint& p : vertices) vertex_min = std::min(vertex_min, test::pointwise_mu(basis, x, p));
    const double vertex_r = vertex_min * vertex_min;
    EXPECT_LE(r.lower, sampled.lo * sampled.lo * (1 + 1e-12)) << "element " << e;
    EXPECT_GE(r.upper, vertex_r * (1 - 1e-12)) << "element " << e;
    EXPECT_LE(r.upper, vertex_r * (1 + 1e-9)) << "element " << e;
    if (std::sqrt(r.upper) - std::sqrt(r.lower) <= 1e-2) ++settled;
  }
  std::printf("[linear prism mu] %d valid, %d certified, %d within 1e-2\n", valid, ok, settled);
  EXPECT_GE(valid, 300);
  EXPECT_GE(ok, valid * 98 / 100);
  EXPECT_GE(settled, valid / 2);
}

// A top triangle that is a translate of the bottom one makes W constant: R is that of W
// at any point.
TEST(LinearPrismMu, TranslatedTopsGetTheirConstantRatio) {
  std::mt19937 rng(61);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = prism6();
  const LagrangeBasis& basis = lagrange_basis(t);
  int checked = 0;
  for (int e = 0; e < 200; ++e) {
    std::vector<double> x(18);
    double shift[3];
    for (double& s : shift) s = u(rng);
    shift[2] += 1.5;
    for (std::size_t n = 0; n < 3; ++n)
      for (std::size_t k = 0; k < 3; ++k) {
        x[3 * n + k] = (n == k + 1 ? 1.0 : 0.0) + 0.3 * u(rng);
        x[3 * (n + 3) + k] = x[3 * n + k] + shift[k];
      }
    BoundsOptions bo;
    BoundsWorkspace ws;
    if (jacobian_bounds(t, x, bo, ws).validity != Validity::valid) continue;
    const CertifiedRatio r = linear_prism_ratio(x, jinv());
    ASSERT_TRUE(r.ok) << "element " << e;
    const double mu = test::pointwise_mu(basis, x, {0.2, 0.3, -0.4});
    EXPECT_LE(r.lower, mu * mu * (1 + 1e-12));
    EXPECT_GE(r.upper, mu * mu * (1 - 1e-12));
    EXPECT_NEAR(r.lower, mu * mu, 1e-8);
    EXPECT_NEAR(r.upper, mu * mu, 1e-8);
    ++checked;
  }
  EXPECT_GE(checked, 100);
}

// mu_bounds with the kernel (the default) and with the general path alone: at the root
// both take the least control matrix's ratio, the general path from its own products.
TEST(LinearPrismMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(67);
  const ElementType& t = prism6();
  QualityOptions opt;
  opt.abs_tol = 1e-2;
  int root = 0;
  for (int e = 0; e < 400; ++e) {
    const auto x = random_prism(e, e % 2 == 0 ? 0.05 : 0.25, rng);
    const QualityBounds fast = mu_bounds(t, x, opt, false);
    mu_use_constant_path(false);
    const QualityBounds general = mu_bounds(t, x, opt, false);
    mu_use_constant_path(true);
    EXPECT_LE(fast.lower, general.upper) << "element " << e;
    EXPECT_LE(general.lower, fast.upper) << "element " << e;
    if (fast.subdivisions == 0 && general.subdivisions == 0 && fast.upper > 0) {
      ++root;
      EXPECT_NEAR(fast.lower, general.lower, 1e-10) << "element " << e;
      EXPECT_NEAR(fast.upper, general.upper, 1e-10) << "element " << e;
    }
  }
  EXPECT_GE(root, 150);
}

}  // namespace
}  // namespace quadval
