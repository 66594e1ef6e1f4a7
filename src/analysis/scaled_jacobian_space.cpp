// Per-type data of the scaled-Jacobian bounds: the node-to-column-coefficient maps (the
// Jacobian product path's, rounded once from exact rationals), the squared Bézier space,
// frames and normalisation.
#include "analysis/scaled_jacobian_space.hpp"

#include <cmath>
#include <memory>

#include "analysis/jacobian_product.hpp"
#include "analysis/mu_space.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/product_tables.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/type_cache.hpp"
#include "bezier/bernstein_product.hpp"
#include "quadval/error.hpp"
#include "quadval/scaled_jacobian.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;

// The degrees of J as the products below form it: the Jacobian space's, except pyramids,
// whose columns are all taken in the cube space of degree r per axis
// (pyramid_column_maps), so J = c_1 . (c_2 x c_3) has degree 3r per axis.
std::vector<FactorDegree> j_degrees_of(const ElementType& type) {
  if (type.family == ElementFamily::pyramid) return std::vector<FactorDegree>(3, {1, 3 * type.order});
  return jacobian_factor_degrees(type.family, type.order);
}

std::vector<FactorDegree> squared_factors(const ElementType& type) {
  std::vector<FactorDegree> out;
  for (const FactorDegree& fd : j_degrees_of(type)) out.push_back({fd.dim, 2 * fd.degree});
  return out;
}

int det3(const Frame& m) {
  // m[j][c]: column j, component c (the frame as a matrix with columns j).
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[1][0] * (m[0][1] * m[2][2] - m[0][2] * m[2][1]) +
         m[2][0] * (m[0][1] * m[1][2] - m[0][2] * m[1][1]);
}

// Corner frames of the reference simplex of dimension d (vertices 0, e_1, .., e_d): the
// edges leaving corner k towards the other corners in increasing order, the first two
// swapped when that makes det E_k = 1 (it is +-1: the simplex is unimodular).
std::vector<Frame> simplex_corner_frames(int d) {
  std::vector<std::array<int, 3>> vertex(static_cast<std::size_t>(d + 1), {0, 0, 0});
  for (int i = 1; i <= d; ++i) vertex[static_cast<std::size_t>(i)][static_cast<std::size_t>(i - 1)] = 1;
  std::vector<Frame> frames;
  for (int k = 0; k <= d; ++k) {
    Frame f{};
    int j = 0;
    for (int m = 0; m <= d; ++m) {
      if (m == k) continue;
      for (int c = 0; c < 3; ++c)
        f[static_cast<std::size_t>(j)][static_cast<std::size_t>(c)] =
            vertex[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)] - vertex[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
      ++j;
    }
    Frame full = f;
    if (d == 2) full[2] = {0, 0, 1};  // det of the 2 x 2 block
    if (det3(full) < 0) std::swap(f[0], f[1]);
    QV_ASSERT(std::abs(det3(d == 2 ? Frame{f[0], f[1], {0, 0, 1}} : f)) == 1, "frame " << k);
    frames.push_back(f);
  }
  return frames;
}

