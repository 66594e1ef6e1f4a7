#include "smoothing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>

#include "eta_of_cosine.hpp"

namespace quadval::recombine_detail {

namespace {

// The score of a quad that is not valid with eta > 0: min(least corner sine, 0), or -1 where
// a corner is degenerate. @pre normal_length != 0
double sine_score(const double turn[4], const double lengths[4], double normal_length) noexcept {
  double worst_sine = 1.0;
  for (int k = 0; k < 4; ++k) {
    const double scale = lengths[k] * normal_length;
    if (scale == 0.0) return -1.0;
    worst_sine = std::min(worst_sine, turn[k] / scale);
  }
  return std::min(worst_sine, 0.0);
}

// The score from a quad's corners, the last step of smoothing_score: per corner k,
// turn[k] = (forward x backward edge) . normal, lengths[k] = the product of the two edges'
// lengths, cosine[k] = |forward . backward|. smoothing_scores4 does the same in lanes.
// @pre normal_length != 0
double score_of_corners(const double turn[4], const double lengths[4], const double cosine[4],
                        double normal_length) noexcept {
  bool valid = true;
  for (int k = 0; k < 4; ++k)
    if (lengths[k] == 0.0 || turn[k] <= 0.0) valid = false;  // degenerate, reflex or inverted
  if (valid) {
    double worst_cos = 0.0;
    for (int k = 0; k < 4; ++k) worst_cos = std::max(worst_cos, cosine[k] / lengths[k]);
    const double eta = eta_of_cosine(std::min(worst_cos, 1.0));  // eq. 3
    if (eta > 0.0) return eta;
  }
  return sine_score(turn, lengths, normal_length);
}

}  // namespace

double smoothing_score(const std::vector<double>& coords, const std::array<NodeIndex, 4>& element,
                       const std::array<double, 3>& normal, double normal_length) noexcept {
  if (element[3] == kNoNode) return -2.0;  // not a quad: callers use element_score
  if (normal_length == 0.0) return -1.0;   // quad_eta: degenerate; corner sine: -1
  // The operations of quad_eta and quad_min_corner_sine, in their order, so the value is the
  // same to the bit; but each edge and its length once (corner k's backward edge is exactly
  // minus edge k-1), not twice.
  double edge[4][3], length[4];
  for (int k = 0; k < 4; ++k) {
    const double* p = coords.data() + 3 * std::size_t{element[k]};
    const double* q = coords.data() + 3 * std::size_t{element[(k + 1) % 4]};
    for (int d = 0; d < 3; ++d) edge[k][d] = q[d] - p[d];
    length[k] =
        std::sqrt(edge[k][0] * edge[k][0] + edge[k][1] * edge[k][1] + edge[k][2] * edge[k][2]);
  }
  double turn[4], lengths[4], cosine[4];  // per corner
  for (int k = 0; k < 4; ++k) {
    const double* f = edge[k];
    const double b[3] = {-edge[(k + 3) % 4][0], -edge[(k + 3) % 4][1], -edge[(k + 3) % 4][2]};
    lengths[k] = length[k] * length[(k + 3) % 4];
    const double cr[3] = {f[1] * b[2] - f[2] * b[1], f[2] * b[0] - f[0] * b[2],
                          f[0] * b[1] - f[1] * b[0]};
    turn[k] = cr[0] * normal[0] + cr[1] * normal[1] + cr[2] * normal[2];
    cosine[k] = std::abs(f[0] * b[0] + f[1] * b[1] + f[2] * b[2]);
  }
  return score_of_corners(turn, lengths, cosine, normal_length);
}

void smoothing_scores4(const std::vector<double>& coords, const std::array<NodeIndex, 4>* const quads[4],
                       const std::array<double, 3>* const normals[4], const double normal_lengths[4], int count,
                       double out[4]) noexcept {
  using V = EtaLanes;  // four lanes, one quad each
  // Corner positions and normals, lane by lane (unused lanes repeat lane 0).
  V x[4][3], n[3];
  for (int l = 0; l < 4; ++l) {
    const int q = l < count ? l : 0;
    for (int k = 0; k < 4; ++k) {
      const double* p = coords.data() + 3 * std::size_t{(*quads[q])[k]};
      for (int d = 0; d < 3; ++d) x[k][d][l] = p[d];
    }
    for (int d = 0; d < 3; ++d) n[d][l] = (*normals[q])[d];
  }
  // smoothing_score's operations, in its order.
  V edge[4][3], length[4];
  for (int k = 0; k < 4; ++k) {
    for (int d = 0; d < 3; ++d) edge[k][d] = x[(k + 1) % 4][d] - x[k][d];
    const V sq = edge[k][0] * edge[k][0] + edge[k][1] * edge[k][1] + edge[k][2] * edge[k][2];
    for (int l = 0; l < 4; ++l) length[k][l] = std::sqrt(sq[l]);
  }
  V turn[4], lengths[4], cosine[4];
  for (int k = 0; k < 4; ++k) {
    const V* f = edge[k];
    const V b[3] = {-edge[(k + 3) % 4][0], -edge[(k + 3) % 4][1], -edge[(k + 3) % 4][2]};
    lengths[k] = length[k] * length[(k + 3) % 4];
    const V cr[3] = {f[1] * b[2] - f[2] * b[1], f[2] * b[0] - f[0] * b[2], f[0] * b[1] - f[1] * b[0]};
    turn[k] = cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2];
    cosine[k] = f[0] * b[0] + f[1] * b[1] + f[2] * b[2];
  }
  // score_of_corners in lanes: validity, the worst cosine (garbage in the lanes of a
  // degenerate corner, which are not valid) and eta.
  auto valid = lengths[0] != 0.0 && turn[0] > 0.0;
  for (int k = 1; k < 4; ++k) valid = valid && lengths[k] != 0.0 && turn[k] > 0.0;
  V worst_cos = {0, 0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    const V c = (cosine[k] < 0.0 ? -cosine[k] : cosine[k]) / lengths[k];
    worst_cos = worst_cos < c ? c : worst_cos;  // std::max
  }
  const V one = {1, 1, 1, 1};
  const V eta = eta_of_cosine(one < worst_cos ? one : worst_cos);  // std::min
  for (int l = 0; l < count; ++l) {
    if (normal_lengths[l] == 0.0) {
      out[l] = -1.0;
    } else if (valid[l] && eta[l] > 0.0) {
      out[l] = eta[l];
    } else {
      const double t[4] = {turn[0][l], turn[1][l], turn[2][l], turn[3][l]};
      const double len[4] = {lengths[0][l], lengths[1][l], lengths[2][l], lengths[3][l]};
      out[l] = sine_score(t, len, normal_lengths[l]);
    }
  }
}

