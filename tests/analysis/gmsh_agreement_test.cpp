// Agreement with Gmsh 4.8.4's AnalyseMeshQuality (AnalyseCurvedMesh) on the curved meshes
// of ../shared/data/curved: our set of invalid elements equals Gmsh's (minJ/maxJ <= 0),
// and every difference is explained and checked here by dense sampling of J from the
// Lagrange shape functions:
//   - Gmsh reports minJ/maxJ of an element inverted everywhere (J < 0 at every point) as a
//     positive ratio (two negatives), so it does not flag it; we call it invalid, and
//     sampling finds J < 0 at every sample point;
//   - elements of a family or order not analysed are skipped (reported, never valid).
// Also: the results do not depend on the thread count.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/io.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using test::read_gmsh_ratios;

class GmshAgreementTest : public testing::TestWithParam<const char*> {};

TEST_P(GmshAgreementTest, InvalidSetsAgreeAndDifferencesAreExplained) {
  const std::string base = std::string(QUADVAL_SHARED_DIR) + "/data/curved/" + GetParam();
  const Mesh mesh = read_mesh(base + ".msh");
  const auto gmsh = read_gmsh_ratios(base + ".gmsh.csv");
  CheckOptions opts;
  opts.threads = 2;
  const CheckReport r = check_mesh(mesh, opts, base + ".msh");
  ASSERT_EQ(r.elements.size(), gmsh.size());

  // element tag -> its node coordinates
  std::map<Tag, std::vector<double>> coords;
  for (const ElementBlock& b : mesh.blocks)
    for (std::size_t e = 0; e < b.size(); ++e) {
      std::vector<double> x = test::element_coordinates(mesh, b, e);
      coords[b.tags[e]] = std::move(x);
    }
  std::mt19937 rng(1);
  std::size_t agree = 0, inverted_everywhere = 0, skipped = 0;
  for (const ElementCheck& e : r.elements) {
    ASSERT_TRUE(gmsh.count(e.tag)) << e.tag;
    const bool gmsh_invalid = gmsh.at(e.tag) <= 0;
    if (!e.analysed) {  // a family or order not analysed (yet): said so, never valid
      ++skipped;
      continue;
    }
    EXPECT_NE(e.bounds.validity, Validity::undetermined) << e.tag;
    const bool ours_invalid = e.bounds.validity == Validity::invalid;
    if (ours_invalid == gmsh_invalid) {
      ++agree;
      continue;
    }
    // The only difference allowed: inverted everywhere, which Gmsh's ratio hides.
    ASSERT_TRUE(ours_invalid) << "Gmsh calls " << e.tag << " invalid, we call it "
                              << validity_name(e.bounds.validity);
    EXPECT_LT(e.bounds.jmax_upper, 0) << e.tag;
    EXPECT_GT(gmsh.at(e.tag), 0) << e.tag;
    const LagrangeBasis& lb = lagrange_basis(*e.type);
    double smax = -INFINITY;
    for (const auto& p : test::dense_points(e.type->family, 6, 50, rng))
      smax = std::max(smax, test::jacobian_at(lb, coords.at(e.tag), p, r.planar));
    EXPECT_LT(smax, 0) << e.tag << ": sampling finds J >= 0 somewhere";
    ++inverted_everywhere;
  }
  std::cout << GetParam() << ": " << agree << " agree, " << inverted_everywhere
            << " inverted everywhere (Gmsh's ratio > 0), " << skipped << " skipped\n";

  // Same answers and bounds with one thread.
  opts.threads = 1;
  const CheckReport r1 = check_mesh(mesh, opts, base + ".msh");
  EXPECT_EQ(check_csv(r1), check_csv(r));
}

INSTANTIATE_TEST_SUITE_P(CurvedMeshes, GmshAgreementTest,
                         testing::Values("tri_h0.4_o4", "quad_h0.4_o2", "tets_h0.8_o2",
                                         "hex_box_N20_amp0.35_seed777", "mixed_h0.6_o2",
                                         "warped_hexahedron_o2_N6_a0.25", "warped_prism_o2_N6_a0.25",
                                         "warped_tetrahedron_o3_N6_a0.25"));

}  // namespace
}  // namespace quadval
