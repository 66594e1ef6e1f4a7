// Smoothing (Paper I §6). smoothing_score, one quad or four at once, equals the score's
// definition from quad_eta and quad_min_corner_sine bit for bit (closed forms and random
// quads, valid, reflex, inverted, degenerate). smooth() gives, bit for bit, what the
// plain sweep of its doc comment gives in smoothing_order (written out here with
// element_score, node_elements and corner_of: none of smooth()'s shortcuts), on one thread
// or two; smoothing_order visits every movable node once and no two blocks of one colour
// share an element; smooth() never lowers the worst score and inverts nothing. The last polish of the worst elements (polish_worst): a closed form, one interior
// node pulled off the centre of 2 x 2 unit squares goes back to where all four are squares;
// by levels in parallel, the same bits as node after node.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <omp.h>

#include "quadval/quad_quality.hpp"
#include "recombine/boundary_slide.hpp"
#include "recombine/smoothing.hpp"

namespace quadval {
namespace {

using namespace recombine_detail;

double normal_length(const std::array<double, 3>& n) {
  return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// One quad (nodes 0..3) with the given corners; the score of smoothing_score.
double score_of(const std::array<std::array<double, 3>, 4>& x, const std::array<double, 3>& n) {
  MixedMesh m;
  for (int k = 0; k < 4; ++k) m.add_node(x[k], k + 1);
  return smoothing_score(m.coords, {0, 1, 2, 3}, n, normal_length(n));
}

TEST(SmoothingScore, ClosedForms) {
  const std::array<double, 3> up{0, 0, 1};
  EXPECT_EQ(score_of({{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, up), 1.0);  // square
  // Rhombus with 60 and 120 degree corners: each deviates 30 degrees, eta = 1 - 30/90.
  const double h = std::sqrt(3.0) / 2;
  EXPECT_NEAR(score_of({{{0, 0, 0}, {1, 0, 0}, {1.5, h, 0}, {0.5, h, 0}}}, up), 2.0 / 3.0, 1e-14);
  // The square seen from below is inverted: every corner sine is -1.
  EXPECT_EQ(score_of({{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, {0, 0, -1}), -1.0);
  // A repeated corner is degenerate: -1, like element_score.
  EXPECT_EQ(score_of({{{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, up), -1.0);
  EXPECT_EQ(score_of({{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, {0, 0, 0}), -1.0);
  // A triangle is not its business.
  MixedMesh t;
  for (int k = 0; k < 3; ++k) t.add_node({double(k == 1), double(k == 2), 0.0}, k + 1);
  EXPECT_EQ(smoothing_score(t.coords, {0, 1, 2, kNoNode}, up, 1.0), -2.0);
}

// The score by its definition: quad_eta's eta where positive, else the least corner sine
// (at most 0), from the public quality functions (none of smoothing_score's shortcuts).
double defined_score(const MixedMesh& m, const std::array<NodeIndex, 4>& q, const std::array<double, 3>& n) {
  const QuadCorners x{m.point(q[0]), m.point(q[1]), m.point(q[2]), m.point(q[3])};
  const QuadEta e = quad_eta(x, n);
  if (e.shape == QuadShape::ok && e.eta > 0.0) return e.eta;
  return std::min(quad_min_corner_sine(x, n), 0.0);
}

// Random quads around the unit square, from slightly to wildly perturbed (so convex, reflex,
// inverted and nearly degenerate ones), with tilted, scaled and (every 101st) zero normals,
// all in one mesh: quad i has nodes 4i .. 4i + 3.
MixedMesh random_quads(int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  MixedMesh m;
  for (int i = 0; i < count; ++i) {
    const double amplitude = 0.02 + 0.8 * (i % 10) / 9.0;
    const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const auto first = static_cast<NodeIndex>(m.num_nodes());
    for (int k = 0; k < 4; ++k)
      m.add_node({corner[k][0] + amplitude * unit(rng), corner[k][1] + amplitude * unit(rng),
                  amplitude * unit(rng) * (i % 3 == 0)},
                 first + k + 1);
    if (i % 97 == 0) std::memcpy(&m.coords[3 * (first + 1)], &m.coords[3 * first], 3 * sizeof(double));  // repeat
    std::array<double, 3> n{0.3 * unit(rng) * (i % 2), 0.3 * unit(rng) * (i % 2),
                            (1.0 + 0.5 * unit(rng)) * (i % 5 == 4 ? -1.0 : 1.0)};
    if (i % 101 == 0) n = {0, 0, 0};
    m.elements.push_back({first, first + 1, first + 2, first + 3});
    m.normal.push_back(n);
  }
  return m;
}

TEST(SmoothingScore, EqualsDefinitionBitForBit) {
  const MixedMesh m = random_quads(20000);
  int valid = 0, invalid = 0;
  for (std::size_t i = 0; i < m.elements.size(); ++i) {
    const double want = defined_score(m, m.elements[i], m.normal[i]);
    EXPECT_EQ(smoothing_score(m.coords, m.elements[i], m.normal[i], normal_length(m.normal[i])), want) << "quad " << i;
    EXPECT_EQ(element_score(m, i), want) << "quad " << i;
    (want > 0 ? valid : invalid)++;
  }
  EXPECT_GT(valid, 5000);
  EXPECT_GT(invalid, 2000);
}

// Four lanes (or fewer, the others unused) give each quad's smoothing_score to the bit.
TEST(SmoothingScore, FourLanesEqualOneByOne) {
  const MixedMesh m = random_quads(20000);
  std::size_t i = 0;
  for (int group = 0; i < m.elements.size(); ++group) {
    const int count = static_cast<int>(std::min<std::size_t>(1 + group % 4, m.elements.size() - i));
    const std::array<NodeIndex, 4>* quads[4] = {};
    const std::array<double, 3>* normals[4] = {};
    double lengths[4] = {}, out[4] = {9, 9, 9, 9};
    for (int k = 0; k < count; ++k) {
      quads[k] = &m.elements[i + k];
      normals[k] = &m.normal[i + k];
      lengths[k] = normal_length(m.normal[i + k]);
    }
    smoothing_scores4(m.coords, quads, normals, lengths, count, out);
    for (int k = 0; k < count; ++k)
      EXPECT_EQ(out[k], smoothing_score(m.coords, m.elements[i + k], m.normal[i + k], lengths[k])) << "quad " << i + k;
    for (int k = count; k < 4; ++k) EXPECT_EQ(out[k], 9.0) << "unused lane " << k << " written";
    i += static_cast<std::size_t>(count);
  }
}

// The sweep of smooth()'s doc comment, written the plain way: every node in smoothing_order,
// one at a time, every pass, element_score of every element at the node for each trial.
std::size_t plain_smooth(MixedMesh& m, const std::vector<char>& fixed, const SmoothingOptions& o) {
  const auto at = node_elements(m);
  const std::vector<NodeIndex> order = smoothing_order(m, fixed, o).nodes;
  std::vector<double> score(m.elements.size(), 0.0);
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e]) score[e] = element_score(m, e);
  std::size_t accepted = 0;
  for (int pass = 0; pass < 2 * o.passes; ++pass) {
    const bool raise_mean = pass >= o.passes;
    double global_min = 2.0;
    for (std::size_t e = 0; e < m.elements.size(); ++e)
      if (m.alive[e]) global_min = std::min(global_min, score[e]);
    std::size_t this_pass = 0;
    for (NodeIndex v : order) {
      const bool sliding = fixed[v] && o.slides != nullptr && (*o.slides)[v][0] != kNoNode;
      if ((fixed[v] && !sliding) || at[v].empty()) continue;
      const auto x = m.point(v);
      double sum[3] = {0, 0, 0}, weights = 0, old_min = 2.0, old_sum = 0;
      for (std::uint32_t e : at[v]) {
        old_min = std::min(old_min, score[e]);
        old_sum += score[e];
        const int c = corner_of(m.elements[e], v);
        for (NodeIndex j : {next_corner(m.elements[e], c), prev_corner(m.elements[e], c)}) {
          const auto y = m.point(j);
          double w = 1.0;
          if (o.size_field != nullptr)
            w = 1.0 / (*o.size_field)(0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1]),
                                      0.5 * (x[2] + y[2]));
          for (int d = 0; d < 3; ++d) sum[d] += w * y[d];
          weights += w;
        }
      }
      std::array<double, 3> move{sum[0] / weights - x[0], sum[1] / weights - x[1],
                                 sum[2] / weights - x[2]};
      std::array<double, 3> a{}, along{};
      if (sliding) {
        a = m.point((*o.slides)[v][0]);
        const auto b = m.point((*o.slides)[v][1]);
        along = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double ll = along[0] * along[0] + along[1] * along[1] + along[2] * along[2];
        const double t = (move[0] * along[0] + move[1] * along[1] + move[2] * along[2]) / ll;
        for (int d = 0; d < 3; ++d) move[d] = t * along[d];
      }
      for (double fraction : {1.0, 0.5}) {
        if (sliding) {
          double s = 0, ll = 0;
          for (int d = 0; d < 3; ++d) {
            s += (x[d] + fraction * move[d] - a[d]) * along[d];
            ll += along[d] * along[d];
          }
          if (!(s > 0 && s < ll)) continue;
        }
        for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d] + fraction * move[d];
        double new_min = 2.0, new_sum = 0;
        std::vector<double> trial;
        for (std::uint32_t e : at[v]) {
          trial.push_back(element_score(m, e));
          new_min = std::min(new_min, trial.back());
          new_sum += trial.back();
        }
        if (new_min >= old_min ||
            (raise_mean && new_min >= global_min && new_min > 0 && new_sum > old_sum)) {
          for (std::size_t i = 0; i < at[v].size(); ++i) score[at[v][i]] = trial[i];
          ++this_pass;
          break;
        }
        for (int d = 0; d < 3; ++d) m.coords[3 * std::size_t{v} + d] = x[d];
      }
    }
    accepted += this_pass;
    if (this_pass == 0 && raise_mean) break;
  }
  return accepted;
}

// A jittered nx x ny grid of quads on [0, nx] x [0, ny], some cells split into two triangles,
// some jitters large enough for inverted quads; the last cell's elements are removed (dead).
MixedMesh jittered_mixed_grid(int nx, int ny, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  MixedMesh m;
  auto id = [&](int i, int j) { return static_cast<NodeIndex>((nx + 1) * j + i); };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const bool inside = i > 0 && j > 0 && i < nx && j < ny;
      m.add_node({i + (inside ? jitter * unit(rng) : 0.0), j + (inside ? jitter * unit(rng) : 0.0),
                  0.0},
                 static_cast<Tag>(id(i, j) + 1));
    }
  auto add = [&](std::array<NodeIndex, 4> el, bool alive) {
    m.elements.push_back(el);
    m.region.push_back(0);
    m.normal.push_back({0, 0, 1});
    m.alive.push_back(alive);
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const bool alive = !(i == nx - 1 && j == ny - 1);
      if ((i * 7 + j * 3) % 11 == 0) {
        add({id(i, j), id(i + 1, j), id(i + 1, j + 1), kNoNode}, alive);
        add({id(i, j), id(i + 1, j + 1), id(i, j + 1), kNoNode}, alive);
      } else {
        add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, alive);
      }
    }
  return m;
}

double worst_alive_score(const MixedMesh& m) {
  double w = 2.0;
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    if (m.alive[e]) w = std::min(w, element_score(m, e));
  return w;
}

TEST(Smooth, SameBitsAsThePlainSweep) {
  const SizeFunction size = [](double x, double y, double) { return 0.5 + 0.1 * x + 0.05 * y; };
  for (unsigned seed = 1; seed <= 6; ++seed) {
    // Blocks of 512 (the default: one block here) and of 5 nodes (many blocks and colours).
    for (int block : {512, 5}) {
      const MixedMesh start = jittered_mixed_grid(9, 7, seed % 2 ? 0.3 : 0.55, seed);
      const std::vector<char> fixed = region_boundary_nodes(start);
      const auto slides = straight_boundary_slides(start, fixed);
      SmoothingOptions options;
      options.passes = 4;
      options.slides = &slides;
      options.block = block;
      if (seed > 3) options.size_field = &size;
      MixedMesh fast = start, plain = start;
      const std::size_t moves = smooth(fast, fixed, options);
      EXPECT_EQ(moves, plain_smooth(plain, fixed, options)) << "seed " << seed;
      EXPECT_GT(moves, 0u);
      ASSERT_EQ(fast.coords.size(), plain.coords.size());
      for (std::size_t i = 0; i < fast.coords.size(); ++i)
        ASSERT_EQ(fast.coords[i], plain.coords[i]) << "seed " << seed << " block " << block << " coordinate " << i;
    }
  }
}

TEST(Smooth, OrderVisitsEveryMovableNodeOnceAndColoursDoNotTouch) {
  const MixedMesh m = jittered_mixed_grid(30, 20, 0.3, 3);
  const std::vector<char> fixed = region_boundary_nodes(m);
  const auto slides = straight_boundary_slides(m, fixed);
  const auto at = node_elements(m);
  for (int block : {512, 40, 7, 1}) {
    SmoothingOptions options;
    options.slides = &slides;
    options.block = block;
    const SmoothingSweep sweep = smoothing_order(m, fixed, options);
    const std::vector<NodeIndex>& order = sweep.nodes;
    ASSERT_EQ(sweep.colors.size(), order.size());
    // Every node with an element that is free or slides, once.
    std::vector<int> seen(m.num_nodes(), 0);
    for (NodeIndex v : order) ++seen[v];
    for (NodeIndex v = 0; v < m.num_nodes(); ++v) {
      const bool movable = !at[v].empty() && (!fixed[v] || slides[v][0] != kNoNode);
      EXPECT_EQ(seen[v], movable ? 1 : 0) << "block " << block << " node " << v;
    }
    // Colour by colour; blocks are runs of `block` movable nodes in node order, each within
    // one colour, its nodes in node order; no element has corners in two different blocks of
    // one colour.
    std::vector<NodeIndex> movable;
    for (NodeIndex v = 0; v < m.num_nodes(); ++v)
      if (seen[v]) movable.push_back(v);
    std::vector<std::size_t> block_of(m.num_nodes(), SIZE_MAX), color_of(m.num_nodes(), SIZE_MAX);
    for (std::size_t k = 0; k < movable.size(); ++k) block_of[movable[k]] = k / static_cast<std::size_t>(block);
    for (std::size_t k = 0; k < order.size(); ++k) {
      color_of[order[k]] = sweep.colors[k];
      if (k > 0) {
        EXPECT_LE(sweep.colors[k - 1], sweep.colors[k]);
        if (block_of[order[k - 1]] == block_of[order[k]]) {
          EXPECT_LT(order[k - 1], order[k]);
          EXPECT_EQ(sweep.colors[k - 1], sweep.colors[k]);
        }
      }
    }
    const std::size_t color = sweep.colors.empty() ? 0 : sweep.colors.back();
    for (std::size_t e = 0; e < m.elements.size(); ++e) {
      if (!m.alive[e]) continue;
      for (int i = 0; i < MixedMesh::size(m.elements[e]); ++i)
        for (int j = 0; j < MixedMesh::size(m.elements[e]); ++j) {
          const NodeIndex a = m.elements[e][i], b = m.elements[e][j];
          if (!seen[a] || !seen[b] || block_of[a] == block_of[b]) continue;
          EXPECT_NE(color_of[a], color_of[b]) << "element " << e << " block " << block;
        }
    }
    if (block < 40) {
      EXPECT_GT(color, 0u) << "several colours expected with blocks of " << block;
    }
  }
}

TEST(Smooth, SameBitsOnOneThreadOrTwo) {
  const SizeFunction size = [](double x, double y, double) { return 0.5 + 0.02 * x + 0.01 * y; };
  MixedMesh one = jittered_mixed_grid(40, 30, 0.35, 11);
  const std::vector<char> fixed = region_boundary_nodes(one);
  const auto slides = straight_boundary_slides(one, fixed);
  SmoothingOptions options;
  options.slides = &slides;
  options.size_field = &size;
  options.block = 16;
  MixedMesh two = one;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::size_t moves_one = smooth(one, fixed, options);
  omp_set_num_threads(2);
  const std::size_t moves_two = smooth(two, fixed, options);
  omp_set_num_threads(threads);
  EXPECT_GT(moves_one, 0u);
  EXPECT_EQ(moves_one, moves_two);
  for (std::size_t i = 0; i < one.coords.size(); ++i) ASSERT_EQ(one.coords[i], two.coords[i]) << "coordinate " << i;
}

TEST(Smooth, NeverLowersTheWorstScoreNorInverts) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    MixedMesh m = jittered_mixed_grid(12, 10, 0.35, seed);
    const std::vector<char> fixed = region_boundary_nodes(m);
    const auto slides = straight_boundary_slides(m, fixed);
    std::vector<char> valid(m.elements.size());
    for (std::size_t e = 0; e < m.elements.size(); ++e) valid[e] = element_score(m, e) > 0;
    const double before = worst_alive_score(m);
    const MixedMesh start = m;
    SmoothingOptions options;
    options.slides = &slides;
    EXPECT_GT(smooth(m, fixed, options), 0u);
    EXPECT_GE(worst_alive_score(m), before) << "seed " << seed;
    for (std::size_t e = 0; e < m.elements.size(); ++e) {
      if (m.alive[e] && valid[e]) {
        EXPECT_GT(element_score(m, e), 0.0) << "seed " << seed;
      }
    }
    // The boundary keeps its shape: a fixed node stays, a sliding one stays on the line
    // through its two neighbours' first positions.
    for (NodeIndex v = 0; v < m.num_nodes(); ++v) {
      if (!fixed[v]) continue;
      const auto p = m.point(v), p0 = start.point(v);
      if (slides[v][0] == kNoNode) {
        EXPECT_EQ(p, p0) << "seed " << seed << " node " << v;
        continue;
      }
      const auto a = start.point(slides[v][0]), b = start.point(slides[v][1]);
      const double cross = (p[0] - a[0]) * (b[1] - a[1]) - (p[1] - a[1]) * (b[0] - a[0]);
      EXPECT_NEAR(cross, 0.0, 1e-12) << "seed " << seed << " node " << v;
    }
  }
}

// 2 x 2 unit squares whose centre node is pulled to (1.3, 1.2): the polish must bring it back
// near (1, 1), where all four quads are squares (eta = 1), never lowering the worst score.
TEST(PolishWorst, RestoresTheSquaresAroundAPulledNode) {
  MixedMesh m;
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) m.add_node({double(i), double(j), 0.0}, 3 * j + i + 1);
  m.coords[3 * 4] = 1.3;
  m.coords[3 * 4 + 1] = 1.2;
  auto id = [](int i, int j) { return static_cast<NodeIndex>(3 * j + i); };
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      m.elements.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      m.region.push_back(0);
      m.normal.push_back({0, 0, 1});
      m.alive.push_back(1);
    }
  auto worst = [&] {
    double w = 2;
    for (std::size_t e = 0; e < 4; ++e) w = std::min(w, element_score(m, e));
    return w;
  };
  const double before = worst();
  EXPECT_LT(before, 0.9);
  const std::vector<char> boundary = region_boundary_nodes(m);
  EXPECT_GT(polish_worst(m, boundary, SmoothingOptions{}), 0u);
  EXPECT_NEAR(m.point(4)[0], 1.0, 0.01);
  EXPECT_NEAR(m.point(4)[1], 1.0, 0.01);
  EXPECT_GT(worst(), 0.98);
  for (NodeIndex v : {0u, 1u, 2u, 3u, 5u, 6u, 7u, 8u})  // corners of the square stay
    EXPECT_EQ(m.point(v)[2], 0.0);
  EXPECT_EQ(m.point(0)[0], 0.0);
}

// polish_worst, by levels on one thread or two, gives the bits of the plain order: the
// worst elements' nodes one after the other by polish_node, ascending.
TEST(PolishWorst, SameBitsAsTheNodesOneAfterTheOther) {
  const MixedMesh start = jittered_mixed_grid(40, 30, 0.45, 5);
  const std::vector<char> fixed = region_boundary_nodes(start);
  const auto slides = straight_boundary_slides(start, fixed);
  SmoothingOptions options;
  options.slides = &slides;
  constexpr double kShare = 0.1;

  MixedMesh plain = start;
  const auto at = node_elements(plain);
  std::vector<std::pair<double, std::uint32_t>> scored;
  for (std::size_t e = 0; e < plain.elements.size(); ++e)
    if (plain.alive[e]) scored.push_back({element_score(plain, e), static_cast<std::uint32_t>(e)});
  std::sort(scored.begin(), scored.end());
  scored.resize(static_cast<std::size_t>(kShare * static_cast<double>(scored.size())));
  std::vector<NodeIndex> nodes;
  for (const auto& [score, e] : scored)
    for (int c = 0; c < MixedMesh::size(plain.elements[e]); ++c) nodes.push_back(plain.elements[e][c]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  std::size_t plain_kept = 0;
  for (NodeIndex v : nodes) {
    const bool sliding = fixed[v] && slides[v][0] != kNoNode;
    if ((!fixed[v] || sliding) && !at[v].empty()) plain_kept += polish_node(plain, v, at[v], sliding, options);
  }
  EXPECT_GT(nodes.size(), 100u);
  EXPECT_GT(plain_kept, 100u);

  const int threads = omp_get_max_threads();
  for (int t : {1, 2}) {
    omp_set_num_threads(t);
    MixedMesh m = start;
    EXPECT_EQ(polish_worst(m, fixed, options, kShare), plain_kept) << t << " thread(s)";
    for (std::size_t i = 0; i < m.coords.size(); ++i)
      ASSERT_EQ(m.coords[i], plain.coords[i]) << t << " thread(s), coordinate " << i;
  }
  omp_set_num_threads(threads);
}

}  // namespace
}  // namespace quadval
