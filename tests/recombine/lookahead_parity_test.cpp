// Odd connected pieces (issue 8): a region made of several pieces with odd counts gets one
// boundary-edge split per odd piece, so that the look-ahead criterion can run on it.
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "quadval/error.hpp"
#include "quadval/recombine.hpp"
#include "recombine/lookahead_parity.hpp"
#include "recombine/test_meshes.hpp"
#include "recombine/triangle_input.hpp"

namespace quadval {
namespace {

using recombine_detail::TriangleSurface;

// Cells (i, j), 0 <= j < 3, of a grid of unit squares, i in [0, 3) (left piece) and [4, 7)
// (right piece), each cut along a-c; in each piece the triangle (a, c, d) of its first cell is
// left out: two pieces of 17 triangles, 34 in the one region.
Mesh two_odd_pieces() {
  std::vector<std::array<double, 2>> xy;
  for (int j = 0; j <= 3; ++j)
    for (int i = 0; i <= 7; ++i) xy.push_back({double(i), double(j)});
  auto id = [](int i, int j) { return static_cast<NodeIndex>(j * 8 + i); };
  std::vector<std::array<NodeIndex, 3>> tris;
  for (int first : {0, 4})
    for (int j = 0; j < 3; ++j)
      for (int i = first; i < first + 3; ++i) {
        const NodeIndex a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
        tris.push_back({a, b, c});
        if (!(i == first && j == 0)) tris.push_back({a, c, d});
      }
  return test::make_triangle_mesh(xy, tris);
}

// Components over shared edges (by node pairs, same region), computed here.
std::vector<std::size_t> piece_sizes(const TriangleSurface& s) {
  std::map<std::pair<NodeIndex, NodeIndex>, std::vector<std::uint32_t>> by_edge;
  for (std::uint32_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const NodeIndex a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      by_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  std::vector<std::uint32_t> root(s.triangles.size());
  for (std::uint32_t t = 0; t < root.size(); ++t) root[t] = t;
  auto find = [&](std::uint32_t t) {
    while (root[t] != t) t = root[t];
    return t;
  };
  for (const auto& [edge, ts] : by_edge)
    if (ts.size() == 2 && s.region[ts[0]] == s.region[ts[1]]) root[find(ts[0])] = find(ts[1]);
  std::map<std::uint32_t, std::size_t> count;
  for (std::uint32_t t = 0; t < root.size(); ++t) ++count[find(t)];
  std::vector<std::size_t> sizes;
  for (const auto& [r, n] : count) sizes.push_back(n);
  return sizes;
}

double area(const TriangleSurface& s) {
  double a = 0;
  for (const auto& t : s.triangles) {
    const double* p = &s.coords[3 * t[0]];
    const double* q = &s.coords[3 * t[1]];
    const double* r = &s.coords[3 * t[2]];
    a += 0.5 * std::abs((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
  }
  return a;
}

TEST(LookaheadParity, EachOddPieceOfARegionGetsOneSplit) {
  std::vector<std::string> warnings;
  TriangleSurface s = recombine_detail::prepare_triangles(two_odd_pieces(), "two", warnings);
  ASSERT_EQ(s.triangles.size(), 34u);
  EXPECT_EQ(piece_sizes(s), (std::vector<std::size_t>{17, 17}));
  TriangleSurface by_region = s;
  recombine_detail::make_regions_even(by_region);  // the region is even: nothing to do
  EXPECT_EQ(by_region.odd_splits, 0u);

  const std::vector<std::int32_t> region_before = s.region;
  recombine_detail::make_pieces_even(s);
  EXPECT_EQ(s.odd_splits, 2u);
  EXPECT_TRUE(s.odd_regions_left.empty());
  EXPECT_EQ(piece_sizes(s), (std::vector<std::size_t>{18, 18}));
  ASSERT_EQ(s.region.size(), 36u);
  EXPECT_EQ(s.region_entity, std::vector<int>{1});
  for (std::int32_t r : s.region) EXPECT_EQ(r, 0);
  EXPECT_TRUE(std::equal(region_before.begin(), region_before.end(), s.region.begin()));
  EXPECT_EQ(s.forbidden_pairs.size(), 2u);
  EXPECT_NEAR(area(s), 2 * 8.5, 1e-12);  // 2 pieces of 9 unit cells less half a cell
}

TEST(LookaheadParity, OnePiecePerRegionIsExactlyTheRegionSplit) {
  // Odd and even single-piece regions: make_pieces_even must equal make_regions_even.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Mesh m = test::random_grid_mesh(5, 4, seed, 1, false);
    std::vector<std::string> warnings;
    TriangleSurface a = recombine_detail::prepare_triangles(m, "grid", warnings);
    if (piece_sizes(a).size() != 1) continue;
    TriangleSurface b = a;
    recombine_detail::make_regions_even(a);
    recombine_detail::make_pieces_even(b);
    EXPECT_EQ(a.triangles, b.triangles) << seed;
    EXPECT_EQ(a.coords, b.coords) << seed;
    EXPECT_EQ(a.region, b.region) << seed;
    EXPECT_EQ(a.odd_splits, b.odd_splits) << seed;
  }
}

TEST(LookaheadParity, RecombineHandlesTwoOddPieces) {
  RecombineOptions o;
  o.algorithm = RecombineAlgorithm::lookahead;
  o.lookahead.horizon = 3;
  o.full_quad = true;
  const RecombineResult r = recombine(two_odd_pieces(), o);
  EXPECT_EQ(r.stats.odd_splits, 2u);
  EXPECT_EQ(r.stats.triangles, 0u);
  EXPECT_GT(r.stats.quads, 0u);
  for (const auto& b : r.mesh.blocks) EXPECT_EQ(b.type->gmsh_id, 3);
  // The left-out policy keeps the pieces odd: the criterion cannot run, a clear InputError.
  o.odd_policy = OddPolicy::leave_triangle;
  EXPECT_THROW(recombine(two_odd_pieces(), o), InputError);
}

TEST(LookaheadParity, BlossomIsAllQuadOnTwoOddPieces) {
  // Two pieces of 17 triangles: each needs its own split for a perfect matching to exist.
  RecombineOptions o;
  o.algorithm = RecombineAlgorithm::blossom;
  const RecombineResult r = recombine(two_odd_pieces(), o);
  EXPECT_EQ(r.stats.odd_splits, 2u);
  EXPECT_TRUE(r.stats.perfect_matching);
  EXPECT_EQ(r.stats.triangles, 0u);
  for (const auto& b : r.mesh.blocks) EXPECT_EQ(b.type->gmsh_id, 3);
}

}  // namespace
}  // namespace quadval
