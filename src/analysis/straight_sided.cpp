// The margin of a straight-sided high-order element (straight_sided.hpp).
#include "analysis/straight_sided.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "analysis/jacobian_product.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kStraight = 1e-9;  // deviation / edge below which an element counts as straight
constexpr double kUnderflow = 0x1p-1000;

constexpr std::size_t kLanes = kNativeLanes;  // elements side by side (lane_vector.hpp, also vabs and vmax)
// The first-order kind of a curved type's vertices (pyramids excluded: Bergot's
// first-order map is not in the space of the higher orders' maps).
LinearKind vertex_kind(const ElementType& type, bool planar) noexcept {
  if (type.order < 2 || !type.has_lagrange_basis || type.family == ElementFamily::pyramid) return LinearKind::none;
  const ElementType* first_order = find_element_type(type.family, 1, true);
  return first_order != nullptr ? linear_kind(*first_order, planar) : LinearKind::none;
}

// Per direction c, the vertex pairs (from, to) of the edges whose convex combination is
// a_c (halved on [-1, 1]).
struct Direction {
  int edges;
  int from[4], to[4];
};
constexpr Direction kTriangle[2] = {{1, {0}, {1}}, {1, {0}, {2}}};
constexpr Direction kTetrahedron[3] = {{1, {0}, {1}}, {1, {0}, {2}}, {1, {0}, {3}}};
constexpr Direction kQuadrangle[2] = {{2, {0, 3}, {1, 2}}, {2, {0, 1}, {3, 2}}};
constexpr Direction kHexahedron[3] = {
    {4, {0, 3, 4, 7}, {1, 2, 5, 6}}, {4, {0, 1, 4, 5}, {3, 2, 7, 6}}, {4, {0, 1, 2, 3}, {4, 5, 6, 7}}};

const Direction* directions(LinearKind kind) noexcept {
  switch (kind) {
    case LinearKind::triangle: return kTriangle;
    case LinearKind::tetrahedron: return kTetrahedron;
    case LinearKind::quadrangle: return kQuadrangle;
    case LinearKind::hexahedron: return kHexahedron;
    default: return nullptr;
  }
}

}  // namespace

StraightSidedMargin::StraightSidedMargin(const ElementType& type, const JacobianSpace& space, bool planar)
    : kind_(vertex_kind(type, planar)) {
  if (kind_ == LinearKind::none || space.product() == nullptr) {
    kind_ = LinearKind::none;
    return;
  }
  num_nodes_ = type.num_nodes;
  num_vertices_ = linear_num_vertices(kind_);
  dim_ = type.dim;
  axes_ = dim_ == 2 ? 2 : 3;
  // N_v at every other node: barycentric on simplices, products of (1 +- xi) / 2 on
  // quadrangles and hexahedra (the vertices' reference coordinates give the signs).
  const auto nodes = reference_nodes(type);
  const auto vertices = reference_vertices(type.family);
  const bool simplex = kind_ == LinearKind::triangle || kind_ == LinearKind::tetrahedron;
  for (int i = num_vertices_; i < num_nodes_; ++i) {
    const RefPoint& x = nodes[static_cast<std::size_t>(i)];
    NodeTerms t;
    for (int v = 1; v < num_vertices_; ++v) {
      double n = 1;
      if (simplex) {
        n = x[static_cast<std::size_t>(v - 1)];
      } else {
        for (int k = 0; k < dim_; ++k)
          n *= (1 + vertices[static_cast<std::size_t>(v)][static_cast<std::size_t>(k)] * x[static_cast<std::size_t>(k)]) / 2;
      }
      if (n == 0) continue;
      t.vertex[static_cast<std::size_t>(t.count)] = v;
      t.value[static_cast<std::size_t>(t.count++)] = n;
    }
    terms_.push_back(t);
  }
  for (int c = 0; c < dim_; ++c) lambda_[static_cast<std::size_t>(c)] = space.product()->derivative_row_sum(SampleMap::curved, c);
  // N~ within 8u of N (at most three roundings of values in [-1, 2], and the reference
  // coordinate's own); the products N~ y~ and the sum of n_v terms: (n_v + 3) u more of
  // sum |y_v|; the differences y = x - x_0 and d = y_i - sum: 3u; so (n_v + 14) u S, twice.
  deviation_error_ = 2 * (num_vertices_ + 14) * kUnit;
}

