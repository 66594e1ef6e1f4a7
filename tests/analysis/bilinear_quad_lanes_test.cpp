// The closed forms of bilinear planar quadrangles four at a time (bilinear_quad_lanes in
// src/analysis/bilinear_quad_quality.hpp): in the check's chunks bit for bit what mu_bounds
// and scaled_jacobian_bounds give each element alone, and the closed forms of rectangles
// and parallelograms in every lane.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/bilinear_quad_quality.hpp"
#include "check_alone_test_util.hpp"
#include "quadval/lagrange_basis.hpp"
#include "quadval/mu_bounds.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

// Quadrangles of `type` at random in the plane z = 0.25: a unit square with its corners
// moved (some far enough to fold it), scaled by 1e-6 to 1e4, some mirrored (inverted);
// the other nodes where the bilinear map of the corners puts them, off it by a
// rounding-sized deviation (which gives a margin) or curved.
std::vector<std::vector<double>> random_quads(const ElementType& type, int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::vector<double>> elements;
  for (int e = 0; e < count; ++e) {
    const double scale = e % 7 == 0 ? 1e-6 : e % 11 == 0 ? 1e4 : 1;
    const double move = e % 9 == 0 ? 0.6 : 0.25;
    const double mirror = e % 6 == 4 ? -1 : 1;
    const double square[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    double v[4][2];
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 2; ++j) v[k][j] = scale * (square[k][j] + move * u(rng)) * (j == 0 ? mirror : 1);
    const double deviation = e % 4 == 0 ? 0.0 : e % 4 == 1 ? 1e-13 : e % 4 == 2 ? 1e-9 : 1e-2;
    std::vector<double> x;
    for (const RefPoint& p : reference_nodes(type)) {
      const bool vertex = x.size() < 12;
      const double n[4] = {(1 - p[0]) * (1 - p[1]) / 4, (1 + p[0]) * (1 - p[1]) / 4, (1 + p[0]) * (1 + p[1]) / 4,
                           (1 - p[0]) * (1 + p[1]) / 4};
      for (int j = 0; j < 2; ++j) {
        double c = 0;
        for (int k = 0; k < 4; ++k) c += n[k] * v[k][j];
        if (!vertex) c += deviation * scale * u(rng);
        x.push_back(vertex ? v[x.size() / 3][j] : c);
      }
      x.push_back(0.25);
    }
    elements.push_back(std::move(x));
  }
  return elements;
}

TEST(BilinearQuadLanes, CheckChunksMatchEachElementAloneBitForBit) {
  std::mt19937 rng(81);
  for (const int id : {3, 10, 16, 36}) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    const auto quads = random_quads(type, 1500, rng);
    const int valid_mu = test::expect_check_matches_alone(
        type, quads, CheckMeasure::mu,
        [&](const std::vector<double>& x, const QualityOptions& q) { return mu_bounds(type, x, q, true); });
    const int valid_sj = test::expect_check_matches_alone(
        type, quads, CheckMeasure::scaled_jacobian,
        [&](const std::vector<double>& x, const QualityOptions& q) { return scaled_jacobian_bounds(type, x, q, true); });
    EXPECT_GT(valid_mu, 700);
    EXPECT_GT(valid_sj, 700);
  }
}

// Rectangles a x b (mu = b / a) and parallelograms of angle theta (sj = sin theta), each
// lane at its own scale and angle; a lane with an infinite margin is declined.
TEST(BilinearQuadLanes, RectanglesAndParallelogramsInEveryLane) {
  constexpr int kW = kNativeLanes;
  Lanes<kW> rect[8] = {}, para[8] = {}, beta[2] = {}, margin{};
  double ratio[kW], angle[kW];
  for (int l = 0; l < kW; ++l) {
    const double s = std::ldexp(1.0, 9 * l - 14), b = 0.2 + 0.1 * l;  // below 1 in all 8 lanes
    ratio[l] = b;
    angle[l] = 0.3 + 0.35 * l;
    const double r[4][2] = {{0, 0}, {s, 0}, {s, b * s}, {0, b * s}};
    const double dx = s * std::cos(angle[l]), dy = s * std::sin(angle[l]);
    const double p[4][2] = {{0, 0}, {2 * s, 0}, {2 * s + dx, dy}, {dx, dy}};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 2; ++j) {
        rect[2 * k + j][l] = 3 + r[k][j];
        para[2 * k + j][l] = -1 + p[k][j];
      }
  }
  QualityBounds mu[kW], sj[kW];
  ASSERT_EQ(bilinear_quad_mu_lanes(rect, beta, margin, 1e-2, mu), (1u << kW) - 1);
  ASSERT_EQ(bilinear_quad_sj_lanes(para, beta, margin, 1e-2, sj), (1u << kW) - 1);
  for (int l = 0; l < kW; ++l) {
    // The exact values of the coordinates as stored (their differences are exact, Sterbenz),
    // in long double.
    const long double a = rect[2][l] - rect[0][l], b = rect[7][l] - rect[1][l];
    const long double r = b / a;
    const long double ex = para[2][l] - para[0][l], fx = para[6][l] - para[0][l], fy = para[7][l] - para[1][l];
    const long double sine = ex * fy / (ex * std::sqrt(fx * fx + fy * fy));
    EXPECT_NEAR(static_cast<double>(r), ratio[l], 1e-9);
    EXPECT_NEAR(static_cast<double>(sine), std::sin(angle[l]), 1e-9);
    EXPECT_LE(mu[l].lower, r);
    EXPECT_GE(mu[l].upper, r);
    EXPECT_LT(mu[l].upper - mu[l].lower, 1e-9);
    EXPECT_LE(sj[l].lower, sine);
    EXPECT_GE(sj[l].upper, sine);
    EXPECT_LT(sj[l].upper - sj[l].lower, 1e-9);
  }
  margin[1] = INFINITY;
  EXPECT_EQ(bilinear_quad_mu_lanes(rect, beta, margin, 1e-2, mu), ((1u << kW) - 1) & ~2u);
  EXPECT_EQ(bilinear_quad_sj_lanes(para, beta, margin, 1e-2, sj), ((1u << kW) - 1) & ~2u);
}

}  // namespace
}  // namespace quadval
