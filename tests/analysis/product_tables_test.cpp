// The build-time product tables (src/analysis/product_tables.hpp): bit for bit the tables
// that exact arithmetic gives at run time, used by jacobian_space for the common types, and
// the exact data the generated path builds lazily agrees with them; the same for the
// midpoint probe's tables and the bisection's edge lines.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "analysis/jacobian_product.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/midpoint_probe.hpp"
#include "analysis/mu_space.hpp"
#include "analysis/product_tables.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "quadval/scaled_jacobian.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "jacobian_test_util.hpp"

namespace quadval {
namespace {

// Bitwise equality (0.0 and -0.0 differ; NaN would not compare unequal to itself).
void expect_same_bits(std::span<const double> got, std::span<const double> want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i)
    ASSERT_EQ(std::bit_cast<std::uint64_t>(got[i]), std::bit_cast<std::uint64_t>(want[i]))
        << what << " entry " << i << ": " << got[i] << " vs " << want[i];
}

void expect_same_tables(const ProductTables& got, const ProductTables& want, const std::string& name) {
  for (std::size_t m = 0; m < 2; ++m) {
    const std::string map = name + (m == 0 ? " curved" : " straight");
    EXPECT_EQ(got.maps[m].num_nodes, want.maps[m].num_nodes) << map;
    for (std::size_t c = 0; c < 3; ++c) {
      expect_same_bits(got.maps[m].matrix[c], want.maps[m].matrix[c], map + " matrix " + std::to_string(c));
      expect_same_bits(std::span(&got.maps[m].row_sum[c], 1), std::span(&want.maps[m].row_sum[c], 1),
                       map + " row sum " + std::to_string(c));
    }
  }
  for (std::size_t c = 0; c < 3; ++c)
    expect_same_bits(got.deriv_inv_mult[c], want.deriv_inv_mult[c], name + " 1/mult " + std::to_string(c));
  expect_same_bits(got.inv_mult, want.inv_mult, name + " 1/mult of J");
  expect_same_bits(std::span(&got.rounding, 1), std::span(&want.rounding, 1), name + " rounding");
  EXPECT_EQ(got.lattice_of_node, want.lattice_of_node) << name;
  EXPECT_EQ(got.gather_first, want.gather_first) << name;
  EXPECT_EQ(got.gather_terms, want.gather_terms) << name;
}

TEST(ProductTables, GeneratedEqualExactlyBuiltBitForBit) {
  const auto ids = generated_product_table_ids();
  ASSERT_GE(ids.size(), 40u);  // every common type of the six families
  for (int id : ids) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    const BezierBasis& basis = bezier_basis(type.family, type.order);
    const ProductTables exact = JacobianProduct(type, basis, TableSource::exact).tables();
    // What the view holds, and what a product built from it (the shared space) uses.
    const ProductTableView& view = *generated_product_tables(id);
    ProductTables from_view;
    for (std::size_t m = 0; m < 2; ++m) {
      from_view.maps[m].num_nodes = view.num_nodes[m];
      for (std::size_t c = 0; c < 3; ++c) {
        from_view.maps[m].matrix[c].assign(view.matrix[m][c].begin(), view.matrix[m][c].end());
        from_view.maps[m].row_sum[c] = view.row_sum[m][c];
      }
    }
    for (std::size_t c = 0; c < 3; ++c)
      from_view.deriv_inv_mult[c].assign(view.deriv_inv_mult[c].begin(), view.deriv_inv_mult[c].end());
    from_view.inv_mult.assign(view.inv_mult.begin(), view.inv_mult.end());
    from_view.rounding = view.rounding;
    from_view.lattice_of_node.assign(view.lattice_of_node.begin(), view.lattice_of_node.end());
    // Large types have no generated gathers (their products build them, compared below).
    const bool gathers = !view.gather_first[0].empty();
    for (std::size_t g = 0; g < 2; ++g) {
      const ProductTables& source = exact;
      from_view.gather_first[g] = gathers ? std::vector<int>(view.gather_first[g].begin(), view.gather_first[g].end())
                                          : source.gather_first[g];
      from_view.gather_terms[g] = gathers ? std::vector<int>(view.gather_terms[g].begin(), view.gather_terms[g].end())
                                          : source.gather_terms[g];
    }
    expect_same_tables(from_view, exact, std::string(type.name));
    expect_same_tables(jacobian_space(type).product()->tables(), exact, std::string(type.name));
  }
}