template <int W, class At>
void StraightSidedMargin::lane_margins(const At& at, double* out, double* beta_out) const noexcept {
  using V = Lanes<W>;
  const auto nn = static_cast<std::size_t>(num_nodes_);
  const auto nv = static_cast<std::size_t>(num_vertices_);
  const auto axes = static_cast<std::size_t>(axes_);
  // The vertices, gathered once; y_v = x_v - x_0, and sum_v |y_v| per axis.
  V xv[8][3], y[8][3], vertex_sum[3] = {};
  for (std::size_t v = 0; v < nv; ++v)
    for (std::size_t j = 0; j < axes; ++j) xv[v][j] = at(v, j);
  const V* x0 = xv[0];
  for (std::size_t v = 1; v < nv; ++v)
    for (std::size_t j = 0; j < axes; ++j) {
      y[v][j] = xv[v][j] - x0[j];
      vertex_sum[j] += vabs(y[v][j]);
    }
  // alpha_c: the largest 1-norm of the edges of direction c (halved on [-1, 1]).
  const Direction* dirs = directions(kind_);
  const double half = kind_ == LinearKind::triangle || kind_ == LinearKind::tetrahedron ? 1.0 : 0.5;
  V alpha[3] = {}, edge = {}, finite = {};
  for (std::size_t c = 0; c < static_cast<std::size_t>(dim_); ++c) {
    for (int k = 0; k < dirs[c].edges; ++k) {
      const auto from = static_cast<std::size_t>(dirs[c].from[k]), to = static_cast<std::size_t>(dirs[c].to[k]);
      V norm = {};  // from the coordinates: one rounding per component, however far from x_0
      for (std::size_t j = 0; j < axes; ++j) norm += vabs(xv[to][j] - xv[from][j]);
      alpha[c] = vmax(alpha[c], norm);
      finite += norm;
    }
    edge = vmax(edge, alpha[c]);
    alpha[c] *= half * (1 + 1e-12);
  }
  // The largest deviation and the largest |y| of the other nodes, per axis; `finite` sums
  // the deviations, so that a NaN or infinite coordinate (which max would drop) shows.
  // Curved elements stop at the first node that shows every lane curved.
  const V limit = kStraight * edge;
  V deviation[3] = {}, largest[3] = {};
  for (std::size_t i = nv; i < nn; ++i) {
    const NodeTerms& t = terms_[i - nv];
    for (std::size_t j = 0; j < axes; ++j) {
      const V yi = at(i, j) - x0[j];
      V lin = {};
      for (int k = 0; k < t.count; ++k)
        lin += t.value[static_cast<std::size_t>(k)] * y[static_cast<std::size_t>(t.vertex[static_cast<std::size_t>(k)])][j];
      const V d = vabs(yi - lin);
      deviation[j] = vmax(deviation[j], d);
      largest[j] = vmax(largest[j], vabs(yi));
      finite += d;
    }
    const V shown = deviation[0] + deviation[1] + deviation[2];
    bool all_curved = true;
    for (std::size_t l = 0; l < W && all_curved; ++l) all_curved = shown[l] > limit[l];
    if (all_curved) {
      std::fill(out, out + W, kInf);
      return;
    }
  }
  V delta = {};
  for (std::size_t j = 0; j < axes; ++j)
    delta += deviation[j] + deviation_error_ * (largest[j] + vertex_sum[j]) + kUnderflow;
  // The differences' and the 1-norms' roundings (a few u relative) are covered by 1 + 1e-12.
  V beta[3] = {};
  for (std::size_t c = 0; c < static_cast<std::size_t>(dim_); ++c) beta[c] = lambda_[c] * delta * (1 + 1e-12);
  // prod (alpha + beta) - prod alpha, as a sum of nonnegative terms.
  const V m = dim_ == 3 ? beta[0] * (alpha[1] + beta[1]) * (alpha[2] + beta[2]) +
                              alpha[0] * (beta[1] * (alpha[2] + beta[2]) + alpha[1] * beta[2])
                        : beta[0] * (alpha[1] + beta[1]) + alpha[0] * beta[1];
  const V widened = m * (1 + 1e-12);
  for (std::size_t l = 0; l < W; ++l) {
    // Straight (every comparison with NaN is false) and finite, else +inf.
    const bool straight = delta[l] <= kStraight * edge[l] && finite[l] <= std::numeric_limits<double>::max();
    out[l] = straight ? next_up(widened[l]) : kInf;
    if (beta_out != nullptr)
      for (std::size_t c = 0; c < 3; ++c) beta_out[l * 3 + c] = beta[c][l];
  }
}

