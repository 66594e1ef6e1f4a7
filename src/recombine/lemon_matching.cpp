// Compiled as C++17 (see lemon_matching.hpp).
#include "lemon_matching.hpp"

#include <lemon/matching.h>
#include <lemon/smart_graph.h>

namespace quadval::recombine_detail {

namespace {

using Graph = lemon::SmartGraph;
using WeightMap = Graph::EdgeMap<long long>;

struct Built {
  Graph graph;
  std::vector<Graph::Edge> edges;
};

void build(std::uint32_t num_nodes, const std::vector<WeightedEdge>& edges, Built& b) {
  b.graph.reserveNode(static_cast<int>(num_nodes));
  b.graph.reserveEdge(static_cast<int>(edges.size()));
  for (std::uint32_t i = 0; i < num_nodes; ++i) b.graph.addNode();
  b.edges.reserve(edges.size());
  for (const WeightedEdge& e : edges)
    b.edges.push_back(b.graph.addEdge(b.graph.nodeFromId(static_cast<int>(e.u)),
                                      b.graph.nodeFromId(static_cast<int>(e.v))));
}

template <class Solver>
void read(const Built& b, const Solver& solver, std::vector<char>& matched) {
  matched.assign(b.edges.size(), 0);
  for (std::size_t i = 0; i < b.edges.size(); ++i) matched[i] = solver.matching(b.edges[i]) ? 1 : 0;
}

}  // namespace

bool lemon_max_weight_perfect_matching(std::uint32_t num_nodes,
                                       const std::vector<WeightedEdge>& edges,
                                       std::vector<char>& matched) {
  Built b;
  build(num_nodes, edges, b);
  WeightMap weight(b.graph);
  for (std::size_t i = 0; i < edges.size(); ++i) weight[b.edges[i]] = edges[i].weight;
  lemon::MaxWeightedPerfectMatching<Graph, WeightMap> solver(b.graph, weight);
  if (!solver.run()) return false;
  read(b, solver, matched);
  return true;
}

void lemon_max_weight_matching(std::uint32_t num_nodes, const std::vector<WeightedEdge>& edges,
                               std::vector<char>& matched) {
  Built b;
  build(num_nodes, edges, b);
  WeightMap weight(b.graph);
  for (std::size_t i = 0; i < edges.size(); ++i) weight[b.edges[i]] = edges[i].weight;
  lemon::MaxWeightedMatching<Graph, WeightMap> solver(b.graph, weight);
  solver.run();
  read(b, solver, matched);
}

}  // namespace quadval::recombine_detail
