// SparseRows (sparse_rows.hpp) against the dense map it was built from: the same sums bit
// for bit (one row at a time, and four rows in lanes), on the node maps of real element
// types and on random maps with zeros and signed zeros.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "analysis/mu_space.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "analysis/sparse_rows.hpp"
#include "quadval/element_type.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

// out[a] = sum over every entry of row r, zeros included, of entry * d[3 i + a], from +0.
void dense_row(const std::vector<double>& map, std::size_t r, std::size_t n, const double* d, double out[3]) {
  for (std::size_t a = 0; a < 3; ++a) {
    double s = 0;
    for (std::size_t i = 0; i < n; ++i) s += map[r * n + i] * d[3 * i + a];
    out[a] = s;
  }
}

void expect_same_bits(double a, double b, const char* what) {
  EXPECT_EQ(std::signbit(a), std::signbit(b)) << what;
  EXPECT_EQ(a, b) << what;
}

// Every row of `map` (rows x n) against its SparseRows, on random points, some planar.
void check_map(const std::vector<double>& map, std::size_t rows, std::size_t n, std::mt19937& rng) {
  const SparseRows sparse = SparseRows::of(map, rows, n);
  ASSERT_EQ(sparse.start.size(), rows + 1);
  std::size_t nonzero = 0;
  for (double v : map) nonzero += v != 0;
  EXPECT_EQ(sparse.value.size(), nonzero);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 4; ++trial) {
    const bool flat = trial % 2 == 1;
    std::vector<double> d(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t a = 0; a < 3; ++a) d[3 * i + a] = flat && a == 2 ? 0.0 : u(rng);
    if (trial == 2) d[0] = -0.0;  // a signed zero among the points
    for (std::size_t r = 0; r < rows; ++r) {
      double want[3], got[3];
      dense_row(map, r, n, d.data(), want);
      sparse.row_times_points(r, d.data(), got);
      for (int a = 0; a < 3; ++a) expect_same_bits(got[a], want[a], "row_times_points");
      if (flat) {
        sparse.row_times_flat_points(r, d.data(), got);
        for (int a = 0; a < 3; ++a) expect_same_bits(got[a], want[a], "row_times_flat_points");
      }
      // Four rows at once, lane r % 4 of block r / 4 (the z sum skipped where flat, +0).
      Lanes<4> lanes[3] = {};
      if (flat)
        sparse.four_rows_times_points<2>(r / 4, d.data(), lanes);
      else
        sparse.four_rows_times_points<3>(r / 4, d.data(), lanes);
      for (int a = 0; a < 3; ++a) expect_same_bits(lanes[a][r % 4], want[a], "four_rows_times_points");
    }
    // All rows at once, by blocks of four and row by row (the path for non-finite points).
    for (const bool finite : {true, false}) {
      std::vector<double> all(3 * rows);
      sparse.times_points(d.data(), flat, finite, all.data());
      for (std::size_t r = 0; r < rows; ++r) {
        double want[3];
        dense_row(map, r, n, d.data(), want);
        for (std::size_t a = 0; a < 3; ++a) expect_same_bits(all[a * rows + r], want[a], "times_points");
      }
    }
    // Four flat point sets in lanes (this one in lane trial, others scaled): each lane the
    // bits of its own rows.
    if (flat) {
      std::vector<Lanes<4>> dl(2 * n), out(2 * rows);
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t a = 0; a < 2; ++a)
          for (std::size_t l = 0; l < 4; ++l) dl[2 * i + a][l] = l == 1 ? d[3 * i + a] : (1.0 + 0.1 * l) * d[3 * i + a];
      sparse.rows_times_planar_lanes(dl.data(), out.data());
      for (std::size_t l = 0; l < 4; ++l) {
        std::vector<double> dd(3 * n);
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t a = 0; a < 2; ++a) dd[3 * i + a] = dl[2 * i + a][l];
        for (std::size_t r = 0; r < rows; ++r) {
          double want[3];
          dense_row(map, r, n, dd.data(), want);
          for (std::size_t a = 0; a < 2; ++a) expect_same_bits(out[a * rows + r][l], want[a], "rows_times_planar_lanes");
        }
      }
    }
    // Lanes past the last row are +0.
    if (rows % 4 != 0) {
      Lanes<4> lanes[3] = {};
      sparse.four_rows_times_points<3>(rows / 4, d.data(), lanes);
      for (std::size_t l = rows % 4; l < 4; ++l)
        for (int a = 0; a < 3; ++a) expect_same_bits(lanes[a][l], 0.0, "lane past the last row");
    }
  }
}

TEST(SparseRows, NodeMapsOfElementTypesGiveTheDenseSums) {
  std::mt19937 rng(3);
  // Quadratic and quartic triangles, quadratic quadrangles, cubic tetrahedra, quadratic
  // prisms, hexahedra and pyramids.
  for (const int id : {9, 23, 10, 29, 18, 12, 14}) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(type.name);
    const auto n = static_cast<std::size_t>(type.num_nodes);
    if (mu_supported(type)) {
      const MuSpace& mu = mu_space(type);
      for (int c = 0; c < type.dim; ++c) check_map(mu.derivative(c), static_cast<std::size_t>(mu.w_size()), n, rng);
    }
    const ScaledJacobianSpace& sj = scaled_jacobian_space(type);
    for (int c = 0; c < type.dim; ++c)
      check_map(sj.column_map(c), static_cast<std::size_t>(sj.column_size(c)), n, rng);
  }
}

TEST(SparseRows, RandomMapsWithZerosAndSignedZeros) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t rows = 1 + rng() % 12, n = 1 + rng() % 20;
    std::vector<double> map(rows * n);
    for (double& v : map) {
      const double x = u(rng);
      v = x < -0.6 ? -0.0 : x < 0 ? 0.0 : x;  // about 60% zeros, half of them -0
    }
    check_map(map, rows, n, rng);
  }
}

}  // namespace
}  // namespace quadval