// Base-corner frames of Gmsh's reference pyramid: at base vertex k, the half base edges
// to the next and the previous base vertex and the edge to the apex (entries in
// {-1, 0, 1}, det +-1), the first two swapped when that makes det E_k = 1.
std::vector<Frame> pyramid_corner_frames() {
  const int base[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  std::vector<Frame> frames;
  for (int k = 0; k < 4; ++k) {
    const int* v = base[k];
    const int* next = base[(k + 1) % 4];
    const int* prev = base[(k + 3) % 4];
    Frame f{};
    f[0] = {(next[0] - v[0]) / 2, (next[1] - v[1]) / 2, 0};
    f[1] = {(prev[0] - v[0]) / 2, (prev[1] - v[1]) / 2, 0};
    f[2] = {-v[0], -v[1], 1};
    if (det3(f) < 0) std::swap(f[0], f[1]);
    QV_ASSERT(det3(f) == 1, "pyramid frame " << k);
    frames.push_back(f);
  }
  return frames;
}

std::vector<Frame> family_frames(ElementFamily f) {
  const Frame identity{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  switch (f) {
    case ElementFamily::triangle: return simplex_corner_frames(2);
    case ElementFamily::tetrahedron: return simplex_corner_frames(3);
    case ElementFamily::prism: {
      std::vector<Frame> frames = simplex_corner_frames(2);
      for (Frame& fr : frames) fr[2] = {0, 0, 1};  // times the axis
      return frames;
    }
    case ElementFamily::pyramid: return pyramid_corner_frames();
    default: return {identity};
  }
}

}  // namespace

int scaled_jacobian_max_order(ElementFamily family) noexcept {
  // The Jacobian bounds' orders (max_supported_order) except pyramids, whose squared
  // space has (6r + 1)^3 coefficients per vector: 15625 at r = 4, 166375 at r = 9.
  switch (family) {
    case ElementFamily::line: return 10;
    case ElementFamily::triangle: return 10;
    case ElementFamily::quadrangle: return 10;
    case ElementFamily::tetrahedron:
    case ElementFamily::prism:
    case ElementFamily::hexahedron: return 4;
    case ElementFamily::pyramid: return 4;
    default: return 0;
  }
}

bool scaled_jacobian_supported(const ElementType& type) noexcept {
  return jacobian_supported(type) &&
         type.order <= scaled_jacobian_max_order(type.family);
}

namespace {

// Which reference-domain factor holds Gmsh direction c (jacobian_factor_degrees order).
int factor_of_direction(ElementFamily f, int c) {
  switch (f) {
    case ElementFamily::quadrangle:
    case ElementFamily::hexahedron: return c;
    case ElementFamily::prism: return c == 2 ? 1 : 0;
    default: return 0;  // line, triangle, tetrahedron: one factor
  }
}

}  // namespace

ScaledJacobianSpace::ScaledJacobianSpace(const ElementType& type)
    : type_(&type),
      j_degrees_(j_degrees_of(type)),
      squared_(squared_factors(type)),
      frames_(family_frames(type.family)) {
  QV_ASSERT(scaled_jacobian_supported(type), "no scaled Jacobian for " << type.name);
  for (const FactorDegree& fd : j_degrees_) squared_degrees_.push_back({fd.dim, 2 * fd.degree});
  if (type.family == ElementFamily::pyramid) {
    init_pyramid();
    return;
  }
  // The columns' control points are the Jacobian product path's derivative maps
  // (jacobian_product.hpp: scaled rows G^_k = mult(k) G_k, rounded to nearest from the
  // exact rationals, and 1 / mult(k) rounded to nearest), already in the columns' native
  // spaces and in Gmsh's coordinates; no exact inverse of a J-space collocation matrix is
  // needed (it is cubic in the J factor's size: 220 for a tetrahedron of order 4).
  const JacobianProduct* jp = jacobian_space(type).product();
  QV_ASSERT(jp != nullptr, "no product path for " << type.name);
  const ProductTables tables = jp->tables();
  const ProductTables::MapTables& curved = tables.maps[static_cast<std::size_t>(SampleMap::curved)];
  const auto nn = static_cast<std::size_t>(type.num_nodes);
  QV_ASSERT(curved.num_nodes == type.num_nodes, "product map of " << type.name << " reads " << curved.num_nodes << " nodes");
  for (int c = 0; c < type.dim; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    for (std::size_t f = 0; f < j_degrees_.size(); ++f) {
      const int m = type.order - (factor_of_direction(type.family, c) == static_cast<int>(f) ? 1 : 0);
      col_degrees_[uc].push_back({j_degrees_[f].dim, m});
    }
    const std::vector<double>& g = curved.matrix[uc];
    const std::vector<double>& inv = tables.deriv_inv_mult[uc];
    const std::size_t rows = inv.size();
    QV_ASSERT(rows == static_cast<std::size_t>(bernstein_space_size(col_degrees_[uc])) && g.size() == rows * nn,
              "column space of " << type.name);
    col_size_[uc] = static_cast<int>(rows);
    // Entry G^_ki * fl(1 / mult(k)), rounded: within 3u (1 + 3u) of the exact G_ki.
    col_map_[uc].resize(rows * nn);
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t i = 0; i < nn; ++i) col_map_[uc][r * nn + i] = g[r * nn + i] * inv[r];
    col_sparse_[uc] = SparseRows::of(col_map_[uc], rows, nn);
    // Covers sum_i |exact G_ki| (the product path's own bound).
    col_row_sum_[uc] = curved.row_sum[uc];
  }

  double s = 1;
  if (type.family == ElementFamily::triangle || type.family == ElementFamily::prism) s = 2 / sqrt_rn(3.0);
  if (type.family == ElementFamily::tetrahedron) s = sqrt_rn(2.0);
  // Two roundings (sqrt, division): two ulps each way enclose the exact value.
  s_lo_ = s == 1 ? 1 : next_down(next_down(s));
  s_hi_ = s == 1 ? 1 : next_up(next_up(s));
}

void ScaledJacobianSpace::init_pyramid() {
  // Columns in the cube coordinates (pyramid_space.hpp), degree r per axis; entries within
  // u of the exact rationals (the map's rows sum to zero, as for the other families). They
  // are mu's derivative maps, generated at build time for the smaller pyramids
  // (product_tables.hpp): in GMP they took 1.4 ms of a first check of 14-node pyramids.
  PyramidColumnMaps maps;
  if (const MuTableView* generated = generated_mu_tables(type_->gmsh_id)) {
    for (std::size_t c = 0; c < 3; ++c) {
      maps.map[c].assign(generated->derivative[c].begin(), generated->derivative[c].end());
      maps.row_sum[c] = generated->row_sum[c];
    }
  } else {
    maps = pyramid_column_maps(*type_);
  }
  const int r = type_->order;
  for (std::size_t c = 0; c < 3; ++c) {
    col_degrees_[c] = std::vector<FactorDegree>(3, {1, r});
    col_size_[c] = (r + 1) * (r + 1) * (r + 1);
    QV_ASSERT(maps.map[c].size() == static_cast<std::size_t>(col_size_[c] * type_->num_nodes),
              "pyramid column map of " << type_->name);
    col_map_[c] = std::move(maps.map[c]);
    col_sparse_[c] = SparseRows::of(col_map_[c], static_cast<std::size_t>(col_size_[c]), static_cast<std::size_t>(type_->num_nodes));
    col_row_sum_[c] = next_up(maps.row_sum[c]);
  }
  // At the ideal pyramid each corner frame has |V| / prod |v_j| = 1 / sqrt 2.
  s_lo_ = next_down(next_down(sqrt_rn(2.0)));
  s_hi_ = next_up(next_up(sqrt_rn(2.0)));
}

const ScaledJacobianSpace& scaled_jacobian_space(const ElementType& type) {
  static PerTypeCache<ScaledJacobianSpace> cache;
  return cache.get(type, [&] { return std::make_unique<const ScaledJacobianSpace>(type); });
}

}  // namespace quadval