namespace {

bool can_slide(NodeIndex v, const std::vector<char>& fixed, const SmoothingOptions& options) {
  return fixed[v] && options.slides != nullptr && (*options.slides)[v][0] != kNoNode;
}

/// Everything smooth() needs that the moves do not change (the topology is fixed here): per
/// node its alive elements and, per element, its two edge neighbours there; the movable nodes
/// and the sweep's blocks and colours (smoothing_order).
struct SmoothingTopology {
  std::vector<std::uint32_t> star_offsets;             ///< #nodes + 1
  std::vector<std::uint32_t> star;                     ///< local ids of the elements at each node
  std::vector<std::array<NodeIndex, 2>> star_sides;    ///< per star entry: next, prev corner
  std::vector<NodeIndex> order;                        ///< movable nodes, ascending
  /// Blocks: runs of SmoothingOptions::block consecutive entries of `order`, block b being
  /// order[b * block, ...). Colours: blocks[color_first[c] .. color_first[c + 1]) are the
  /// blocks of colour c, ascending; two blocks of one colour share no element.
  std::vector<std::uint32_t> blocks, color_first;
  /// Local id -> element of m: the alive elements in the order the sweep first meets them,
  /// so that a sweep reads their data nearly in memory order (m's order, after matching and
  /// repair, scatters them: cache misses).
  std::vector<std::uint32_t> element_of;
};

SmoothingTopology build_topology(const MixedMesh& m, const std::vector<char>& fixed,
                                 const SmoothingOptions& options) {
  SmoothingTopology t;
  const std::size_t n = m.num_nodes();
  t.star_offsets.assign(n + 1, 0);
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e])
      for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i)
        ++t.star_offsets[m.elements[e][i] + 1];
  for (std::size_t i = 0; i < n; ++i) t.star_offsets[i + 1] += t.star_offsets[i];
  t.star.resize(t.star_offsets[n]);
  t.star_sides.resize(t.star_offsets[n]);
  std::vector<std::uint32_t> fill(t.star_offsets.begin(), t.star_offsets.end() - 1);
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    if (!m.alive[e]) continue;
    const auto& el = m.elements[e];
    for (int i = 0; i < MixedMesh::size(el); ++i) {
      const std::uint32_t k = fill[el[i]]++;
      t.star[k] = static_cast<std::uint32_t>(e);
      t.star_sides[k] = {next_corner(el, i), prev_corner(el, i)};
    }
  }

  for (NodeIndex v = 0; v < n; ++v)
    if ((!fixed[v] || can_slide(v, fixed, options)) && t.star_offsets[v] < t.star_offsets[v + 1])
      t.order.push_back(v);

  // Greedy colours of the blocks, in block order: the smallest colour that no earlier block
  // sharing an element with this one has. Nodes follow a space-filling curve
  // (order_nodes_along_curve), so a block is a compact patch and has few neighbours.
  constexpr std::uint32_t kUnset = 0xffffffffu;
  const std::size_t block = static_cast<std::size_t>(std::max(1, options.block));
  const std::size_t num_blocks = (t.order.size() + block - 1) / block;
  std::vector<std::uint32_t> block_of(n, kUnset), color(num_blocks, 0), seen;
  for (std::size_t k = 0; k < t.order.size(); ++k) block_of[t.order[k]] = static_cast<std::uint32_t>(k / block);
  std::uint32_t colors = 0;
  for (std::size_t b = 0; b < num_blocks; ++b) {
    seen.assign(colors + 1, 0);
    for (std::size_t k = b * block; k < std::min(t.order.size(), (b + 1) * block); ++k) {
      const NodeIndex v = t.order[k];
      for (std::uint32_t i = t.star_offsets[v]; i < t.star_offsets[v + 1]; ++i) {
        const auto& el = m.elements[t.star[i]];
        for (int c = 0; c < MixedMesh::size(el); ++c) {
          const std::uint32_t other = block_of[el[c]];
          if (other != kUnset && other < b) seen[color[other]] = 1;
        }
      }
    }
    color[b] = static_cast<std::uint32_t>(std::find(seen.begin(), seen.end(), 0) - seen.begin());
    colors = std::max(colors, color[b] + 1);
  }
  t.color_first.assign(colors + 1, 0);
  for (std::uint32_t c : color) ++t.color_first[c + 1];
  for (std::uint32_t c = 0; c < colors; ++c) t.color_first[c + 1] += t.color_first[c];
  t.blocks.resize(num_blocks);
  std::vector<std::uint32_t> next(t.color_first.begin(), t.color_first.end() - 1);
  for (std::size_t b = 0; b < num_blocks; ++b) t.blocks[next[color[b]]++] = static_cast<std::uint32_t>(b);

  std::vector<std::uint32_t> local(m.elements.size(), kUnset);
  auto number = [&](std::uint32_t e) {
    if (local[e] != kUnset) return;
    local[e] = static_cast<std::uint32_t>(t.element_of.size());
    t.element_of.push_back(e);
  };
  for (NodeIndex v : t.order)
    for (std::uint32_t i = t.star_offsets[v]; i < t.star_offsets[v + 1]; ++i) number(t.star[i]);
  for (std::size_t e = 0; e < m.elements.size(); ++e)  // those with no movable corner
    if (m.alive[e]) number(static_cast<std::uint32_t>(e));
  for (std::uint32_t& e : t.star) e = local[e];
  return t;
}

