// eta of Paper I eq. (3) and the corner sine, against closed forms (STYLE.md §4); the
// polynomial asin behind eta (eta_of_cosine.hpp) against the C library's asin.
#include "quadval/quad_quality.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "recombine/eta_of_cosine.hpp"

#include <gtest/gtest.h>

namespace quadval {
namespace {

constexpr double kPi = std::numbers::pi;

struct EtaCase {
  const char* name;
  QuadCorners x;
  double want_eta;
  QuadShape shape;
  double want_min_sine;  // for normal +z
};

// Parallelogram with angle `a` at the first corner, unit sides.
QuadCorners parallelogram(double a) {
  return {{{0, 0, 0}, {1, 0, 0}, {1 + std::cos(a), std::sin(a), 0}, {std::cos(a), std::sin(a), 0}}};
}

const EtaCase kCases[] = {
    {"unit_square", {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, 1.0, QuadShape::ok, 1.0},
    {"rectangle_3x1", {{{0, 0, 0}, {3, 0, 0}, {3, 1, 0}, {0, 1, 0}}}, 1.0, QuadShape::ok, 1.0},
    // Angles 60 and 120 degrees: max deviation pi/6, eta = 1 - (2/pi)(pi/6) = 2/3.
    {"rhombus_60", parallelogram(kPi / 3), 2.0 / 3.0, QuadShape::ok, std::sin(kPi / 3)},
    // 45 / 135 degrees: eta = 1 - (2/pi)(pi/4) = 1/2.
    {"parallelogram_45", parallelogram(kPi / 4), 0.5, QuadShape::ok, std::sin(kPi / 4)},
    // Right trapezoid (0,0) (2,0) (1,1) (0,1): angles 90, 45, 135, 90 -> eta 1/2.
    {"right_trapezoid", {{{0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, 0.5, QuadShape::ok,
     std::sin(kPi / 4)},
    // Dart: corner (1, 0.3) is reflex (> pi): eta 0, corner sine negative.
    {"dart", {{{0, 0, 0}, {2, 0, 0}, {1, 0.3, 0}, {1, 2, 0}}}, 0.0, QuadShape::ok, -1.0},
    // The unit square listed clockwise, seen from +z: inverted.
    {"clockwise_square", {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}}, 0.0, QuadShape::ok, -1.0},
    // Triangle-shaped quad: a straight corner (angle pi) scores 0.
    {"flat_corner", {{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 1, 0}}}, 0.0, QuadShape::ok, 0.0},
    {"collapsed_edge", {{{0, 0, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, 0.0, QuadShape::degenerate,
     -1.0},
};

TEST(QuadQuality, EtaGoldenTableWithNormalPlusZ) {
  for (const EtaCase& c : kCases) {
    SCOPED_TRACE(c.name);
    const QuadEta q = quad_eta(c.x, {0, 0, 1});
    EXPECT_EQ(q.shape, c.shape);
    EXPECT_NEAR(q.eta, c.want_eta, 1e-12);
  }
}

TEST(QuadQuality, MinCornerSineGoldenTable) {
  for (const EtaCase& c : kCases) {
    SCOPED_TRACE(c.name);
    const double s = quad_min_corner_sine(c.x, {0, 0, 1});
    if (c.want_min_sine == -1.0 && c.shape == QuadShape::ok && std::string(c.name) == "dart") {
      EXPECT_LT(s, 0.0);  // reflex corner: negative, value not tabulated
    } else {
      EXPECT_NEAR(s, c.want_min_sine, 1e-12);
    }
  }
}

TEST(QuadQuality, OwnNormalIgnoresOrientation) {
  // Without a reference normal the clockwise square is a perfect square.
  const QuadCorners cw{{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}};
  EXPECT_NEAR(quad_eta(cw).eta, 1.0, 1e-15);
  EXPECT_NEAR(quad_eta(parallelogram(kPi / 3)).eta, 2.0 / 3.0, 1e-12);
}

TEST(QuadQuality, RotatedIntoThreeDimensionsKeepsEta) {
  // The 60-degree rhombus rotated about the x axis by 0.7 rad: same angles, eta 2/3.
  const double c = std::cos(0.7), s = std::sin(0.7);
  QuadCorners x = parallelogram(kPi / 3);
  for (auto& p : x) p = {p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]};
  EXPECT_NEAR(quad_eta(x, {0, -s, c}).eta, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(quad_eta(x, {0, s, -c}).eta, 0.0, 0.0);  // seen from the other side: inverted
}

TEST(QuadQuality, ZeroNormalIsDegenerate) {
  EXPECT_EQ(quad_eta(kCases[0].x, {0, 0, 0}).shape, QuadShape::degenerate);
  EXPECT_EQ(quad_min_corner_sine(kCases[0].x, {0, 0, 0}), -1.0);
}

TEST(QuadQuality, EtaOfParallelogramsMatchesClosedFormOnASweep) {
  // eta(parallelogram(a)) = 1 - |pi/2 - a| / (pi/2) for a in (0, pi).
  for (int i = 1; i < 180; ++i) {
    const double a = kPi * i / 180.0;
    EXPECT_NEAR(quad_eta(parallelogram(a), {0, 0, 1}).eta, 1.0 - std::abs(kPi / 2 - a) / (kPi / 2),
                1e-9)
        << "angle " << i << " degrees";
  }
}

// eta = 1 - asin(c) / (pi / 2), against asinl (long double) on a dense sweep of [0, 1] and
// the doubles next to the branch point 1/2 and to 1: within 2.5e-16 (about one unit in the
// last place of values near 1), and never increasing with c.
TEST(EtaOfCosine, WithinAnUlpOfTheLibraryAsinAndMonotone) {
  using recombine_detail::eta_of_cosine;
  std::vector<double> cs;
  constexpr int kSteps = 1 << 20;
  for (int i = 0; i <= kSteps; ++i) cs.push_back(static_cast<double>(i) / kSteps);
  for (double at : {0.5, 1.0}) {
    double below = at, above = at;
    for (int i = 0; i < 1000; ++i) {
      below = std::nextafter(below, 0.0);
      above = std::nextafter(above, 2.0);
      cs.push_back(below);
      if (above <= 1.0) cs.push_back(above);
    }
  }
  std::sort(cs.begin(), cs.end());
  const long double half_pi = std::acos(-1.0L) / 2;
  double previous = 2.0, worst = 0.0;
  for (double c : cs) {
    const double eta = eta_of_cosine(c);
    const auto exact = static_cast<double>(1.0L - std::asin(static_cast<long double>(c)) / half_pi);
    worst = std::max(worst, std::abs(eta - exact));
    EXPECT_LE(eta, previous) << "c = " << c;
    previous = eta;
  }
  EXPECT_LE(worst, 2.5e-16);
  EXPECT_EQ(eta_of_cosine(0.0), 1.0);
  EXPECT_EQ(eta_of_cosine(1.0), 0.0);
  EXPECT_NEAR(eta_of_cosine(0.5), 2.0 / 3.0, 2.3e-16);
  EXPECT_NEAR(eta_of_cosine(std::sqrt(0.5)), 0.5, 2.3e-16);
}

// Four lanes give each lane's scalar value to the bit, on both sides of the branch point.
TEST(EtaOfCosine, FourLanesEqualOneByOne) {
  using recombine_detail::EtaLanes;
  using recombine_detail::eta_of_cosine;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double special[] = {0.0, 0.5, std::nextafter(0.5, 1.0), std::nextafter(0.5, 0.0), 1.0};
  for (int i = 0; i < 100000; ++i) {
    EtaLanes c = {unit(rng), unit(rng), unit(rng), unit(rng)};
    if (i < 5) c[i % 4] = special[i];
    const EtaLanes eta = eta_of_cosine(c);
    for (int l = 0; l < 4; ++l) ASSERT_EQ(eta[l], eta_of_cosine(c[l])) << "c = " << c[l];
  }
}

}  // namespace
}  // namespace quadval
