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
#include "analysis/mu_space.hpp"
#include "first_order_mu_test_util.hpp"

namespace quadval {
namespace {

const ElementType& prism6() { return test::first_order(ElementFamily::prism); }

const std::array<double, 9>& jinv() { return mu_space(prism6()).ideal_inverse(); }

// A random first-order prism (random_scaled_element); every fourth one flattened to a boundary-layer cell (its top 50 times closer to its bottom).
std::vector<double> random_prism(int e, double amplitude, std::mt19937& rng) {
  std::vector<double> x = test::random_scaled_element(prism6(), e, amplitude, rng);
  if (e % 4 == 3)
    for (std::size_t n = 3; n < 6; ++n)
      for (std::size_t k = 0; k < 3; ++k) x[3 * n + k] = x[3 * (n - 3) + k] + 0.02 * (x[3 * n + k] - x[3 * (n - 3) + k]);
  return x;
}

TEST(LinearPrismMu, BoundsEncloseSampledAndVertexValues) {
  std::mt19937 rng(59);
  const auto points = test::dense_points(ElementFamily::prism, 10, 200, rng);
  const auto vertices = reference_vertices(ElementFamily::prism);
  test::check_against_samples(
      prism6(), [](std::span<const double> x) { return linear_prism_ratio(x, jinv()); },
      [](int e, std::mt19937& r) { return random_prism(e, e % 3 == 0 ? 0.02 : e % 3 == 1 ? 0.1 : 0.25, r); }, 600,
      300, points, {vertices.begin(), vertices.end()}, rng);
}

// A top triangle that is a translate of the bottom one makes W constant: R is that of W
// at any point.
TEST(LinearPrismMu, TranslatedTopsGetTheirConstantRatio) {
  std::mt19937 rng(61);
  std::uniform_real_distribution<double> u(-1, 1);
  const ElementType& t = prism6();
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
    const auto kernel = [](std::span<const double> y) { return linear_prism_ratio(y, jinv()); };
    if (test::check_constant_ratio(t, x, kernel, {0.2, 0.3, -0.4}, e)) ++checked;
  }
  EXPECT_GE(checked, 100);
}

TEST(LinearPrismMu, AgreesWithTheGeneralPath) {
  std::mt19937 rng(67);
  test::check_against_general_path(
      prism6(), [](int e, std::mt19937& r) { return random_prism(e, e % 2 == 0 ? 0.05 : 0.25, r); }, 400, 150, rng);
}

}  // namespace
}  // namespace quadval
