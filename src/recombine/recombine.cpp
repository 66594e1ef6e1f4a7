// The Blossom-Quad pipeline (Paper I §7) and its baselines: see quadval/recombine.hpp.
#include "quadval/recombine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include <fmt/core.h>

#include "boundary_slide.hpp"
#include "dual_graph.hpp"
#include "feature_edges.hpp"
#include "lookahead_matching.hpp"
#include "lookahead_parity.hpp"
#include "matching.hpp"
#include "mixed_mesh.hpp"
#include "node_order.hpp"
#include "quad_cleanup.hpp"
#include "quadval/error.hpp"
#include "recombine_stats.hpp"
#include "refine.hpp"
#include "repair.hpp"
#include "smoothing.hpp"
#include "surface_projection.hpp"
#include "triangle_input.hpp"

namespace quadval {

namespace {

using namespace recombine_detail;
using Clock = std::chrono::steady_clock;

class StageTimer {
 public:
  StageTimer(RecombineStats& stats, const RecombineOptions& options)
      : stats_(stats), options_(options), start_(Clock::now()), last_(start_) {}
  // Ends the current stage: records its time and logs "[stage] message, X ms".
  void stage(const std::string& name, const std::string& message) {
    const auto now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    stats_.times.push_back({name, seconds});
    if (options_.log) options_.log(fmt::format("[{}] {}, {:.1f} ms", name, message, 1e3 * seconds));
  }
  double total() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  RecombineStats& stats_;
  const RecombineOptions& options_;
  Clock::time_point start_, last_;
};

std::array<double, 3> unit_normal(const std::vector<double>& coords,
                                  const std::array<NodeIndex, 3>& t) {
  auto n = triangle_normal(coords, t);
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  return {n[0] / len, n[1] / len, n[2] / len};
}

// Quads from the matched real pairs; triangles of extra pairs (listed for repair) and of no
// pair stay triangles.
MixedMesh mesh_from_matching(const TriangleSurface& s, const DualGraph& g, const Matching& match,
                             std::vector<ExtraPair>& extra) {
  MixedMesh m;
  m.coords = s.coords;
  m.node_tags = s.node_tags;
  const std::size_t nt = s.triangles.size();
  std::vector<std::uint32_t> element_of(nt, kUnmatched);
  auto add_triangle = [&](std::uint32_t t) {
    element_of[t] = static_cast<std::uint32_t>(m.elements.size());
    const auto& v = s.triangles[t];
    m.elements.push_back({v[0], v[1], v[2], kNoNode});
    m.region.push_back(s.region[t]);
    m.normal.push_back(unit_normal(s.coords, v));
    m.alive.push_back(1);
  };
  m.elements.reserve(nt / 2 + 16);
  for (std::uint32_t i : match.pairs) {
    const TrianglePair& p = g.pairs[i];
    if (p.kind == PairKind::extra) {
      add_triangle(p.t0);
      add_triangle(p.t1);
      extra.push_back({element_of[p.t0], element_of[p.t1], p.shared_node});
      continue;
    }
    const auto n0 = unit_normal(s.coords, s.triangles[p.t0]);
    const auto n1 = unit_normal(s.coords, s.triangles[p.t1]);
    m.elements.push_back(quad_of_pair(s.triangles[p.t0], p.t0_edge, s.triangles[p.t1]));
    m.region.push_back(s.region[p.t0]);
    m.normal.push_back({n0[0] + n1[0], n0[1] + n1[1], n0[2] + n1[2]});
    m.alive.push_back(1);
    element_of[p.t0] = element_of[p.t1] = static_cast<std::uint32_t>(m.elements.size() - 1);
  }
  for (std::uint32_t t = 0; t < nt; ++t)
    if (element_of[t] == kUnmatched) add_triangle(t);
  return m;
}

// Smooths only the nodes within one more ring of elements around the marked ones (`near`),
// the rest held: after the last swaps, the mesh elsewhere is smoothed already. Smoothing
// never lowers the worst score, so eta_min stays.
std::size_t smooth_near(MixedMesh& m, const std::vector<char>& fixed, const std::vector<char>& near,
                        SmoothingOptions smoothing) {
  std::vector<char> ring = near;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    bool touches = false;
    for (int k = 0; k < MixedMesh::size(el); ++k) touches = touches || near[el[k]];
    if (touches)
      for (int k = 0; k < MixedMesh::size(el); ++k) ring[el[k]] = 1;
  }
  std::vector<char> held(fixed);
  auto slides = straight_boundary_slides(m, fixed);
  for (NodeIndex v = 0; v < m.num_nodes(); ++v)
    if (!ring[v]) {
      held[v] = 1;
      slides[v] = {kNoNode, kNoNode};
    }
  smoothing.slides = &slides;
  return smooth(m, held, smoothing);
}

// Brings the nodes moved since `before` (a quad-vertex-merge's node at the middle of a
// diagonal, the relaxation around a diagonal swap) or added after it (refine_to_quads' edge
// midpoints and quad centres) back onto the input surface, each only where the elements
// around it stay valid or get no worse. A node starts its walk from a neighbour's triangle
// when it has none: the nodes none of whose neighbours has one yet (quad centres after a
// refinement) wait for a second round.
void project_moved_nodes(MixedMesh& m, const std::vector<double>& before, SurfaceProjection& surface) {
  surface.reserve_nodes(m.num_nodes());
  const std::vector<std::vector<std::uint32_t>> at = node_elements(m);
  const auto least = [&](NodeIndex v) {
    double worst = 2.0;
    for (std::uint32_t e : at[v]) worst = std::min(worst, element_score(m, e));
    return worst;
  };
  std::vector<NodeIndex> waiting;
  const auto place = [&](NodeIndex v) {
    NodeIndex near = kNoNode;
    for (std::uint32_t e : at[v])
      for (int k = 0; k < MixedMesh::size(m.elements[e]); ++k)
        if (near == kNoNode && m.elements[e][k] != v && surface.placed(m.elements[e][k])) near = m.elements[e][k];
    if (near == kNoNode && !surface.placed(v)) return false;
    const std::size_t i = 3 * std::size_t{v};
    const auto x = m.point(v);
    const double old_worst = least(v);
    const auto on = surface.project(v, x, near == kNoNode ? v : near);
    for (int d = 0; d < 3; ++d) m.coords[i + d] = on[d];
    const double new_worst = least(v);
    if (!(new_worst > 0 || new_worst >= old_worst))
      for (int d = 0; d < 3; ++d) m.coords[i + d] = x[d];
    return true;
  };
  for (NodeIndex v = 0; v < m.num_nodes(); ++v) {
    const std::size_t i = 3 * std::size_t{v};
    if (at[v].empty() || (i < before.size() && m.coords[i] == before[i] && m.coords[i + 1] == before[i + 1] &&
                          m.coords[i + 2] == before[i + 2]))
      continue;
    if (!place(v)) waiting.push_back(v);
  }
  for (NodeIndex v : waiting) place(v);
}

void optimize(MixedMesh& m, const TriangleSurface& s, SurfaceProjection* surface,
              const RecombineOptions& options, RecombineStats& stats, StageTimer& timer) {
  const std::vector<char> fixed = region_boundary_nodes(m);
  const auto slides = straight_boundary_slides(m, fixed);
  SmoothingOptions smoothing{options.smoothing_passes,
                             options.size_field ? &options.size_field : nullptr, !s.planar,
                             &slides};
  smoothing.surface = surface;
  stats.smoothing_moves += smooth(m, fixed, smoothing);
  timer.stage("smooth", fmt::format("{} passes, {} moves", options.smoothing_passes,
                                    stats.smoothing_moves));
  const std::vector<double> before_cleanup = surface ? m.coords : std::vector<double>{};
  const CleanupCounts c = cleanup_quads(m, fixed, options.max_cleanup_passes);
  if (surface) project_moved_nodes(m, before_cleanup, *surface);
  const auto slides_after = straight_boundary_slides(m, fixed);  // the clean-up edits elements
  smoothing.slides = &slides_after;
  stats.vertex_merges += c.vertex_merges;
  stats.doublet_collapses += c.doublet_collapses;
  stats.diagonal_swaps += c.diagonal_swaps;
  timer.stage("cleanup", fmt::format("{} quad-vertex-merges, {} doublet collapses, {} diagonal swaps",
                                     c.vertex_merges, c.doublet_collapses, c.diagonal_swaps));
  if (c.vertex_merges + c.doublet_collapses + c.diagonal_swaps > 0) {
    const std::size_t moves = smooth(m, fixed, smoothing);
    stats.smoothing_moves += moves;
    timer.stage("smooth", fmt::format("{} moves after clean-up", moves));
  }
  if (options.smoothing_passes > 0) {
    const std::size_t moves = polish_worst(m, fixed, smoothing);
    stats.smoothing_moves += moves;
    timer.stage("polish", fmt::format("{} moves at the worst elements", moves));
  }
  if (options.max_cleanup_passes > 0) {
    std::vector<char> near;
    const std::vector<double> before_swaps = surface ? m.coords : std::vector<double>{};
    const std::size_t swaps = swap_worst(m, fixed, 0.002, 2, &near);
    if (surface && swaps > 0) project_moved_nodes(m, before_swaps, *surface);
    stats.diagonal_swaps += swaps;
    timer.stage("swap", fmt::format("{} diagonal swaps at the worst quads", swaps));
    if (swaps > 0 && options.smoothing_passes > 0) {
      const std::size_t moves = smooth_near(m, fixed, near, smoothing);
      stats.smoothing_moves += moves;
      timer.stage("smooth", fmt::format("{} moves around the swaps", moves));
    }
  }
}

Mesh to_mesh(const MixedMesh& m, const Mesh& input, const TriangleSurface& s) {
  Mesh out;
  out.entities = input.entities;
  out.physical_names = input.physical_names;
  std::vector<NodeIndex> new_index(m.num_nodes(), kNoNode);
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i) new_index[m.elements[e][i]] = 0;
  }
  // The used nodes by increasing tag: the input's order (MSH tags, or 1, 2, ... for formats
  // without tags), nodes added by repairs and splits last.
  std::vector<NodeIndex> used;
  for (NodeIndex v = 0; v < m.num_nodes(); ++v)
    if (new_index[v] != kNoNode) used.push_back(v);
  std::sort(used.begin(), used.end(),
            [&](NodeIndex a, NodeIndex b) { return m.node_tags[a] < m.node_tags[b]; });
  for (NodeIndex v : used) {
    new_index[v] = static_cast<NodeIndex>(out.node_tags.size());
    out.node_tags.push_back(m.node_tags[v]);
    for (int d = 0; d < 3; ++d) out.coords.push_back(m.coords[3 * std::size_t{v} + d]);
  }
  // One block per (entity, element kind), entities in the order of their first region (the
  // regions cut from one entity at feature edges share its block); element tags 1, 2, ...
  std::vector<int> entities;
  std::map<int, bool> listed;
  for (int entity : s.region_entity)
    if (!std::exchange(listed[entity], true)) entities.push_back(entity);
  Tag tag = 1;
  for (int kind : {4, 3}) {
    for (int entity : entities) {
      ElementBlock b;
      b.type = find_element_type(kind == 4 ? 3 : 2);
      b.entity_dim = 2;
      b.entity_tag = entity;
      for (std::size_t e = 0; e < m.elements.size(); ++e) {
        if (!m.alive[e] || s.region_entity[static_cast<std::size_t>(m.region[e])] != entity ||
            MixedMesh::size(m.elements[e]) != kind)
          continue;
        b.tags.push_back(tag++);
        for (int i = 0; i < kind; ++i) b.nodes.push_back(new_index[m.elements[e][i]]);
      }
      if (!b.tags.empty()) out.blocks.push_back(std::move(b));
    }
  }
  return out;
}

}  // namespace

