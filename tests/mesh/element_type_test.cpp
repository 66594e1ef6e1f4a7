#include "quadval/element_type.hpp"

#include <gtest/gtest.h>

#include <set>

namespace quadval {
namespace {

// Node count of a Lagrange type from its family and order (closed forms): complete
// types hold every node of the order-p lattice, incomplete types vertices and edge nodes.
int expected_num_nodes(ElementFamily f, int p, bool complete) {
  const int e = p - 1;  // nodes inside each edge
  switch (f) {
    case ElementFamily::point: return 1;
    case ElementFamily::line: return p + 1;
    case ElementFamily::triangle: return complete ? (p + 1) * (p + 2) / 2 : 3 + 3 * e;
    case ElementFamily::quadrangle: return complete ? (p + 1) * (p + 1) : 4 + 4 * e;
    case ElementFamily::tetrahedron: return complete ? (p + 1) * (p + 2) * (p + 3) / 6 : 4 + 6 * e;
    case ElementFamily::hexahedron: return complete ? (p + 1) * (p + 1) * (p + 1) : 8 + 12 * e;
    case ElementFamily::prism: return complete ? (p + 1) * (p + 1) * (p + 2) / 2 : 6 + 9 * e;
    case ElementFamily::pyramid:
      return complete ? (p + 1) * (p + 2) * (2 * p + 3) / 6 : 5 + 8 * e;
    default: return -1;
  }
}

TEST(ElementType, IdsAreSortedUniqueAndFindable) {
  std::set<int> seen;
  int previous = 0;
  for (const ElementType& t : element_types()) {
    EXPECT_GT(t.gmsh_id, previous);
    previous = t.gmsh_id;
    EXPECT_TRUE(seen.insert(t.gmsh_id).second);
    EXPECT_EQ(find_element_type(t.gmsh_id), &t);
  }
  EXPECT_EQ(seen.size(), 137u);  // 1..140 less the three ids Gmsh leaves unused (76-78)
  EXPECT_EQ(find_element_type(0), nullptr);
  EXPECT_EQ(find_element_type(76), nullptr);
  EXPECT_EQ(find_element_type(141), nullptr);
}

TEST(ElementType, LagrangeNodeCountsFollowFromFamilyAndOrder) {
  for (const ElementType& t : element_types()) {
    if (!t.has_lagrange_basis) continue;
    SCOPED_TRACE(std::string(t.name));
    EXPECT_EQ(t.num_nodes, expected_num_nodes(t.family, t.order, t.complete));
    EXPECT_EQ(t.dim, family_dimension(t.family));
  }
}

TEST(ElementType, FindByFamilyAndOrder) {
  EXPECT_EQ(find_element_type(ElementFamily::triangle, 2, true)->gmsh_id, 9);
  EXPECT_EQ(find_element_type(ElementFamily::quadrangle, 2, false)->gmsh_id, 16);
  EXPECT_EQ(find_element_type(ElementFamily::hexahedron, 9, true)->gmsh_id, 98);
  EXPECT_EQ(find_element_type(ElementFamily::pyramid, 3, false)->gmsh_id, 125);
  EXPECT_EQ(find_element_type(ElementFamily::tetrahedron, 3, false)->gmsh_id, 137);
  EXPECT_EQ(find_element_type(ElementFamily::line, 1, false)->gmsh_id, 1);
  EXPECT_EQ(find_element_type(ElementFamily::line, 11, true), nullptr);
}

}  // namespace
}  // namespace quadval