/// One smooth() call: the topology, the score of each element (cached, updated on each
/// accepted move) and the trial of one node.
class Smoother {
 public:
  Smoother(MixedMesh& m, const std::vector<char>& fixed, const SmoothingOptions& options)
      : m_(m), fixed_(fixed), options_(options), topo_(build_topology(m, fixed, options)) {
    const std::size_t count = topo_.element_of.size();
    elements_.resize(count);
    normals_.resize(count);
    normal_length_.resize(count);
    score_.resize(count);
    for (std::size_t l = 0; l < count; ++l) {
      const std::uint32_t e = topo_.element_of[l];
      elements_[l] = m.elements[e];
      normals_[l] = m.normal[e];
      const auto& nv = normals_[l];
      normal_length_[l] = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
      score_[l] = score(static_cast<std::uint32_t>(l));
    }
  }

  std::size_t run();

 private:
  // element_score of local element l; for quads through smoothing_score (the same value).
  double score(std::uint32_t l) const noexcept {
    return elements_[l][3] != kNoNode
               ? smoothing_score(m_.coords, elements_[l], normals_[l], normal_length_[l])
               : element_score(m_, topo_.element_of[l]);
  }
  bool try_move(NodeIndex v, bool raise_mean, double global_min, std::vector<double>& trial);
  // The scores of the star entries [first, last) into trial[0 ..): quads four at a time
  // (smoothing_scores4: the same values; random quads 59-73 -> 43-48 ns each, before eta
  // too went into lanes), triangles by element_score. The move's test then reads them in
  // star order.
  void score_star(std::uint32_t first, std::uint32_t last, std::vector<double>& trial) const {
    trial.resize(last - first);
    const std::array<NodeIndex, 4>* quads[4];
    const std::array<double, 3>* normals[4];
    double lengths[4], out[4];
    std::uint32_t at[4];
    int lanes = 0;
    const auto flush = [&] {
      smoothing_scores4(m_.coords, quads, normals, lengths, lanes, out);
      for (int k = 0; k < lanes; ++k) trial[at[k]] = out[k];
      lanes = 0;
    };
    for (std::uint32_t i = first; i < last; ++i) {
      const std::uint32_t l = topo_.star[i];
      if (elements_[l][3] == kNoNode) {
        trial[i - first] = element_score(m_, topo_.element_of[l]);
        continue;
      }
      quads[lanes] = &elements_[l];
      normals[lanes] = &normals_[l];
      lengths[lanes] = normal_length_[l];
      at[lanes] = i - first;
      if (++lanes == 4) flush();
    }
    if (lanes > 0) flush();
  }

