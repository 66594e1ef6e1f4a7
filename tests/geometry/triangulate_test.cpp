// The Gmsh front end, through the library: odd node counts on every model edge, Euler's
// count of triangles (Paper I eqs. 5-6), nodes on the geometry, and bad geometry.
#include "quadval/geometry.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>
#include <numbers>
#include <set>

#include "quadval/error.hpp"

namespace quadval {
namespace {

using testing::HasSubstr;

const char* kPaperField = "0.1 + 0.08*sin(3*x)*cos(6*y)";

std::filesystem::path scratch_dir() {
  const auto dir = std::filesystem::temp_directory_path() / "quadval_triangulate_test";
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path write_text(const std::string& name, const std::string& text) {
  const auto path = scratch_dir() / name;
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::size_t count_family(const Mesh& m, ElementFamily f) {
  std::size_t n = 0;
  for (const auto& b : m.blocks) n += b.type->family == f ? b.size() : 0;
  return n;
}

// Nodes used by triangles, and those on the boundary (edges held by one triangle), both
// found from the triangles alone.
struct TriangleCensus {
  std::set<NodeIndex> used, boundary;
  double area = 0;
};

TriangleCensus census(const Mesh& m) {
  TriangleCensus c;
  std::map<std::pair<NodeIndex, NodeIndex>, int> edge_use;
  for (const auto& b : m.blocks) {
    if (b.type->family != ElementFamily::triangle) continue;
    for (std::size_t e = 0; e < b.size(); ++e) {
      const auto n = b.element(e);
      const auto p0 = m.node(n[0]), p1 = m.node(n[1]), p2 = m.node(n[2]);
      c.area += 0.5 * std::abs((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]));
      for (int k = 0; k < 3; ++k) {
        c.used.insert(n[k]);
        const NodeIndex a = n[k], b2 = n[(k + 1) % 3];
        ++edge_use[{std::min(a, b2), std::max(a, b2)}];
      }
    }
  }
  for (const auto& [edge, uses] : edge_use)
    if (uses == 1) c.boundary.insert(edge.first), c.boundary.insert(edge.second);
  return c;
}

struct AlgorithmCase {
  TriangleAlgorithm algorithm;
  const char* name;
};

class TriangulateAlgorithms : public testing::TestWithParam<AlgorithmCase> {};

// Paper I's rectangle: every curve has an odd number of interior nodes, and Euler's formula
// (eq. 5) n_t = 2 (n_v - 1) - n_v^b with n_v^b from eq. 6 holds, so the count is even.
TEST_P(TriangulateAlgorithms, RectangleCurvesAreOddAndEulerHolds) {
  TriangulationOptions o;
  o.algorithm = GetParam().algorithm;
  o.size = SizeField::from_expression(kPaperField);
  const auto t = triangulate_planar_domain(parse_planar_domain("outer rectangle 0 0 1 3", "r"), o);
  ASSERT_EQ(t.curves.size(), 4u);
  std::size_t boundary_nodes = 0;
  for (const auto& c : t.curves) {
    EXPECT_TRUE(c.odd()) << "curve " << c.curve << ": " << c.interior_nodes;
    boundary_nodes += 1 + c.interior_nodes;  // eq. 6
  }
  const TriangleCensus c = census(t.mesh);
  EXPECT_EQ(c.boundary.size(), boundary_nodes);
  EXPECT_EQ(t.num_triangles, 2 * (c.used.size() - 1) - boundary_nodes);  // eq. 5
  EXPECT_EQ(t.num_triangles % 2, 0u);
  EXPECT_EQ(t.num_triangles, count_family(t.mesh, ElementFamily::triangle));
  ASSERT_EQ(t.surfaces.size(), 1u);
  EXPECT_TRUE(t.surfaces[0].even());
  // The triangles tile the rectangle exactly (area 3), and boundary nodes lie on its sides.
  EXPECT_NEAR(c.area, 3.0, 1e-12);
  for (NodeIndex n : c.boundary) {
    const auto p = t.mesh.node(n);
    const double d = std::min({std::abs(p[0]), std::abs(p[0] - 1), std::abs(p[1]), std::abs(p[1] - 3)});
    EXPECT_LT(d, 1e-12) << p[0] << " " << p[1];
    EXPECT_EQ(p[2], 0.0);
  }
  // Sizes follow h: Paper I §2 says triangle meshers give tau around 85 %, l^h within
  // [1/√2, √2]; anything under 75 % would mean the size field was not used.
  const auto lengths = mesh_normalized_edge_lengths(t.mesh, *o.size);
  EXPECT_GT(efficiency_index(lengths), 75.0) << GetParam().name;
}

INSTANTIATE_TEST_SUITE_P(
    Gmsh, TriangulateAlgorithms,
    testing::Values(AlgorithmCase{TriangleAlgorithm::frontal_quad, "frontal_quad"},
                    AlgorithmCase{TriangleAlgorithm::frontal, "frontal"},
                    AlgorithmCase{TriangleAlgorithm::delaunay, "delaunay"}),
    [](const auto& info) { return std::string(info.param.name); });

// Without the 1D recombination switch, Gmsh's plain 1D mesh of this rectangle has curves with
// an even interior count (seen with Gmsh 4.8.4, algorithm 6): the switch is what makes them
// odd, not luck.
TEST(Triangulate, PlainCurveMeshingGivesSomeEvenCurves) {
  TriangulationOptions o;
  o.algorithm = TriangleAlgorithm::frontal;
  o.size = SizeField::from_expression(kPaperField);
  o.odd_curve_nodes = false;
  const auto t = triangulate_planar_domain(parse_planar_domain("outer rectangle 0 0 1 3", "r"), o);
  EXPECT_LT(t.num_odd_curves(), t.curves.size());
}

// Square with a hole (Paper I §8.1): Euler for a domain with one hole,
// n_t = 2 (n_v - 1) - n_v^b + 2, nodes on the sides or on the circle.
TEST(Triangulate, SquareWithAHoleIsEvenAndOnTheGeometry) {
  TriangulationOptions o;
  o.size = SizeField::from_expression("0.02 + 0.2*min(x, 1-x, y, 1-y)");
  const auto t = triangulate_planar_domain(
      parse_planar_domain("outer rectangle 0 0 1 1; hole circle 0.75 0.75 0.15", "sq"), o);
  EXPECT_EQ(t.curves.size(), 5u);  // four sides and the closed circle
  EXPECT_TRUE(t.all_curves_odd());
  std::size_t boundary_nodes = 0;
  for (const auto& c : t.curves) boundary_nodes += 1 + c.interior_nodes;
  const TriangleCensus c = census(t.mesh);
  EXPECT_EQ(c.boundary.size(), boundary_nodes);
  EXPECT_EQ(t.num_triangles, 2 * (c.used.size() - 1) - boundary_nodes + 2);
  EXPECT_EQ(t.num_triangles % 2, 0u);
  for (NodeIndex n : c.boundary) {
    const auto p = t.mesh.node(n);
    const double side = std::min({std::abs(p[0]), std::abs(p[0] - 1), std::abs(p[1]), std::abs(p[1] - 1)});
    const double circle = std::abs(std::hypot(p[0] - 0.75, p[1] - 0.75) - 0.15);
    EXPECT_LT(std::min(side, circle), 1e-12) << p[0] << " " << p[1];
  }
  // The triangles tile the square minus the polygon of the hole's boundary nodes (shoelace
  // over those nodes sorted by angle around the centre).
  std::vector<std::pair<double, std::array<double, 3>>> on_circle;
  for (NodeIndex n : c.boundary) {
    const auto p = t.mesh.node(n);
    if (std::abs(std::hypot(p[0] - 0.75, p[1] - 0.75) - 0.15) < 1e-12)
      on_circle.push_back({std::atan2(p[1] - 0.75, p[0] - 0.75), p});
  }
  std::sort(on_circle.begin(), on_circle.end());
  double hole = 0;
  for (std::size_t i = 0; i < on_circle.size(); ++i) {
    const auto& a = on_circle[i].second;
    const auto& b = on_circle[(i + 1) % on_circle.size()].second;
    hole += 0.5 * (a[0] * b[1] - b[0] * a[1]);
  }
  EXPECT_NEAR(c.area, 1 - hole, 1e-12);
  EXPECT_LT(hole, std::numbers::pi * 0.0225);  // inscribed in the disk
}

// A solid: only its six faces are meshed, each with an even count, and the volume is named.
TEST(Triangulate, BoxFileGivesAnEvenSurfaceMesh) {
  const auto path = write_text("box.geo", "SetFactory(\"OpenCASCADE\");\nBox(1) = {0,0,0,1,2,3};\n");
  TriangulationOptions o;
  o.size = SizeField::constant(0.25);
  const auto t = triangulate_geometry_file(path, o);
  EXPECT_EQ(t.surfaces.size(), 6u);
  EXPECT_EQ(t.num_volumes_skipped, 1u);
  EXPECT_TRUE(t.all_curves_odd());
  for (const auto& s : t.surfaces) EXPECT_TRUE(s.even()) << "surface " << s.surface;
  EXPECT_EQ(t.mesh.dimension(), 2);
  // Every node on the surface of the box [0,1]x[0,2]x[0,3].
  for (std::size_t i = 0; i < t.mesh.num_nodes(); ++i) {
    const auto p = t.mesh.node(static_cast<NodeIndex>(i));
    const double d = std::min({std::abs(p[0]), std::abs(p[0] - 1), std::abs(p[1]), std::abs(p[1] - 2),
                               std::abs(p[2]), std::abs(p[2] - 3)});
    EXPECT_LT(d, 1e-9);
  }
}

TEST(Triangulate, BadGeometryGivesClearErrors) {
  TriangulationOptions o;
  o.size = SizeField::constant(0.1);
  const auto dir = scratch_dir();
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(dir / "missing.geo", o); }),
              HasSubstr("missing.geo: no such file"));
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(write_text("m.msh", "x"), o); }),
              HasSubstr("this is a mesh, not a geometry"));
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(write_text("a.iges2", "x"), o); }),
              HasSubstr("unknown geometry extension '.iges2'"));
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(write_text("empty.geo", ""), o); }),
              HasSubstr("the file is empty"));
  EXPECT_THAT(
      error_of([&] { triangulate_geometry_file(write_text("comments.geo", "// nothing\n"), o); }),
      HasSubstr("no surfaces to mesh: the model has 0 points, 0 curves, 0 surfaces and 0 volumes"));
  EXPECT_THAT(error_of([&] {
                triangulate_geometry_file(
                    write_text("curve.geo", "Point(1) = {0,0,0};\nPoint(2) = {1,0,0};\nLine(1) = {1,2};\n"), o);
              }),
              HasSubstr("no surfaces to mesh: the model has 2 points, 1 curves"));
  EXPECT_THAT(error_of([&] {
                triangulate_geometry_file(
                    write_text("bad.geo", "Point(1) = {0,0,0};\nLine(1) = {1,2};\n"), o);
              }),
              HasSubstr("Gmsh failed to read the file"));
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(write_text("junk.step", "garbage\n"), o); }),
              HasSubstr("Could not read file"));
}

TEST(Triangulate, NonPositiveSizeFieldIsRefusedBeforeOrDuringMeshing) {
  const auto square = parse_planar_domain("outer rectangle 0 0 1 1", "sq");
  TriangulationOptions o;
  o.size = SizeField::from_expression("x - 0.5");  // negative on the left half
  EXPECT_THAT(error_of([&] { triangulate_planar_domain(square, o); }),
              HasSubstr("must be positive"));
  // A geometry file: h is checked at the model's points first.
  const auto path = write_text("sq.geo",
                               "Point(1)={0,0,0};Point(2)={1,0,0};Point(3)={1,1,0};Point(4)={0,1,0};"
                               "Line(1)={1,2};Line(2)={2,3};Line(3)={3,4};Line(4)={4,1};"
                               "Curve Loop(1)={1,2,3,4};Plane Surface(1)={1};\n");
  o.size = SizeField::from_expression("y - 0.5");
  EXPECT_THAT(error_of([&] { triangulate_geometry_file(path, o); }),
              HasSubstr("at geometry point"));
}

}  // namespace
}  // namespace quadval
