#include "quadval/planar_domain.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "quadval/error.hpp"

namespace quadval {
namespace {

using testing::HasSubstr;

std::string error_of(const std::string& text) {
  try {
    (void)parse_planar_domain(text, "dom.txt");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(PlanarDomain, ParsesPaperOneSquareWithAHole) {
  const auto d = parse_planar_domain(
      "# Paper I, section 8.1\n"
      "outer rectangle 0 0 1 1\n"
      "\n"
      "hole circle 0.75 0.75 0.15   # radius 0.15\n",
      "dom.txt");
  ASSERT_EQ(d.outer.kind, DomainLoop::Kind::polygon);
  ASSERT_EQ(d.outer.vertices.size(), 4u);
  ASSERT_EQ(d.holes.size(), 1u);
  EXPECT_EQ(d.holes[0].kind, DomainLoop::Kind::circle);
  EXPECT_EQ(d.holes[0].line, 4);
  EXPECT_DOUBLE_EQ(d.holes[0].radius, 0.15);
  EXPECT_NEAR(domain_area(d), 1.0 - std::numbers::pi * 0.0225, 1e-15);
  // Distances by hand: (0.5, 0.5) is 0.5 from the sides and sqrt(0.125) - 0.15 from the hole.
  EXPECT_NEAR(distance_to_boundary(d, 0.5, 0.5), std::sqrt(0.125) - 0.15, 1e-15);
  EXPECT_NEAR(distance_to_boundary(d, 0.1, 0.3), 0.1, 1e-15);
  EXPECT_NEAR(distance_to_boundary(d, 0.75, 0.6), 0.0, 1e-15);
  EXPECT_TRUE(domain_contains(d, 0.5, 0.5));
  EXPECT_FALSE(domain_contains(d, 0.75, 0.75));  // in the hole
  EXPECT_FALSE(domain_contains(d, 1.5, 0.5));
  EXPECT_TRUE(domain_contains(d, 1.0, 0.5));  // on the boundary
  const auto box = domain_bounding_box(d);
  EXPECT_EQ(box, (std::array<double, 6>{0, 0, 0, 1, 1, 0}));
}

TEST(PlanarDomain, SemicolonsSeparateStatementsOnTheCommandLine) {
  const auto d = parse_planar_domain(
      "outer polygon 0 0 0 2 2 2 2 0; hole polygon 0.5 0.5 1 0.5 1 1; hole circle 1.5 1.5 0.2",
      "<command line>");
  EXPECT_EQ(d.holes.size(), 2u);
  EXPECT_EQ(d.holes[1].line, 3);
  // Given clockwise, stored counterclockwise (shoelace area positive).
  double s = 0;
  const auto& v = d.outer.vertices;
  for (std::size_t i = 0; i < v.size(); ++i)
    s += v[i][0] * v[(i + 1) % v.size()][1] - v[(i + 1) % v.size()][0] * v[i][1];
  EXPECT_GT(s, 0);
  EXPECT_NEAR(domain_area(d), 4.0 - 0.125 - std::numbers::pi * 0.04, 1e-14);
}

TEST(PlanarDomain, CircleOuterBoundary) {
  const auto d = parse_planar_domain("outer circle 1 2 3\nhole rectangle 0 1 2 3", "dom.txt");
  EXPECT_EQ(domain_bounding_box(d), (std::array<double, 6>{-2, -1, 0, 4, 5, 0}));
  EXPECT_NEAR(domain_area(d), 9 * std::numbers::pi - 4, 1e-13);
  EXPECT_NEAR(distance_to_boundary(d, 1, 2), 1.0, 1e-15);  // rectangle side x = 0 or 2
}

struct BadCase {
  const char* text;
  const char* message;
};

const BadCase kBadCases[] = {
    {"", "no 'outer' boundary"},
    {"hole circle 0 0 1", "no 'outer' boundary"},
    {"outer rectangle 0 0 1 1\nouter circle 0 0 1", "dom.txt:2: second 'outer'"},
    {"outer square 0 0 1 1", "dom.txt:1: unknown shape 'square'"},
    {"inner circle 0 0 1", "dom.txt:1: unknown statement 'inner'"},
    {"outer", "dom.txt:1: expected a shape"},
    {"outer circle 0 0", "circle needs cx cy r, got 2 numbers"},
    {"outer circle 0 0 -1", "radius -1 is not positive"},
    {"outer circle 0 0 1e999", "'1e999' is not a finite number"},
    {"outer circle 0 zero 1", "'zero' is not a finite number"},
    {"outer rectangle 1 0 0 1", "x0 < x1"},
    {"outer polygon 0 0 1 0 1", "x y pairs"},
    {"outer polygon 0 0 1 0", "at least 3 vertices"},
    {"outer polygon 0 0 1 0 1 1 0 0", "vertices 4 and 1 coincide"},
    {"outer polygon 0 0 1 1 1 0 0 1", "side 1 touches side 3"},  // bow tie
    {"outer polygon 0 0 2 0 1 0", "folds back"},
    {"outer polygon 0 0 1 0 2 0", "folds back on itself at vertex 3"},  // flat: 2,0 -> 0,0
    {"\n\nouter rectangle 0 0 1 1\nhole circle 0.9 0.5 0.2", "dom.txt:4: hole is not strictly inside"},
    {"outer rectangle 0 0 1 1\nhole circle 0.5 0.5 0.5", "hole is not strictly inside"},  // touches
    {"outer circle 0 0 1\nhole rectangle 0 0 1 0.5", "hole is not strictly inside"},
    {"outer rectangle 0 0 1 1\nhole polygon 0.5 0.5 1.5 0.5 0.5 0.6", "not strictly inside"},
    {"outer rectangle 0 0 4 4\nhole circle 1 1 0.5\nhole circle 2 1 0.5",
     "dom.txt:3: hole overlaps or touches the hole on line 2"},
    {"outer rectangle 0 0 4 4\nhole rectangle 1 1 2 2\nhole circle 2.3 1.5 0.4",
     "overlaps or touches"},
    {"outer rectangle 0 0 4 4\nhole rectangle 1 1 3 3\nhole rectangle 1.5 1.5 2 2",
     "overlaps or touches"},  // nested holes: no edge crossing, containment caught
};

TEST(PlanarDomain, RejectsBadInputWithLineAndReason) {
  for (const auto& c : kBadCases) EXPECT_THAT(error_of(c.text), HasSubstr(c.message)) << c.text;
}

TEST(PlanarDomain, ReadsAFileAndNamesAMissingOne) {
  const auto dir = std::filesystem::temp_directory_path() / "quadval_planar_domain_test";
  std::filesystem::create_directories(dir);
  const auto path = dir / "d.txt";
  std::ofstream(path) << "outer circle 0 0 1\n";
  EXPECT_EQ(read_planar_domain(path).outer.kind, DomainLoop::Kind::circle);
  try {
    (void)read_planar_domain(dir / "missing.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing.txt: cannot open"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace quadval
