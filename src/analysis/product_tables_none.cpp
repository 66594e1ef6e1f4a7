// No generated tables: linked only into the generator (tools/gen_product_tables.cpp), which
// builds every type's tables in exact arithmetic.
#include "analysis/product_tables.hpp"
#include "bezier/bernstein_bisection.hpp"

namespace quadval {

const ProductTableView* generated_product_tables(int) noexcept { return nullptr; }

std::span<const int> generated_product_table_ids() noexcept { return {}; }

const MuTableView* generated_mu_tables(int) noexcept { return nullptr; }

const ProbeTableView* generated_probe_table(ElementFamily, int) noexcept { return nullptr; }

std::span<const ProbeTableView> generated_probe_tables() noexcept { return {}; }

const FactorEdgeLinesView* generated_factor_edge_lines(int, int) noexcept { return nullptr; }

std::span<const FactorEdgeLinesView> generated_factor_edge_lines() noexcept { return {}; }

}  // namespace quadval
