// quadval info: what is in a mesh file.
//
//   quadval info mesh.msh            counts by element type and order, bounding box, and for
//                                    triangle meshes the parity, boundary loops, non-manifold edges
//   quadval info mesh.stl --json     the same as JSON on stdout
#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "quadval/io.hpp"
#include "quadval/topology.hpp"

namespace quadval::cli {
namespace {

struct InfoOptions {
  std::string path;
  bool json = false;
};

nlohmann::json describe(const Mesh& mesh) {
  nlohmann::json out;
  out["nodes"] = mesh.num_nodes();
  out["elements"] = mesh.num_elements();
  out["dimension"] = mesh.dimension();

  std::map<int, std::size_t> count_by_type;
  for (const ElementBlock& b : mesh.blocks) count_by_type[b.type->gmsh_id] += b.size();
  nlohmann::json types = nlohmann::json::array();
  for (const auto& [id, count] : count_by_type) {
    const ElementType& t = *find_element_type(id);
    types.push_back({{"gmsh_type", id},
                     {"name", std::string(t.name)},
                     {"family", std::string(family_name(t.family))},
                     {"order", t.order},
                     {"complete", t.complete},
                     {"count", count}});
  }
  out["element_types"] = types;

  if (mesh.num_nodes() > 0) {
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < mesh.num_nodes(); ++i)
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], mesh.coords[3 * i + d]);
        hi[d] = std::max(hi[d], mesh.coords[3 * i + d]);
      }
    out["bounding_box"] = {{"min", lo}, {"max", hi}};
  }

  const TriangleTopology topo = build_triangle_topology(mesh);
  if (topo.num_triangles() > 0) {
    std::vector<Tag> nonmanifold;  // first few, by node tags, so users can find them
    for (std::size_t k = 0; k < std::min<std::size_t>(topo.nonmanifold_edges.size(), 10); ++k) {
      const auto& e = topo.edges[topo.nonmanifold_edges[k]];
      nonmanifold.push_back(mesh.node_tags[e[0]]);
      nonmanifold.push_back(mesh.node_tags[e[1]]);
    }
    out["triangles"] = {{"count", topo.num_triangles()},
                        {"even", topo.even()},
                        {"edges", topo.num_edges()},
                        {"boundary_edges", topo.boundary_edges.size()},
                        {"boundary_loops", topo.boundary_loops.size()},
                        {"open_boundary_chains", topo.open_boundary_chains.size()},
                        {"nonmanifold_edges", topo.nonmanifold_edges.size()},
                        {"nonmanifold_edge_node_tags", nonmanifold},
                        {"collapsed_triangles", topo.collapsed_triangles.size()},
                        {"misoriented_edges", topo.num_misoriented_edges}};
  }
  return out;
}

void print_text(const std::string& path, const nlohmann::json& d) {
  fmt::print("{}\n", path);
  fmt::print("  nodes     {}\n", d["nodes"].get<std::size_t>());
  fmt::print("  elements  {} (dimension {})\n", d["elements"].get<std::size_t>(),
             d["dimension"].get<int>());
  for (const auto& t : d["element_types"])
    fmt::print("    {:>10}  {:<20} {} order {}{}\n", t["count"].get<std::size_t>(),
               t["name"].get<std::string>(), t["family"].get<std::string>(),
               t["order"].get<int>(), t["complete"].get<bool>() ? "" : " (incomplete)");
  if (d.contains("bounding_box")) {
    const auto& lo = d["bounding_box"]["min"];
    const auto& hi = d["bounding_box"]["max"];
    fmt::print("  bounding box  x [{:.6g}, {:.6g}]  y [{:.6g}, {:.6g}]  z [{:.6g}, {:.6g}]\n",
               lo[0].get<double>(), hi[0].get<double>(), lo[1].get<double>(),
               hi[1].get<double>(), lo[2].get<double>(), hi[2].get<double>());
  }
  if (d.contains("triangles")) {
    const auto& t = d["triangles"];
    const bool even = t["even"].get<bool>();
    fmt::print("  triangles {} ({}){}\n", t["count"].get<std::size_t>(), even ? "even" : "odd",
               even ? ""
                    : ": no perfect matching exists; `quadval recombine` splits a boundary "
                      "edge first (--odd split) or leaves one triangle (--odd leave)");
    fmt::print("    edges {}, boundary edges {}, boundary loops {}\n",
               t["edges"].get<std::size_t>(), t["boundary_edges"].get<std::size_t>(),
               t["boundary_loops"].get<std::size_t>());
    const auto nm = t["nonmanifold_edges"].get<std::size_t>();
    fmt::print("    non-manifold edges {}", nm);
    if (nm > 0) {
      fmt::print(" (node tags:");
      const auto& tags = t["nonmanifold_edge_node_tags"];
      for (std::size_t k = 0; k + 1 < tags.size(); k += 2)
        fmt::print(" {}-{}", tags[k].get<Tag>(), tags[k + 1].get<Tag>());
      fmt::print("{})", nm > 10 ? " ..." : "");
    }
    fmt::print("\n");
    if (t["open_boundary_chains"].get<std::size_t>() > 0)
      fmt::print("    open boundary chains {}\n", t["open_boundary_chains"].get<std::size_t>());
    if (t["collapsed_triangles"].get<std::size_t>() > 0)
      fmt::print("    collapsed triangles (a repeated node) {}\n",
                 t["collapsed_triangles"].get<std::size_t>());
    if (t["misoriented_edges"].get<std::size_t>() > 0)
      fmt::print("    edges between triangles of opposite orientation {}\n",
                 t["misoriented_edges"].get<std::size_t>());
  }
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto opts = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Describe a mesh: counts by element type and order, bounding box, and for triangle "
      "meshes the triangle count's parity, boundary loops and non-manifold edges.\n"
      "Reads .msh (2.2 or 4.1, ASCII or binary), .stl, .obj, .off.");
  cmd->add_option("FILE", opts->path, "mesh file")->required();
  cmd->add_flag("--json", opts->json, "print JSON on stdout instead of a table");
  cmd->callback([opts, &exit_code] {
    const Mesh mesh = read_mesh(opts->path);
    const nlohmann::json d = describe(mesh);
    if (opts->json)
      fmt::print("{}\n", d.dump(2));
    else
      print_text(opts->path, d);
    exit_code = kExitOk;
  });
}

}  // namespace quadval::cli
