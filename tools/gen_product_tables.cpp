// Build-time generator of the Bernstein-product tables (src/analysis/product_tables.hpp).
//
//   quadval_gen_product_tables OUT.cpp
//
// For every common element type, builds its JacobianProduct in exact rational arithmetic
// (TableSource::exact: the code path of every other type), its MuSpace derivative maps and
// its basis's midpoint-probe table (midpoint_probe.hpp) and its factors' bisection lines
// (bernstein_bisection.hpp), and writes the rounded tables as
// hexadecimal float literals, which the compiler reads back to the same doubles bit for
// bit, and the kernel's index tables as integers. CMake runs it (add_custom_command) and compiles OUT.cpp into quadval_product_tables.
// Linked with src/analysis/product_tables_none.cpp, so it never reads tables of its own.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "analysis/jacobian_product.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/midpoint_probe.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "analysis/mu_space.hpp"
#include "quadval/bezier_basis.hpp"
#include "quadval/element_type.hpp"
#include "quadval/mu_bounds.hpp"

namespace {

using quadval::ElementType;

// Which types get tables: the Lagrange types of the product path with at most 64 nodes
// (hexahedra and prisms up to order 3, tetrahedra 4, pyramids 4, triangles 9, quadrangles
// 7, incomplete triangles and quadrangles 10, lines 10). Larger ones (order-4 hexahedra:
// 37,500 entries) keep the exact path.
// Pyramids matter most: their exact set-up (Vandermonde inverse, monomial-to-Bernstein
// maps in GMP) took 1.4 ms for the 14-node pyramid, against ~50 us from tables. Their
// serendipity types of orders 5-8 have few nodes but J spaces of up to 12,672
// coefficients (tables 10x the size of all others together): exact path too.
constexpr int kMaxNodes = 64;
constexpr int kMaxPyramidOrder = 4;
// The convolutions' index tables (gathers) only up to this many integers per type: the
// order-3 hexahedra and the larger pyramids would add 2 MB to the binary for a set-up
// that is a small part of analysing even a few of their elements; they build theirs.
constexpr std::size_t kMaxGatherInts = 8192;

// MuSpace's derivative maps (mu_space.hpp) for the types with at most this many nodes
// (to hexahedra of order 2 and tetrahedra of order 3): larger ones hold up to 4096 x 64
// entries per direction for a set-up of tens of milliseconds at most.
constexpr int kMaxMuNodes = 27;

bool generated(const ElementType& t) {
  return quadval::jacobian_supported(t) && t.num_nodes <= kMaxNodes &&
         (t.family != quadval::ElementFamily::pyramid || t.order <= kMaxPyramidOrder);
}

std::string hex(double x) {
  if (!std::isfinite(x)) {
    std::fprintf(stderr, "gen_product_tables: non-finite table entry\n");
    std::exit(1);
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", x);
  return buf;
}

// `const double NAME[] = {...};`, or nothing for an empty table (its span stays empty).
std::string array(std::ostringstream& out, const std::string& name, const std::vector<double>& v) {
  if (v.empty()) return "{}";
  out << "const double " << name << "[] = {";
  for (std::size_t i = 0; i < v.size(); ++i) out << (i % 4 == 0 ? "\n    " : " ") << hex(v[i]) << ",";
  out << "\n};\n";
  return name;
}

// `const int NAME[] = {...};`, likewise.
std::string array(std::ostringstream& out, const std::string& name, const std::vector<int>& v) {
  if (v.empty()) return "{}";
  out << "const int " << name << "[] = {";
  for (std::size_t i = 0; i < v.size(); ++i) out << (i % 16 == 0 ? "\n    " : " ") << v[i] << ",";
  out << "\n};\n";
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT.cpp\n", argv[0]);
    return 2;
  }
  std::ostringstream arrays, entries, ids, mu_entries, probe_entries;
  std::vector<std::pair<quadval::ElementFamily, int>> probe_bases;  // (family, order) done
  std::ostringstream line_entries;
  std::vector<std::pair<int, int>> line_factors;  // (dim, degree) done
  std::vector<int> slot_of_id;  // 1 + index into kTables, 0 for none
  std::vector<int> mu_slot_of_id;  // 1 + index into kMuTables, 0 for none
  int count = 0, mu_count = 0;
  for (int id = 1; id < 1024; ++id) {
    const ElementType* t = quadval::find_element_type(id);
    if (t == nullptr || !generated(*t)) continue;
    const quadval::JacobianProduct product(*t, quadval::bezier_basis(t->family, t->order),
                                           quadval::TableSource::exact);
    const quadval::ProductTables tables = product.tables();
    const std::string p = std::string("t").append(std::to_string(id));  // not "t" + ...: a false -Wrestrict of GCC 12
    std::string matrix[2][3], deriv[3];
    for (int m = 0; m < 2; ++m)
      for (int c = 0; c < 3; ++c)
        matrix[m][c] = array(arrays, p + "_m" + std::to_string(m) + "_d" + std::to_string(c),
                             tables.maps[static_cast<std::size_t>(m)].matrix[static_cast<std::size_t>(c)]);
    for (int c = 0; c < 3; ++c)
      deriv[c] = array(arrays, p + "_inv_d" + std::to_string(c), tables.deriv_inv_mult[static_cast<std::size_t>(c)]);
    const std::string inv = array(arrays, p + "_inv", tables.inv_mult);
    const std::string lattice = array(arrays, p + "_lattice", tables.lattice_of_node);
    std::string first[2] = {"{}", "{}"}, terms[2] = {"{}", "{}"};
    std::size_t gather_ints = 0;
    for (std::size_t g = 0; g < 2; ++g) gather_ints += tables.gather_first[g].size() + tables.gather_terms[g].size();
    for (std::size_t g = 0; g < 2 && gather_ints <= kMaxGatherInts; ++g) {
      first[g] = array(arrays, p + "_first" + std::to_string(g), tables.gather_first[g]);
      terms[g] = array(arrays, p + "_terms" + std::to_string(g), tables.gather_terms[g]);
    }
    entries << "    {" << id << ", {" << tables.maps[0].num_nodes << ", " << tables.maps[1].num_nodes << "},\n     {";
    for (int m = 0; m < 2; ++m)
      entries << (m ? ", " : "") << "{" << matrix[m][0] << ", " << matrix[m][1] << ", " << matrix[m][2] << "}";
    entries << "},\n     {";
    for (int m = 0; m < 2; ++m) {
      const auto& rs = tables.maps[static_cast<std::size_t>(m)].row_sum;
      entries << (m ? ", " : "") << "{" << hex(rs[0]) << ", " << hex(rs[1]) << ", " << hex(rs[2]) << "}";
    }
    entries << "},\n     {" << deriv[0] << ", " << deriv[1] << ", " << deriv[2] << "}, " << inv << ",\n     "
            << hex(tables.rounding) << ", " << lattice << ", {" << first[0] << ", " << first[1] << "}, {" << terms[0]
            << ", " << terms[1] << "}},  // " << t->name << "\n";
    // The midpoint probe's table of this type's basis, once per (family, order).
    if (std::find(probe_bases.begin(), probe_bases.end(), std::pair{t->family, t->order}) == probe_bases.end()) {
      probe_bases.emplace_back(t->family, t->order);
      const quadval::MidpointProbeTable probe =
          quadval::build_midpoint_probe_table(quadval::bezier_basis(t->family, t->order));
      const std::string q = p + "_probe";
      const std::string first = array(arrays, q + "_first", probe.first);
      const std::string index = array(arrays, q + "_index", probe.index);
      const std::string weight = array(arrays, q + "_weight", probe.weight);
      probe_entries << "    {ElementFamily(" << static_cast<int>(t->family) << "), " << t->order << ", " << first
                    << ", " << index << ", " << weight << ", " << hex(probe.gamma) << "},  // "
                    << quadval::family_name(t->family) << " " << t->order << "\n";
    }
    // The bisection's edge lines of each factor of this type's basis, once per (dim, degree).
    for (const quadval::FactorDegree& fd : quadval::jacobian_factor_degrees(t->family, t->order)) {
      if (std::find(line_factors.begin(), line_factors.end(), std::pair{fd.dim, fd.degree}) != line_factors.end())
        continue;
      line_factors.emplace_back(fd.dim, fd.degree);
      const quadval::FactorEdgeLines lines = quadval::build_factor_edge_lines(fd.dim, fd.degree);
      const std::string q = std::string("f").append(std::to_string(fd.dim)).append("_").append(std::to_string(fd.degree));
      std::string first[16], index[16];
      for (std::size_t k = 0; k < 16; ++k) {
        first[k] = array(arrays, q + "_first" + std::to_string(k), lines.first[k]);
        index[k] = array(arrays, q + "_index" + std::to_string(k), lines.index[k]);
      }
      line_entries << "    {" << fd.dim << ", " << fd.degree << ",\n     {{";  // std::array: {{...}}
      for (std::size_t k = 0; k < 16; ++k) line_entries << (k ? ", " : "") << first[k];
      line_entries << "}},\n     {{";
      for (std::size_t k = 0; k < 16; ++k) line_entries << (k ? ", " : "") << index[k];
      line_entries << "}}},\n";
    }
    ids << (count % 12 == 0 ? "\n    " : " ") << id << ",";
    slot_of_id.resize(static_cast<std::size_t>(id) + 1, 0);
    slot_of_id.back() = ++count;
    if (quadval::mu_supported(*t) && t->num_nodes <= kMaxMuNodes) {
      const quadval::MuTables mu = quadval::MuSpace(*t, quadval::TableSource::exact).tables();
      std::string d[3];
      for (int c = 0; c < 3; ++c)
        d[c] = array(arrays, p + "_mu_d" + std::to_string(c), mu.derivative[static_cast<std::size_t>(c)]);
      mu_entries << "    {" << id << ", {" << d[0] << ", " << d[1] << ", " << d[2] << "}, {" << hex(mu.row_sum[0]) << ", "
                 << hex(mu.row_sum[1]) << ", " << hex(mu.row_sum[2]) << "}},  // " << t->name << "\n";
      mu_slot_of_id.resize(static_cast<std::size_t>(id) + 1, 0);
      mu_slot_of_id.back() = ++mu_count;
    }
  }
  if (count > 255) {
    std::fprintf(stderr, "gen_product_tables: %d types overflow the slot table\n", count);
    return 1;
  }
  std::ostringstream out;
  out << "// Generated by tools/gen_product_tables.cpp at build time: do not edit.\n"
         "// The Bernstein-product tables (with MuSpace derivative maps and midpoint-probe tables) of "
      << count
      << " element types (src/analysis/product_tables.hpp).\n"
         "#include \"analysis/product_tables.hpp\"\n#include \"bezier/bernstein_bisection.hpp\"\n\n"
         "namespace quadval {\nnamespace {\n\n"
      << arrays.str() << "\nconst ProductTableView kTables[] = {\n"
      << entries.str() << "};\n\nconst int kIds[] = {" << ids.str() << "\n};\n\n"
      << "// By Gmsh id: 1 + the index in kTables, 0 for none (a lookup touches one entry).\n"
         "const unsigned char kSlot[] = {";
  for (std::size_t id = 0; id < slot_of_id.size(); ++id) out << (id % 20 == 0 ? "\n    " : " ") << slot_of_id[id] << ",";
  out << "\n};\n\nconst MuTableView kMuTables[] = {\n" << mu_entries.str() << "};\n\n"
      << "// By Gmsh id: 1 + the index in kMuTables, 0 for none.\nconst unsigned char kMuSlot[] = {";
  for (std::size_t id = 0; id < mu_slot_of_id.size(); ++id)
    out << (id % 20 == 0 ? "\n    " : " ") << mu_slot_of_id[id] << ",";
  out << "\n};\n\nconst ProbeTableView kProbeTables[] = {\n" << probe_entries.str() << "};\n\n"
      << "const FactorEdgeLinesView kEdgeLines[] = {\n" << line_entries.str() << "};\n\n"
      << "}  // namespace\n\n"
      << "const MuTableView* generated_mu_tables(int gmsh_id) noexcept {\n"
         "  if (gmsh_id < 0 || static_cast<std::size_t>(gmsh_id) >= sizeof kMuSlot || kMuSlot[gmsh_id] == 0) return nullptr;\n"
         "  return &kMuTables[kMuSlot[gmsh_id] - 1];\n}\n\n"
      << "const ProductTableView* generated_product_tables(int gmsh_id) noexcept {\n"
         "  if (gmsh_id < 0 || static_cast<std::size_t>(gmsh_id) >= sizeof kSlot || kSlot[gmsh_id] == 0) return nullptr;\n"
         "  return &kTables[kSlot[gmsh_id] - 1];\n}\n\n"
         "std::span<const int> generated_product_table_ids() noexcept { return kIds; }\n\n"
         "const ProbeTableView* generated_probe_table(ElementFamily family, int order) noexcept {\n"
         "  for (const ProbeTableView& t : kProbeTables)\n"
         "    if (t.family == family && t.order == order) return &t;\n"
         "  return nullptr;\n}\n\n"
         "std::span<const ProbeTableView> generated_probe_tables() noexcept { return kProbeTables; }\n\n"
         "const FactorEdgeLinesView* generated_factor_edge_lines(int dim, int degree) noexcept {\n"
         "  for (const FactorEdgeLinesView& t : kEdgeLines)\n"
         "    if (t.dim == dim && t.degree == degree) return &t;\n"
         "  return nullptr;\n}\n\n"
         "std::span<const FactorEdgeLinesView> generated_factor_edge_lines() noexcept { return kEdgeLines; }\n\n"
         "}  // namespace quadval\n";
  // Write-then-rename: an interrupted build never leaves a truncated table file.
  const std::string path = argv[1], tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << out.str();
    if (!f) {
      std::fprintf(stderr, "gen_product_tables: cannot write %s\n", tmp.c_str());
      return 1;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::fprintf(stderr, "gen_product_tables: cannot rename to %s\n", path.c_str());
    return 1;
  }
  std::printf("gen_product_tables: %d types (%d with mu tables), %zu probe tables, %zu factors' lines -> %s\n",
              count, mu_count, probe_bases.size(), line_factors.size(), path.c_str());
  return 0;
}