  MixedMesh& m_;
  const std::vector<char>& fixed_;
  const SmoothingOptions& options_;
  SmoothingTopology topo_;
  // Per local element (topo_.element_of): copies of its corners and normal, |normal|, score.
  std::vector<std::array<NodeIndex, 4>> elements_;
  std::vector<std::array<double, 3>> normals_;
  std::vector<double> normal_length_;
  std::vector<double> score_;
};

bool Smoother::try_move(NodeIndex v, bool raise_mean, double global_min,
                        std::vector<double>& trial) {
  const std::uint32_t first = topo_.star_offsets[v], last = topo_.star_offsets[v + 1];
  const bool sliding = fixed_[v] != 0;  // only the sliding fixed nodes are in the order
  const std::array<double, 3> x = m_.point(v);
  double sum[3] = {0, 0, 0}, weights = 0, old_min = 2.0, old_sum = 0.0;
  NodeIndex near = v;  // a neighbour, where v has no place on the surface yet
  std::array<double, 3> normal{0, 0, 0};
  for (std::uint32_t i = first; i < last; ++i) {
    const std::uint32_t e = topo_.star[i];
    old_min = std::min(old_min, score_[e]);
    old_sum += score_[e];
    if (options_.tangential)
      for (int d = 0; d < 3; ++d) normal[d] += normals_[e][d];
    // Each edge neighbour appears in two elements at an interior node: each counts once
    // per element, which weighs them equally.
    for (NodeIndex j : topo_.star_sides[i]) {
      near = j;
      const double* y = m_.coords.data() + 3 * std::size_t{j};
      double w = 1.0;
      if (options_.size_field != nullptr) {
        const double h = (*options_.size_field)(0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1]),
                                                0.5 * (x[2] + y[2]));
        w = h > 0 && std::isfinite(h) ? 1.0 / h : 1.0;
      }
      for (int d = 0; d < 3; ++d) sum[d] += w * y[d];
      weights += w;
    }
  }
  std::array<double, 3> move{sum[0] / weights - x[0], sum[1] / weights - x[1],
                             sum[2] / weights - x[2]};
  std::array<double, 3> a{}, along{};
  if (sliding) {
    // Keep only the component along the side a-b.
    a = m_.point((*options_.slides)[v][0]);
    const auto b = m_.point((*options_.slides)[v][1]);
    along = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double ll = along[0] * along[0] + along[1] * along[1] + along[2] * along[2];
    const double t = (move[0] * along[0] + move[1] * along[1] + move[2] * along[2]) / ll;
    for (int d = 0; d < 3; ++d) move[d] = t * along[d];
  } else if (options_.tangential) {
    const double nn = normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2];
    if (nn > 0) {
      const double h = (move[0] * normal[0] + move[1] * normal[1] + move[2] * normal[2]) / nn;
      for (int d = 0; d < 3; ++d) move[d] -= h * normal[d];
    }
  }
  double* position = m_.coords.data() + 3 * std::size_t{v};
  for (double fraction : {1.0, 0.5}) {
    if (sliding) {
      // Strictly between a and b (s in (0, 1) along a-b), so the side keeps its order.
      double s = 0, ll = 0;
      for (int d = 0; d < 3; ++d) {
        s += (x[d] + fraction * move[d] - a[d]) * along[d];
        ll += along[d] * along[d];
      }
      if (!(s > 0 && s < ll)) continue;
    }
    for (int d = 0; d < 3; ++d) position[d] = x[d] + fraction * move[d];
    if (options_.surface != nullptr && !sliding) {
      const auto on = options_.surface->project(v, {position[0], position[1], position[2]}, near);
      for (int d = 0; d < 3; ++d) position[d] = on[d];
    }
    // Phase 1: never lower the worst element at v. Phase 2: also take moves that raise the
    // sum of the scores at v while keeping them above the mesh's worst at the sweep's start.
    // A score below old_min that also fails phase 2's floor refuses the move at once.
    const double floor =
        raise_mean ? std::max(global_min, std::numeric_limits<double>::denorm_min()) : 2.0;
    score_star(first, last, trial);
    double new_min = 2.0, new_sum = 0;
    bool refused = false;
    for (std::uint32_t i = first; i < last; ++i) {
      const double s = trial[i - first];
      if (s < old_min && s < floor) {
        refused = true;
        break;
      }
      new_min = std::min(new_min, s);
      new_sum += s;
    }
    if (!refused && (new_min >= old_min || (raise_mean && new_min >= global_min &&
                                            new_min > 0 && new_sum > old_sum))) {
      for (std::uint32_t i = first; i < last; ++i) score_[topo_.star[i]] = trial[i - first];
      return true;
    }
    for (int d = 0; d < 3; ++d) position[d] = x[d];
  }
  return false;
}