RecombineResult recombine(const Mesh& input, const RecombineOptions& options) {
  RecombineResult result;
  RecombineStats& stats = result.stats;
  StageTimer timer(stats, options);

  // In locality order before the checks too (node_order.hpp); the output keeps the input's
  // node order.
  TriangleSurface s = collect_triangles(input, options.source, result.warnings);
  order_nodes_along_curve(s);
  order_triangles_along_curve(s);
  validate_triangles(s, options.source, result.warnings);
  stats.input_triangles = s.triangles.size();
  if (options.cost == PairCostKind::cross_field && !options.cross_field_per_triangle.empty() &&
      options.cross_field_per_triangle.size() != s.triangles.size())
    throw InputError::in_file(
        options.source, fmt::format("the cross field has {} angles for {} triangles",
                                    options.cross_field_per_triangle.size(), s.triangles.size()));
  stats.feature_edges = split_regions_at_features(s, options.feature_angle);
  if (options.odd_policy == OddPolicy::split_boundary_edge) {
    // A perfect matching needs every connected piece of a region even (the dual graph of
    // two pieces has no edge between them), and so does the look-ahead criterion.
    if (options.algorithm != RecombineAlgorithm::greedy) make_pieces_even(s);
  }
  stats.odd_splits = s.odd_splits;
  if (s.odd_splits > 0)
    result.warnings.push_back(fmt::format(
        "connected pieces with an odd number of triangles have no all-quad matching: {} edge(s) "
        "were split at their midpoint (the longest boundary edge of an odd piece, or an edge "
        "between two pieces of a closed surface cut at feature edges)",
        s.odd_splits));
  if (!s.odd_regions_left.empty())
    result.warnings.push_back(fmt::format(
        "{} connected piece(s) have an odd number of triangles and no boundary edge to split: "
        "at least one triangle will remain in each{}",
        s.odd_regions_left.size(),
        stats.feature_edges > 0 ? fmt::format(" (the {} feature edges cut the surface into {} pieces; a larger "
                                              "feature angle cuts fewer)",
                                              stats.feature_edges, s.region_entity.size())
                                : std::string()));
  timer.stage("input", fmt::format("{} triangles, {} regions, {} feature edges", stats.input_triangles,
                                   s.region_entity.size(), stats.feature_edges));

  // Cross-field angles follow the triangles (split halves inherit their parent's angle).
  std::vector<double> field;
  if (!options.cross_field_per_triangle.empty())
    for (std::uint32_t i : s.input_index) field.push_back(options.cross_field_per_triangle[i]);
  DualGraphInput gin{&s.coords, &s.triangles, &s.region, s.node_tags.size(), options.cost,
                     &field, options.cross_field_angle,
                     options.extra_edges && options.algorithm == RecombineAlgorithm::blossom,
                     options.extra_edge_cost, &s.forbidden_pairs,
                     s.topology ? &*s.topology : nullptr};
  const DualGraph graph = build_dual_graph(gin);
  // Surfaces in 3D: the input triangles, which the moved and added nodes are kept on (made
  // while the kept topology is still there).
  std::optional<SurfaceProjection> surface;
  if (!s.planar && (options.optimize || options.full_quad)) surface.emplace(s);
  s.topology.reset();  // not needed below
  stats.graph_pairs = graph.num_real;
  stats.extra_pairs = graph.pairs.size() - graph.num_real;
  timer.stage("graph", fmt::format("{} pairs, {} extra", stats.graph_pairs, stats.extra_pairs));

  const Matching match = options.algorithm == RecombineAlgorithm::blossom
                             ? blossom_matching(graph, options.matching_progress)
                             : options.algorithm == RecombineAlgorithm::lookahead
                             ? lookahead_matching(graph, s, options, stats)
                             : greedy_matching(graph);
  stats.perfect_matching = match.perfect;
  stats.matching_cost = match.cost;
  timer.stage(options.algorithm == RecombineAlgorithm::blossom     ? "blossom"
              : options.algorithm == RecombineAlgorithm::lookahead ? "lookahead"
                                                                   : "greedy",
              fmt::format("{} pairs{}, cost {:.6g}", match.pairs.size(),
                          match.perfect ? " (perfect)" : " (not perfect)", match.cost));
  if (!match.perfect && options.algorithm == RecombineAlgorithm::blossom)
    result.warnings.push_back(fmt::format(
        "no perfect matching exists even with the extra edges: {} triangle(s) left unmatched",
        s.triangles.size() - 2 * match.pairs.size()));

  std::vector<ExtraPair> extra;
  MixedMesh m = mesh_from_matching(s, graph, match, extra);
  stats.matched_extra_pairs = extra.size();
  Tag next_tag = 1;
  for (Tag t : m.node_tags) next_tag = std::max(next_tag, t + 1);
  const RepairCounts repaired = repair_extra_pairs(m, extra, next_tag);
  stats.edge_swaps = repaired.edge_swaps;
  stats.vertex_duplications = repaired.vertex_duplications;
  if (repaired.failed > 0)
    result.warnings.push_back(fmt::format(
        "{} extra-edge pair(s) could not be repaired and stay as triangles", repaired.failed));
  timer.stage("repair", fmt::format("{} extra pairs matched: {} edge swaps, {} vertex "
                                    "duplications", extra.size(), repaired.edge_swaps,
                                    repaired.vertex_duplications));

  if (options.optimize) optimize(m, s, surface ? &*surface : nullptr, options, stats, timer);
  if (options.full_quad) {
    const std::vector<double> before = surface ? m.coords : std::vector<double>{};
    m = refine_to_quads(m, next_tag);
    if (surface) project_moved_nodes(m, before, *surface);
    timer.stage("refine", fmt::format("{} quads", m.elements.size()));
    if (options.optimize && options.smoothing_passes > 0) {
      const std::vector<char> fixed = region_boundary_nodes(m);
      SmoothingOptions smoothing{options.smoothing_passes, options.size_field ? &options.size_field : nullptr,
                                 !s.planar};
      smoothing.surface = surface ? &*surface : nullptr;
      stats.smoothing_moves += smooth(m, fixed, smoothing);
      timer.stage("smooth", "after refinement");
    }
  }
  compute_statistics(m, options.size_field, stats);
  result.mesh = to_mesh(m, input, s);
  timer.stage("output", fmt::format("{} quads, {} triangles, eta min {:.3f} mean {:.3f}",
                                    stats.quads, stats.triangles, stats.eta_min, stats.eta_mean));
  stats.total_seconds = timer.total();
  return result;
}

}  // namespace quadval