TEST(ProductTables, GeneratedMuTablesEqualExactlyBuiltBitForBit) {
  int count = 0;
  for (int id : generated_product_table_ids()) {
    const MuTableView* view = generated_mu_tables(id);
    if (view == nullptr) continue;
    ++count;
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    const MuTables exact = MuSpace(type, TableSource::exact).tables();
    for (const MuTables& got : {mu_space(type).tables(), MuSpace(type).tables()}) {
      for (std::size_t c = 0; c < 3; ++c) {
        expect_same_bits(got.derivative[c], exact.derivative[c], "derivative " + std::to_string(c));
        expect_same_bits(std::span(&got.row_sum[c], 1), std::span(&exact.row_sum[c], 1), "row sum");
      }
    }
    for (std::size_t c = 0; c < 3; ++c) {
      expect_same_bits(view->derivative[c], exact.derivative[c], "view derivative " + std::to_string(c));
      expect_same_bits(std::span(&view->row_sum[c], 1), std::span(&exact.row_sum[c], 1), "view row sum");
    }
  }
  EXPECT_GE(count, 30);
}

// The scaled Jacobian's pyramid columns take mu's generated derivative maps where there are
// some: bit for bit the exactly built column maps, for every pyramid order, generated or
// not.
TEST(ProductTables, PyramidScaledJacobianColumnsEqualExactMaps) {
  int generated = 0;
  for (const ElementType& type : element_types()) {
    if (type.family != ElementFamily::pyramid || !scaled_jacobian_supported(type)) continue;
    SCOPED_TRACE(std::string(type.name));
    if (generated_mu_tables(type.gmsh_id) != nullptr) ++generated;
    const PyramidColumnMaps exact = pyramid_column_maps(type);
    const ScaledJacobianSpace& space = scaled_jacobian_space(type);
    for (int c = 0; c < 3; ++c) {
      const auto uc = static_cast<std::size_t>(c);
      expect_same_bits(space.column_map(c), exact.map[uc], "column map " + std::to_string(c));
      const double want_row_sum = std::nextafter(exact.row_sum[uc], INFINITY);
      const double row_sum = space.column_row_sum(c);
      expect_same_bits(std::span(&row_sum, 1), std::span(&want_row_sum, 1), "row sum");
    }
  }
  EXPECT_GE(generated, 2);  // orders 1 and 2
}

TEST(ProductTables, GeneratedProbeTablesEqualBuiltOnesBitForBit) {
  // One per basis of a generated type, each the table build_midpoint_probe_table makes.
  for (int id : generated_product_table_ids()) {
    const ElementType& type = *find_element_type(id);
    EXPECT_NE(generated_probe_table(type.family, type.order), nullptr) << type.name;
  }
  const auto tables = generated_probe_tables();
  ASSERT_GE(tables.size(), 30u);
  for (const ProbeTableView& view : tables) {
    SCOPED_TRACE(std::string(family_name(view.family)) + " order " + std::to_string(view.order));
    EXPECT_EQ(generated_probe_table(view.family, view.order), &view);  // one per (family, order)
    const MidpointProbeTable built = build_midpoint_probe_table(bezier_basis(view.family, view.order));
    EXPECT_EQ(std::vector<int>(view.first.begin(), view.first.end()), built.first);
    EXPECT_EQ(std::vector<int>(view.index.begin(), view.index.end()), built.index);
    expect_same_bits(view.weight, built.weight, "weights");
    expect_same_bits(std::span(&view.gamma, 1), std::span(&built.gamma, 1), "gamma");
  }
}

TEST(ProductTables, GeneratedBisectionLinesEqualBuiltOnes) {
  // One per factor of a generated type's basis, each what build_factor_edge_lines makes.
  for (int id : generated_product_table_ids()) {
    const ElementType& type = *find_element_type(id);
    for (const FactorDegree& f : jacobian_factor_degrees(type.family, type.order))
      EXPECT_NE(generated_factor_edge_lines(f.dim, f.degree), nullptr) << type.name;
  }
  const auto all = generated_factor_edge_lines();
  ASSERT_GE(all.size(), 20u);
  for (const FactorEdgeLinesView& view : all) {
    SCOPED_TRACE("factor dim " + std::to_string(view.dim) + " degree " + std::to_string(view.degree));
    EXPECT_EQ(generated_factor_edge_lines(view.dim, view.degree), &view);  // one per (dim, degree)
    const FactorEdgeLines built = build_factor_edge_lines(view.dim, view.degree);
    for (std::size_t k = 0; k < 16; ++k) {
      EXPECT_EQ(std::vector<int>(view.first[k].begin(), view.first[k].end()), built.first[k]) << "edge slot " << k;
      EXPECT_EQ(std::vector<int>(view.index[k].begin(), view.index[k].end()), built.index[k]) << "edge slot " << k;
    }
  }
}

