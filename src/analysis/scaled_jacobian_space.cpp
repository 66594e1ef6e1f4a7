// Per-type data of the scaled-Jacobian bounds: the exact node-to-column-coefficient maps
// (rounded once), the squared Bézier space, frames and normalisation.
#include "analysis/scaled_jacobian_space.hpp"

#include <gmpxx.h>

#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "analysis/mu_space.hpp"
#include "analysis/outward_rounding.hpp"
#include "bezier/bezier_exact.hpp"
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

std::vector<const BernsteinSimplex*> squared_factors(const ElementType& type) {
  std::vector<const BernsteinSimplex*> out;
  for (const FactorDegree& fd : j_degrees_of(type))
    out.push_back(&bernstein_simplex(fd.dim, 2 * fd.degree));
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
  switch (family) {
    case ElementFamily::line:
    case ElementFamily::triangle:
    case ElementFamily::quadrangle: return 6;
    case ElementFamily::tetrahedron:
    case ElementFamily::prism:
    case ElementFamily::hexahedron: return 3;
    case ElementFamily::pyramid: return 2;
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

using Matrix = std::vector<mpq_class>;  // row-major

// B^n_alpha (|alpha| = n, factor `from`) at the Lagrange points of `to`, exactly:
// to.size() x from.size().
Matrix bernstein_values(const BernsteinSimplex& from, const BernsteinSimplex& to) {
  const int d = from.dim(), n = from.degree();
  const auto rows = static_cast<std::size_t>(to.size()), cols = static_cast<std::size_t>(from.size());
  Matrix m(rows * cols);
  mpz_class fact_n = 1;
  for (int i = 2; i <= n; ++i) fact_n *= i;
  for (std::size_t r = 0; r < rows; ++r) {
    const auto num = to.point_numerators(static_cast<int>(r));
    for (std::size_t c = 0; c < cols; ++c) {
      const auto& alpha = from.multi_indices()[c];
      mpq_class v(fact_n);
      for (int a = 0; a <= d; ++a) {
        const auto ua = static_cast<std::size_t>(a);
        mpz_class fa = 1;
        for (int i = 2; i <= alpha[ua]; ++i) fa *= i;
        v /= fa;
        const mpq_class lambda = mpq_class(num[ua]) / mpq_class(to.point_denominator());
        for (int e = 0; e < alpha[ua]; ++e) v *= lambda;
      }
      v.canonicalize();
      m[r * cols + c] = v;
    }
  }
  return m;
}

Matrix multiply(const Matrix& a, const Matrix& b, std::size_t rows, std::size_t inner, std::size_t cols) {
  Matrix c(rows * cols, mpq_class(0));
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t k = 0; k < inner; ++k) {
      const mpq_class& x = a[r * inner + k];
      if (sgn(x) == 0) continue;
      for (std::size_t j = 0; j < cols; ++j)
        if (sgn(b[k * cols + j]) != 0) c[r * cols + j] += x * b[k * cols + j];
    }
  return c;
}

}  // namespace

