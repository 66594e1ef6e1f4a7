#pragma once
// Loader for tests/data/gmsh_lagrange_reference.json (made by
// scripts/make_gmsh_reference_data.py from Gmsh 4.8.4), shared by the reference-node and
// Lagrange-basis tests.

#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "quadval/lagrange_basis.hpp"

namespace quadval::testing_data {

struct GmshType {
  int id = 0;
  std::string name;
  int dim = 0, order = 0, num_nodes = 0;
  std::vector<RefPoint> nodes;
  bool has_values = false;          ///< Lagrange families only
  std::vector<RefPoint> points;     ///< where values were taken
  std::vector<double> values;       ///< #points × num_nodes, row-major
  double gmsh_kronecker_error = 0;  ///< max |N_i(node_j) - delta_ij| of Gmsh's own functions
};

struct GmshReference {
  std::string gmsh_version;
  std::map<int, GmshType> types;
  std::map<int, std::string> rejected;  ///< id -> Gmsh's error message
};

inline std::vector<RefPoint> to_points(const nlohmann::json& flat) {
  const auto v = flat.get<std::vector<double>>();
  std::vector<RefPoint> out(v.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  return out;
}

/// Parsed once; throws if the file is missing (the tests then fail, loudly).
inline const GmshReference& gmsh_reference() {
  static const GmshReference data = [] {
    const std::string path = std::string(QUADVAL_SOURCE_DIR) + "/tests/data/gmsh_lagrange_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    const nlohmann::json j = nlohmann::json::parse(in);
    GmshReference r;
    r.gmsh_version = j.at("gmsh_version").get<std::string>();
    for (const auto& t : j.at("types")) {
      GmshType g;
      g.id = t.at("id");
      g.name = t.at("name");
      g.dim = t.at("dim");
      g.order = t.at("order");
      g.num_nodes = t.at("num_nodes");
      g.nodes = to_points(t.at("nodes"));
      if (t.contains("values")) {
        g.has_values = true;
        g.points = to_points(t.at("points"));
        g.values = t.at("values").get<std::vector<double>>();
        g.gmsh_kronecker_error = t.at("gmsh_kronecker_error");
      }
      r.types[g.id] = std::move(g);
    }
    for (const auto& t : j.at("rejected")) r.rejected[t.at("id")] = t.at("gmsh_error");
    return r;
  }();
  return data;
}

/// Every registry type that has a Lagrange basis.
inline std::vector<const ElementType*> lagrange_types() {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types())
    if (t.has_lagrange_basis) out.push_back(&t);
  return out;
}

}  // namespace quadval::testing_data