TEST(ProductTables, CommonTypesAreGenerated) {
  // The types of the benchmark meshes and of everyday Gmsh output, orders 1-3 (4 in 2D),
  // pyramids included (their exact set-up was the costliest: milliseconds).
  for (int id : {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 16, 17, 18, 19, 21, 23, 29, 36, 92})
    EXPECT_NE(generated_product_tables(id), nullptr) << find_element_type(id)->name;
  // Their convolutions' index tables too, up to order 2 in 3D and 4 in 2D, and order-3
  // tetrahedra: a type's set-up then builds no convolution.
  for (int id : {2, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 16, 17, 18, 19, 21, 23, 29, 36})
    EXPECT_FALSE(generated_product_tables(id)->gather_first[0].empty()) << find_element_type(id)->name;
  // mu's derivative maps of the same types (lines have no mu space).
  for (int id : {2, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 16, 17, 18, 19, 21, 23, 29, 36})
    EXPECT_NE(generated_mu_tables(id), nullptr) << find_element_type(id)->name;
  EXPECT_EQ(generated_product_tables(93), nullptr);  // hexahedron of order 4: exact path
}

TEST(ProductTables, LazyExactDataAgreesWithGeneratedTables) {
  // A product from generated tables builds its exact data only for exact_coefficients: the
  // rounded coefficients must lie within their error bound of those exact ones.
  std::mt19937 rng(5);
  for (int id : {5, 11, 12, 17, 18, 29, 36, 9, 23, 26, 7, 14, 19}) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    const JacobianProduct product(type, bezier_basis(type.family, type.order));
    const std::vector<double> x = test::random_element(type, 0.15, rng);
    const auto size = static_cast<std::size_t>(bezier_basis(type.family, type.order).size());
    std::vector<double> coeffs(size);
    double err = 0;
    ProductScratch scratch;
    product.coefficients(SampleMap::curved, x.data(), 1, type.dim == 2, coeffs.data(), &err, scratch);
    const std::vector<mpq_class> exact = product.exact_coefficients(SampleMap::curved, x.data(), type.dim == 2);
    ASSERT_EQ(exact.size(), size);
    for (std::size_t k = 0; k < size; ++k)
      ASSERT_TRUE(abs(mpq_class(coeffs[k]) - exact[k]) <= mpq_class(err)) << "coefficient " << k;
  }
}

TEST(ProductTables, LazyExactDataEqualsEagerlyBuiltOne) {
  // Pyramids build their exact data (shape-function coefficients, mult) on a path of their
  // own: built lazily after generated tables, it must be the data the exact build makes,
  // so the exact fallback gives the same rationals either way; and both products' double
  // coefficients and error bounds are the same bits.
  std::mt19937 rng(11);
  for (int id : {7, 14, 19, 12, 17, 11}) {
    const ElementType& type = *find_element_type(id);
    SCOPED_TRACE(std::string(type.name));
    ASSERT_NE(generated_product_tables(id), nullptr);
    const BezierBasis& basis = bezier_basis(type.family, type.order);
    const JacobianProduct lazy(type, basis), eager(type, basis, TableSource::exact);
    const auto size = static_cast<std::size_t>(basis.size());
    for (int trial = 0; trial < 3; ++trial) {
      const std::vector<double> x = test::random_element(type, 0.2, rng);
      for (SampleMap map : {SampleMap::curved, SampleMap::straight}) {
        const std::vector<mpq_class> a = lazy.exact_coefficients(map, x.data(), false);
        const std::vector<mpq_class> b = eager.exact_coefficients(map, x.data(), false);
        ASSERT_EQ(a.size(), size);
        ASSERT_EQ(b.size(), size);
        for (std::size_t k = 0; k < size; ++k) ASSERT_EQ(a[k], b[k]) << "coefficient " << k;
        std::vector<double> ca(size), cb(size);
        double ea = 0, eb = 0;
        ProductScratch scratch;
        lazy.coefficients(map, x.data(), 1, false, ca.data(), &ea, scratch);
        eager.coefficients(map, x.data(), 1, false, cb.data(), &eb, scratch);
        expect_same_bits(ca, cb, "coefficients");
        expect_same_bits(std::span(&ea, 1), std::span(&eb, 1), "error bound");
      }
    }
  }
}

}  // namespace
}  // namespace quadval
