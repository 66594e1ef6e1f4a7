#pragma once
// Bernstein-product tables (jacobian_product.hpp) made at build time, so that the first use
// of a common element type costs no exact (GMP) arithmetic and builds no convolution:
// `quadval check` on a small mesh would otherwise spend most of its time building them
// (milliseconds per type against microseconds for the elements; with the rounded tables
// alone, the convolutions' index tables and the lattice of the nodes were still about 20
// us of a 160 us check of quad_h0.4_o2). Internal to src/analysis.
//
// The same for the derivative maps of mu's space (MuSpace, mu_space.hpp): their exact set-up
// was half of a first `check --measure mu` of tri_h0.4_o4 (about 1 ms); for the midpoint
// probe's tables (midpoint_probe.hpp), about 13 us of a 155 us check of quad_h0.4_o2; and for
// the bisection's edge lines of the bases' factors (declared in bernstein_bisection.hpp, as
// the bezier layer reads them), about 15 us more of that check.
//
// tools/gen_product_tables.cpp builds each type's JacobianProduct (and MuSpace) in exact
// arithmetic (TableSource::exact), the same code path as any other type, and writes their tables as
// hexadecimal float literals, which read back to the same doubles bit for bit; CMake runs
// it and compiles the output into the library. The generator itself links
// product_tables_none.cpp instead. tests/analysis/product_tables_test.cpp checks that the
// generated tables equal the exactly built ones bit for bit.
#include <span>

#include "quadval/element_type.hpp"

namespace quadval {

/// One type's tables: the fields of ProductTables (jacobian_product.hpp) as views of
/// static arrays; index m is SampleMap (0 curved, 1 straight), c the direction, g the
/// convolution (0 cross, 1 dot).
struct ProductTableView {
  int gmsh_id = 0;
  int num_nodes[2] = {0, 0};
  std::span<const double> matrix[2][3];
  double row_sum[2][3] = {};
  std::span<const double> deriv_inv_mult[3];
  std::span<const double> inv_mult;
  double rounding = 0;
  std::span<const int> lattice_of_node;
  std::span<const int> gather_first[2], gather_terms[2];
};

/// The generated tables of a Gmsh type id, or nullptr when none were generated.
const ProductTableView* generated_product_tables(int gmsh_id) noexcept;

/// One type's MuSpace derivative maps (MuTables, mu_space.hpp) as views of static arrays.
struct MuTableView {
  int gmsh_id = 0;
  std::span<const double> derivative[3];
  double row_sum[3] = {};
};

/// The generated MuSpace tables of a Gmsh type id, or nullptr when none were generated.
const MuTableView* generated_mu_tables(int gmsh_id) noexcept;

/// The midpoint probe's table (MidpointProbeTable, midpoint_probe.hpp) of the Jacobian
/// basis of one (family, order) as views of static arrays.
struct ProbeTableView {
  ElementFamily family = ElementFamily::point;
  int order = 0;
  std::span<const int> first, index;
  std::span<const double> weight;
  double gamma = 0;
};

/// The generated probe table of the basis bezier_basis(family, order), or nullptr.
const ProbeTableView* generated_probe_table(ElementFamily family, int order) noexcept;

/// All generated probe tables (for tests).
std::span<const ProbeTableView> generated_probe_tables() noexcept;

/// The ids of all generated types (for tests).
std::span<const int> generated_product_table_ids() noexcept;

}  // namespace quadval