std::size_t Smoother::run() {
  std::size_t accepted = 0;
  const std::size_t block = static_cast<std::size_t>(std::max(1, options_.block));
  for (int pass = 0; pass < 2 * options_.passes; ++pass) {
    const bool raise_mean = pass >= options_.passes;
    double global_min = 2.0;
    for (double s : score_) global_min = std::min(global_min, s);
    std::size_t accepted_this_pass = 0;
    // The blocks of one colour share no element: a move reads and writes only its node's
    // elements and their corners, so they go in parallel, and the result is that of the
    // sweep in smoothing_order for any number of threads.
    for (std::size_t c = 0; c + 1 < topo_.color_first.size(); ++c) {
      const auto first = static_cast<std::ptrdiff_t>(topo_.color_first[c]);
      const auto last = static_cast<std::ptrdiff_t>(topo_.color_first[c + 1]);
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : accepted_this_pass) if (last - first > 1)
      for (std::ptrdiff_t i = first; i < last; ++i) {
        std::vector<double> trial;
        const std::size_t b = topo_.blocks[static_cast<std::size_t>(i)];
        for (std::size_t k = b * block; k < std::min(topo_.order.size(), (b + 1) * block); ++k)
          if (try_move(topo_.order[k], raise_mean, global_min, trial)) ++accepted_this_pass;
      }
    }
    accepted += accepted_this_pass;
    if (accepted_this_pass == 0 && raise_mean) break;
  }
  return accepted;
}

}  // namespace

