#include "quadval/size_field.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "quadval/error.hpp"
#include "quadval/mesh.hpp"

namespace quadval {
namespace {

using testing::HasSubstr;

// Paper I's field for the rectangle demo (thesis line 521), written in C++ as the oracle.
double paper_field(double x, double y) { return 0.1 + 0.08 * std::sin(3 * x) * std::cos(6 * y); }

std::string message_of(const std::string& expression) {
  try {
    (void)SizeField::from_expression(expression);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SizeField, EvaluatesPaperOneFieldLikeTheClosedForm) {
  const auto h = SizeField::from_expression("0.1 + 0.08*sin(3*x)*cos(6*y)");
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 60; ++j) {
      const double x = i / 20.0, y = j / 20.0;
      EXPECT_NEAR(h(x, y, 0.0), paper_field(x, y), 1e-15) << x << " " << y;
    }
  EXPECT_EQ(h.expression(), "0.1 + 0.08*sin(3*x)*cos(6*y)");
}

TEST(SizeField, KnowsConstantsScientificNotationAndMinMax) {
  EXPECT_DOUBLE_EQ(SizeField::from_expression("pi")(0, 0, 0), std::numbers::pi);
  EXPECT_DOUBLE_EQ(SizeField::from_expression("e")(0, 0, 0), std::numbers::e);
  EXPECT_DOUBLE_EQ(SizeField::from_expression("2.5e-3 + z")(0, 0, 1), 1.0025);
  // min over the distances to the sides of the unit square, as the square-hole demo uses.
  const auto d = SizeField::from_expression("min(x, 1-x, y, 1-y)");
  EXPECT_DOUBLE_EQ(d(0.1, 0.5, 0), 0.1);
  EXPECT_DOUBLE_EQ(d(0.5, 0.8, 0), 0.2);
  EXPECT_DOUBLE_EQ(SizeField::from_expression("max(x, y, z)")(1, 3, 2), 3.0);
  EXPECT_DOUBLE_EQ(SizeField::constant(0.25)(7, 8, 9), 0.25);
}

TEST(SizeField, RejectsUnknownVariablesByName) {
  EXPECT_THAT(message_of("0.1 + r"), HasSubstr("unknown variable 'r'"));
  EXPECT_THAT(message_of("0.1 + r"), HasSubstr("size expression '0.1 + r'"));
  EXPECT_THAT(message_of("X + 1"), HasSubstr("unknown variable 'X'"));
}

TEST(SizeField, RejectsSyntaxErrorsWithTheirPosition) {
  EXPECT_THAT(message_of("0.1 +* x"), HasSubstr("does not parse"));
  EXPECT_THAT(message_of("0.1 +* x"), HasSubstr("byte offset"));
  EXPECT_THAT(message_of("sin(x"), HasSubstr("does not parse"));
  EXPECT_THAT(message_of("foo(x)"), HasSubstr("size expression 'foo(x)'"));
  EXPECT_THAT(message_of("  "), HasSubstr("empty expression"));
  EXPECT_THAT(message_of(""), HasSubstr("empty expression"));
}

// Each thread evaluates on its own points and compares with the closed form: a parser
// shared without protection would mix x and y between threads and fail here.
TEST(SizeField, EvaluationIsThreadSafe) {
  const auto h = SizeField::from_expression("0.1 + 0.08*sin(3*x)*cos(6*y)");
  const auto g = SizeField::from_expression("x*x + y");  // a second field, interleaved
  constexpr int kThreads = 8;
  std::vector<int> mismatches(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20000; ++i) {
        const double x = t + i * 1e-4, y = -t - i * 2e-4;
        if (h(x, y, 0) != paper_field(x, y)) ++mismatches[t];
        if (g(x, y, 0) != x * x + y) ++mismatches[t];
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(mismatches[t], 0) << "thread " << t;
}

TEST(SizeField, CopiesShareTheExpressionAndOutliveTheOriginal) {
  std::vector<SizeField> fields;
  for (int k = 1; k <= 100; ++k)  // more fields than the per-thread table keeps
    fields.push_back(SizeField::from_expression(std::to_string(k) + " * x"));
  for (int k = 1; k <= 100; ++k) EXPECT_DOUBLE_EQ(fields[k - 1](2, 0, 0), 2.0 * k);
  for (int k = 100; k >= 1; --k) EXPECT_DOUBLE_EQ(fields[k - 1](3, 0, 0), 3.0 * k);
}

TEST(SizeField, PositivityCheckNamesTheFirstBadNode) {
  const auto h = SizeField::from_expression("x - 0.5");
  const std::vector<double> good{1, 0, 0, 0.75, 2, 0};
  EXPECT_NO_THROW(h.check_positive_at(good, "mesh node"));
  const std::vector<double> bad{1, 0, 0, 0.5, 2, 0, 0.25, 0, 0};
  try {
    h.check_positive_at(bad, "mesh node");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("h = 0 at mesh node 1 (0.5, 2, 0)"));
    EXPECT_THAT(e.what(), HasSubstr("must be positive"));
  }
  // NaN (sqrt of a negative number) is not positive either.
  EXPECT_THROW(SizeField::from_expression("sqrt(x)").check_positive_at(std::vector<double>{-1, 0, 0},
                                                                       "node"),
               InputError);
}

TEST(SizeField, BoxCheckFindsANegativeRegion) {
  const std::array<double, 6> unit_square{0, 0, 0, 1, 1, 0};
  EXPECT_NO_THROW(SizeField::from_expression("0.1 + 0.08*sin(3*x)*cos(6*y)")
                      .check_positive_on_box({0, 0, 0, 1, 3, 0}));
  // Negative only for x > 0.9: the grid of 17 samples per side reaches x = 0.9375 and 1.
  EXPECT_THAT(
      [&] {
        try {
          SizeField::from_expression("0.9 - x").check_positive_on_box(unit_square);
        } catch (const InputError& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      HasSubstr("bounding box"));
}

// l^h (Paper I eq. 1) against closed forms.
TEST(SizeField, NormalizedEdgeLengthMatchesClosedForms) {
  // Constant h: l^h = |ab| / h.
  EXPECT_NEAR(normalized_edge_length(SizeField::constant(0.1), {0, 0, 0}, {0.3, 0.4, 0}), 5.0,
              1e-12);
  // h = 1 + x along x from 0 to 2: ∫ dx / (1 + x) = ln 3.
  EXPECT_NEAR(normalized_edge_length(SizeField::from_expression("1 + x"), {0, 0, 0}, {2, 0, 0}),
              std::log(3.0), 1e-8 * std::log(3.0));
  // Same field, segment run backwards and off-axis: (0,0,0)->(1,1,1), h = 1 + x,
  // |ab| = sqrt(3), ∫_0^1 dt / (1 + t) = ln 2.
  EXPECT_NEAR(normalized_edge_length(SizeField::from_expression("1 + x"), {1, 1, 1}, {0, 0, 0}),
              std::sqrt(3.0) * std::log(2.0), 1e-8);
  // h = exp(y): ∫_0^1 exp(-y) dy = 1 - 1/e.
  EXPECT_NEAR(normalized_edge_length(SizeField::from_expression("exp(y)"), {5, 0, 0}, {5, 1, 0}),
              1.0 - std::exp(-1.0), 1e-8);
  EXPECT_EQ(normalized_edge_length(SizeField::constant(1), {1, 2, 3}, {1, 2, 3}), 0.0);
  // h <= 0 on the segment: no finite length.
  EXPECT_TRUE(std::isinf(
      normalized_edge_length(SizeField::from_expression("x - 0.5"), {0, 0, 0}, {1, 0, 0})));
}

// Unit square split into two triangles along (0,0)-(1,1), h = 0.5: four sides of l^h = 2 and
// a diagonal of 2 sqrt(2); tau = 100 exp((4 (1/2 - 1) + (1/(2 sqrt 2) - 1)) / 5).
TEST(SizeField, EfficiencyIndexOfTwoTrianglesByHand) {
  Mesh m;
  m.node_tags = {1, 2, 3, 4};
  m.coords = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  ElementBlock t;
  t.type = find_element_type(2);
  t.tags = {1, 2};
  t.nodes = {0, 1, 2, 0, 2, 3};
  m.blocks = {t};
  const auto l = mesh_normalized_edge_lengths(m, SizeField::constant(0.5));
  ASSERT_EQ(l.size(), 5u);  // the diagonal is shared: counted once
  // Order by node pair: (0,1) (0,2) (0,3) (1,2) (2,3).
  EXPECT_NEAR(l[0], 2.0, 1e-12);
  EXPECT_NEAR(l[1], 2.0 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(l[2], 2.0, 1e-12);
  const double want = 100.0 * std::exp((4 * (0.5 - 1) + (1 / (2 * std::sqrt(2.0)) - 1)) / 5);
  EXPECT_NEAR(efficiency_index(l), want, 1e-12);
  // A unit mesh scores 100; l = 0.5 and l = 2 are equally far from it.
  EXPECT_DOUBLE_EQ(efficiency_index(std::vector<double>{1.0, 1.0}), 100.0);
  EXPECT_DOUBLE_EQ(efficiency_index(std::vector<double>{0.5}), efficiency_index(std::vector<double>{2.0}));
}

}  // namespace
}  // namespace quadval