// One element in two lanes: see lane_vector.hpp on one-lane vectors.
double StraightSidedMargin::margin(const double* nodes, std::array<double, 3>& beta) const noexcept {
  if (kind_ == LinearKind::none) return kInf;
  double m[2] = {kInf, kInf}, b[6] = {};
  lane_margins<2>([nodes](std::size_t i, std::size_t j) { return broadcast_lanes<2>(nodes[i * 3 + j]); }, m, b);
  std::copy_n(b, 3, beta.begin());
  return m[0];
}

// Lane blocks gathered from the mesh a node at a time, as lane_margins asks for them (it
// stops at the first node that shows every lane curved). A tail block repeats its last
// element. Measured and not adopted: AVX-512 hardware gathers (the eight lanes' node ids in
// one, then one per axis) took 62 ns per element of tri_h0.4_o4 against 39 for these loads
// (gathers are slow on this CPU); loading through a stack array gained nothing with
// link-time optimisation (25.5 ns either way).
void StraightSidedMargin::margins(const double* coords, const NodeIndex* conn, std::size_t count, double* out,
                                  double* beta) const noexcept {
  if (kind_ == LinearKind::none) {
    std::fill(out, out + count, kInf);
    return;
  }
  const auto nn = static_cast<std::size_t>(num_nodes_);
  for (std::size_t e = 0; e < count; e += kLanes) {
    const NodeIndex* lane[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l) lane[l] = conn + std::min(e + l, count - 1) * nn;
    double m[kLanes], b[kLanes * 3] = {};
    lane_margins<kLanes>(
        [&](std::size_t i, std::size_t j) {
          Lanes<kLanes> v;
          for (std::size_t l = 0; l < kLanes; ++l) v[l] = coords[3 * static_cast<std::size_t>(lane[l][i]) + j];
          return v;
        },
        m, beta != nullptr ? b : nullptr);
    std::copy_n(m, std::min(kLanes, count - e), out + e);
    if (beta != nullptr) std::copy_n(b, 3 * std::min(kLanes, count - e), beta + 3 * e);
  }
}

const StraightSidedMargin& straight_sided_margin(const ElementType& type) {
  thread_local std::vector<std::pair<const ElementType*, std::unique_ptr<const StraightSidedMargin>>> cache;
  for (const auto& [key, margin] : cache)
    if (key == &type) return *margin;
  cache.emplace_back(&type, std::make_unique<const StraightSidedMargin>(type, jacobian_space(type), true));
  return *cache.back().second;
}

bool in_a_z_plane(std::span<const double> nodes) noexcept {
  for (std::size_t i = 2; i < nodes.size(); i += 3)
    if (nodes[i] != nodes[2]) return false;
  return true;
}

}  // namespace quadval