std::size_t smooth(MixedMesh& m, const std::vector<char>& fixed, const SmoothingOptions& options) {
  if (options.passes <= 0) return 0;
  if (options.surface != nullptr) options.surface->reserve_nodes(m.num_nodes());
  return Smoother(m, fixed, options).run();
}

SmoothingSweep smoothing_order(const MixedMesh& m, const std::vector<char>& fixed,
                               const SmoothingOptions& options) {
  const SmoothingTopology t = build_topology(m, fixed, options);
  const std::size_t block = static_cast<std::size_t>(std::max(1, options.block));
  SmoothingSweep out;
  for (std::size_t c = 0; c + 1 < t.color_first.size(); ++c)
    for (std::uint32_t i = t.color_first[c]; i < t.color_first[c + 1]; ++i) {
      const std::size_t b = t.blocks[i];
      for (std::size_t k = b * block; k < std::min(t.order.size(), (b + 1) * block); ++k) {
        out.nodes.push_back(t.order[k]);
        out.colors.push_back(static_cast<std::uint32_t>(c));
      }
    }
  return out;
}

namespace {

// The least score of these elements (element_score's values: quads four at a time).
double least_score(const MixedMesh& m, std::span<const std::uint32_t> elements) noexcept {
  double low = 2.0;
  const std::array<NodeIndex, 4>* quads[4];
  const std::array<double, 3>* normals[4];
  double lengths[4], out[4];
  int lanes = 0;
  const auto flush = [&] {
    smoothing_scores4(m.coords, quads, normals, lengths, lanes, out);
    for (int k = 0; k < lanes; ++k) low = std::min(low, out[k]);
    lanes = 0;
  };
  for (std::uint32_t e : elements) {
    if (m.elements[e][3] == kNoNode) {
      low = std::min(low, element_score(m, e));
      continue;
    }
    const auto& n = m.normal[e];
    quads[lanes] = &m.elements[e];
    normals[lanes] = &n;
    lengths[lanes] = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (++lanes == 4) flush();
  }
  if (lanes > 0) flush();
  return low;
}

}  // namespace

std::size_t polish_node(MixedMesh& m, NodeIndex v, std::span<const std::uint32_t> star, bool sliding,
                        const SmoothingOptions& options) {
  std::size_t kept = 0;
  // Directions: the straight side, or two orthonormal tangents of the mean normal.
  std::array<double, 3> a{}, d1{}, d2{};
  int directions = 2;
  double edge = 0;
  int edges = 0;
  const auto x0 = m.point(v);
  std::array<double, 3> normal{0, 0, 0};
  for (std::uint32_t e : star) {
    for (int k = 0; k < 3; ++k) normal[k] += m.normal[e][k];
    const auto& el = m.elements[e];
    const auto y = m.point(next_corner(el, corner_of(el, v)));
    edge += std::sqrt((y[0] - x0[0]) * (y[0] - x0[0]) + (y[1] - x0[1]) * (y[1] - x0[1]) +
                      (y[2] - x0[2]) * (y[2] - x0[2]));
    ++edges;
  }
  edge /= edges;
  auto unit = [](std::array<double, 3> u) {
    const double l = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    return std::array<double, 3>{u[0] / l, u[1] / l, u[2] / l};
  };
  std::array<double, 3> b{};
  if (sliding) {
    a = m.point((*options.slides)[v][0]);
    b = m.point((*options.slides)[v][1]);
    d1 = unit({b[0] - a[0], b[1] - a[1], b[2] - a[2]});
    directions = 1;
  } else {
    const auto n = unit(normal);
    // Any vector not parallel to n, made orthogonal to it; then n x d1.
    std::array<double, 3> t = std::abs(n[0]) < 0.9 ? std::array<double, 3>{1, 0, 0}
                                                   : std::array<double, 3>{0, 1, 0};
    const double tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    d1 = unit({t[0] - tn * n[0], t[1] - tn * n[1], t[2] - tn * n[2]});
    d2 = {n[1] * d1[2] - n[2] * d1[1], n[2] * d1[0] - n[0] * d1[2], n[0] * d1[1] - n[1] * d1[0]};
  }
  double best = least_score(m, star);
  for (double h = 0.1 * edge; h >= 1e-3 * edge;) {
    bool improved = false;
    for (int k = 0; k < 2 * directions && !improved; ++k) {
      const auto& dir = k < 2 ? d1 : d2;
      const double step = (k % 2 == 0 ? h : -h);
      const auto x = m.point(v);
      std::array<double, 3> y{x[0] + step * dir[0], x[1] + step * dir[1], x[2] + step * dir[2]};
      if (options.surface != nullptr && !sliding) {
        const auto& el = m.elements[star[0]];
        y = options.surface->project(v, y, next_corner(el, corner_of(el, v)));
      }
      if (sliding) {  // strictly inside the side a-b
        double s = 0, ll = 0;
        for (int q = 0; q < 3; ++q) {
          s += (y[q] - a[q]) * (b[q] - a[q]);
          ll += (b[q] - a[q]) * (b[q] - a[q]);
        }
        if (!(s > 0 && s < ll)) continue;
      }
      for (int q = 0; q < 3; ++q) m.coords[3 * std::size_t{v} + q] = y[q];
      const double trial = least_score(m, star);
      if (trial > best) {
        best = trial;
        improved = true;
        ++kept;
      } else {
        for (int q = 0; q < 3; ++q) m.coords[3 * std::size_t{v} + q] = x[q];
      }
    }
    if (!improved) h *= 0.5;
  }
  return kept;
}