ScaledJacobianSpace::ScaledJacobianSpace(const ElementType& type)
    : type_(&type),
      j_degrees_(j_degrees_of(type)),
      squared_(type.family, type.order, squared_factors(type)),
      frames_(family_frames(type.family)) {
  QV_ASSERT(scaled_jacobian_supported(type), "no scaled Jacobian for " << type.name);
  for (const FactorDegree& fd : j_degrees_) squared_degrees_.push_back({fd.dim, 2 * fd.degree});
  if (type.family == ElementFamily::pyramid) {
    init_pyramid();
    return;
  }
  const JacobianSpace& js = jacobian_space(type);
  const auto nn = static_cast<std::size_t>(type.num_nodes);
  const std::size_t nf = j_degrees_.size();
  for (int c = 0; c < type.dim; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    // Native degrees, and per factor the exact map from the Jacobian space's samples to
    // the column's Bézier coefficients: A_f = T_native * (Bernstein_n at the native
    // points) * T_n (eq. 18 both ends).
    std::vector<Matrix> a(nf);
    std::vector<std::size_t> s_in(nf), s_out(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      const int m = type.order - (factor_of_direction(type.family, c) == static_cast<int>(f) ? 1 : 0);
      col_degrees_[uc].push_back({j_degrees_[f].dim, m});
      const BernsteinSimplex& jf = bernstein_simplex(j_degrees_[f].dim, j_degrees_[f].degree);
      const BernsteinSimplex& nat = bernstein_simplex(j_degrees_[f].dim, m);
      s_in[f] = static_cast<std::size_t>(jf.size());
      s_out[f] = static_cast<std::size_t>(nat.size());
      const Matrix e = bernstein_values(jf, nat);
      const Matrix et = multiply(e, jf.exact().to_bezier, s_out[f], s_in[f], s_in[f]);
      a[f] = multiply(nat.exact().to_bezier, et, s_out[f], s_out[f], s_in[f]);
    }
    // Apply A_0 x A_1 x A_2 to every node's gradient column, factor by factor.
    const std::vector<mpq_class>& g = js.exact_gradient(c);
    std::size_t out_size = 1;
    for (std::size_t f = 0; f < nf; ++f) out_size *= s_out[f];
    col_size_[uc] = static_cast<int>(out_size);
    std::vector<mpq_class> exact(out_size * nn);
    for (std::size_t i = 0; i < nn; ++i) {
      std::size_t in_size = 1;
      for (std::size_t f = 0; f < nf; ++f) in_size *= s_in[f];
      std::vector<mpq_class> t(in_size);
      for (std::size_t k = 0; k < in_size; ++k) t[k] = g[k * nn + i];
      std::size_t inner = 1;
      for (std::size_t f = 0; f < nf; ++f) {
        std::size_t outer = 1;
        for (std::size_t h = f + 1; h < nf; ++h) outer *= s_in[h];
        std::vector<mpq_class> u(inner * s_out[f] * outer, mpq_class(0));
        for (std::size_t b = 0; b < outer; ++b)
          for (std::size_t r = 0; r < s_out[f]; ++r)
            for (std::size_t m = 0; m < s_in[f]; ++m) {
              const mpq_class& w = a[f][r * s_in[f] + m];
              if (sgn(w) == 0) continue;
              for (std::size_t x = 0; x < inner; ++x) {
                const mpq_class& v = t[x + inner * (m + s_in[f] * b)];
                if (sgn(v) != 0) u[x + inner * (r + s_out[f] * b)] += w * v;
              }
            }
        t = std::move(u);
        inner *= s_out[f];
      }
      for (std::size_t r = 0; r < out_size; ++r) exact[r * nn + i] = t[r];
    }
    col_map_[uc].resize(out_size * nn);
    double worst = 0;
    for (std::size_t r = 0; r < out_size; ++r) {
      double sum = 0;
      for (std::size_t i = 0; i < nn; ++i) {
        const double d = exact[r * nn + i].get_d();  // truncation: within 2u relative
        col_map_[uc][r * nn + i] = d;
        sum += std::abs(d);
      }
      worst = std::max(worst, sum);
    }
    // |exact| <= |rounded| (1 + 2u); the double sum of nn terms within gamma_nn.
    col_row_sum_[uc] = next_up(worst * (1 + 4 * kUnit) * (1 + rounding_gamma(static_cast<int>(nn))));
  }

  double s = 1;
  if (type.family == ElementFamily::triangle || type.family == ElementFamily::prism) s = 2 / std::sqrt(3.0);
  if (type.family == ElementFamily::tetrahedron) s = std::sqrt(2.0);
  // Two roundings (sqrt, division): two ulps each way enclose the exact value.
  s_lo_ = s == 1 ? 1 : next_down(next_down(s));
  s_hi_ = s == 1 ? 1 : next_up(next_up(s));
}

void ScaledJacobianSpace::init_pyramid() {
  // Columns in the cube coordinates (pyramid_space.hpp), degree r per axis; entries within
  // u of the exact rationals (the map's rows sum to zero, as for the other families).
  PyramidColumnMaps maps = pyramid_column_maps(*type_);
  const int r = type_->order;
  for (std::size_t c = 0; c < 3; ++c) {
    col_degrees_[c] = std::vector<FactorDegree>(3, {1, r});
    col_size_[c] = (r + 1) * (r + 1) * (r + 1);
    col_map_[c] = std::move(maps.map[c]);
    col_row_sum_[c] = next_up(maps.row_sum[c]);
  }
  // At the ideal pyramid each corner frame has |V| / prod |v_j| = 1 / sqrt 2.
  s_lo_ = next_down(next_down(std::sqrt(2.0)));
  s_hi_ = next_up(next_up(std::sqrt(2.0)));
}

const ScaledJacobianSpace& scaled_jacobian_space(const ElementType& type) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<const ScaledJacobianSpace>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[type.gmsh_id];
  if (!slot) slot = std::make_unique<const ScaledJacobianSpace>(type);
  return *slot;
}

}  // namespace quadval
