// Planar elements of the highest orders Gmsh defines (triangles and quadrangles of orders 9
// and 10, complete and incomplete), made by Gmsh itself (make_wavy_high_order.py: a square
// with a wavy edge, meshed coarsely so that some elements along the wave fold), analysed
// by us and by Gmsh 4.8.4's AnalyseMeshQuality plugin (../shared/data/tools/
// gmsh_analyse.py): every element is analysed and decided, and our set of invalid
// elements equals Gmsh's (minJ/maxJ <= 0; none of these is inverted everywhere, the one
// case where the two may differ, see gmsh_agreement_test.cpp).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>

#include <unistd.h>

#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

struct HighOrderCase {
  const char* family;  // triangle | quadrangle
  int order;
  const char* kind;  // complete | incomplete
};

class GmshHighOrderTest : public testing::TestWithParam<HighOrderCase> {};

TEST_P(GmshHighOrderTest, InvalidSetEqualsGmsh) {
  const HighOrderCase c = GetParam();
  const auto dir = std::filesystem::temp_directory_path() /
                   fmt::format("quadval_gmsh_high_order_{}_{}_{}_{}", c.family, c.order, c.kind, ::getpid());
  std::filesystem::create_directories(dir);
  const std::string msh = (dir / "wavy.msh").string(), csv = (dir / "wavy.gmsh.csv").string();
  ASSERT_EQ(std::system(fmt::format("'{}' '{}/tests/analysis/make_wavy_high_order.py' {} {} {} '{}'",
                                    QUADVAL_PYTHON, QUADVAL_SOURCE_DIR, c.family, c.order, c.kind, msh)
                            .c_str()),
            0);
  ASSERT_EQ(std::system(fmt::format("'{}' '{}/data/tools/gmsh_analyse.py' '{}' --measures J --csv '{}' --quiet "
                                    ">/dev/null",
                                    QUADVAL_PYTHON, QUADVAL_SHARED_DIR, msh, csv)
                            .c_str()),
            0);
  const Mesh mesh = read_mesh(msh);
  const auto gmsh = test::read_gmsh_ratios(csv);
  const CheckReport r = check_mesh(mesh, CheckOptions{}, msh);
  std::filesystem::remove_all(dir);

  ASSERT_EQ(r.elements.size(), gmsh.size());
  std::set<Tag> ours, theirs;
  std::size_t of_order = 0;
  for (const ElementCheck& e : r.elements) {
    ASSERT_TRUE(e.analysed) << e.type->name << " " << e.tag << " not analysed";
    EXPECT_NE(e.bounds.validity, Validity::undetermined) << e.tag;
    if (e.type->order == c.order) ++of_order;
    if (e.bounds.validity == Validity::invalid) ours.insert(e.tag);
    ASSERT_TRUE(gmsh.count(e.tag)) << e.tag;
    if (gmsh.at(e.tag) <= 0) theirs.insert(e.tag);
  }
  EXPECT_GT(of_order, 50u);
  EXPECT_GE(theirs.size(), 2u) << "the mesh should hold folded elements";
  EXPECT_LT(theirs.size(), r.elements.size() / 4) << "and mostly valid ones";
  EXPECT_EQ(ours, theirs);
}

INSTANTIATE_TEST_SUITE_P(
    Orders9And10, GmshHighOrderTest,
    testing::Values(HighOrderCase{"triangle", 9, "complete"}, HighOrderCase{"triangle", 10, "complete"},
                    HighOrderCase{"triangle", 10, "incomplete"}, HighOrderCase{"quadrangle", 9, "complete"},
                    HighOrderCase{"quadrangle", 10, "complete"}, HighOrderCase{"quadrangle", 10, "incomplete"}),
    [](const testing::TestParamInfo<HighOrderCase>& i) {
      return fmt::format("{}{}{}", i.param.family, i.param.order, i.param.kind[0] == 'c' ? "" : "_incomplete");
    });

}  // namespace
}  // namespace quadval