std::size_t polish_worst(MixedMesh& m, const std::vector<char>& fixed,
                         const SmoothingOptions& options, double share) {
  if (options.surface != nullptr) options.surface->reserve_nodes(m.num_nodes());
  const std::vector<std::vector<std::uint32_t>> at = node_elements(m);
  std::vector<std::pair<double, std::uint32_t>> worst;
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e]) worst.push_back({element_score(m, e), static_cast<std::uint32_t>(e)});
  const std::size_t count = std::min(
      worst.size(), std::max<std::size_t>(16, static_cast<std::size_t>(share * worst.size())));
  std::partial_sort(worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(count),
                    worst.end());
  std::vector<NodeIndex> nodes;
  for (std::size_t i = 0; i < count; ++i) {
    const auto& el = m.elements[worst[i].second];
    for (int c = 0; c < MixedMesh::size(el); ++c) nodes.push_back(el[c]);
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());

  // Levels: a node's is one more than the highest of the earlier listed nodes that share an
  // element with it. The nodes of one level share no element, so their searches read and
  // write disjoint positions and run in parallel, and every node still sees the final
  // positions of the earlier nodes it depends on: the result is that of the searches one
  // after the other in node order, for any number of threads.
  std::vector<int> level_of(m.num_nodes(), -1);
  std::vector<std::vector<NodeIndex>> levels;
  for (NodeIndex v : nodes) {
    if ((fixed[v] && !can_slide(v, fixed, options)) || at[v].empty()) continue;
    int level = 0;
    for (std::uint32_t e : at[v])
      for (int c = 0; c < MixedMesh::size(m.elements[e]); ++c)
        level = std::max(level, level_of[m.elements[e][c]] + 1);
    level_of[v] = level;
    if (static_cast<std::size_t>(level) == levels.size()) levels.emplace_back();
    levels[static_cast<std::size_t>(level)].push_back(v);
  }
  std::size_t kept = 0;
  for (const std::vector<NodeIndex>& level : levels) {
    const auto size = static_cast<std::ptrdiff_t>(level.size());
#pragma omp parallel for schedule(dynamic, 8) reduction(+ : kept) if (size > 64)
    for (std::ptrdiff_t i = 0; i < size; ++i) {
      const NodeIndex v = level[static_cast<std::size_t>(i)];
      kept += polish_node(m, v, at[v], fixed[v] != 0, options);
    }
  }
  return kept;
}

}  // namespace quadval::recombine_detail
