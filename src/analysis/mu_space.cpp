// Per-type data of the measure mu: exact maps nodes -> control values of the derivatives
// of the geometry (Lagrange-to-Bézier of the geometry, the Bernstein derivative rule and
// degree elevation, all exact rationals rounded once), the ideal elements, and the product
// tables. Thesis, Paper V §2 (W = J_p J_i^-1) and §4-5 (q, s, t, p, J).
#include "analysis/mu_space.hpp"

#include <gmpxx.h>

#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "analysis/exact_inverse.hpp"
#include "analysis/factor_shapes.hpp"
#include "analysis/product_tables.hpp"
#include "analysis/pyramid_space.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/type_cache.hpp"
#include "bezier/bezier_exact.hpp"
#include "bezier/rational_rounding.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using MultiIndex = std::array<int, 4>;
using Matrix = std::vector<mpq_class>;  // row-major

bool simplicial(ElementFamily f) {
  return f == ElementFamily::triangle || f == ElementFamily::tetrahedron;
}

// Numerator m of a Gmsh coordinate on the order-p lattice (m / p in Bézier units).
int snap(double x, int p, bool interval) {
  const double t = interval ? (x + 1) * 0.5 * p : x * p;
  const double m = std::round(t);
  QV_ASSERT(std::abs(t - m) < 1e-9, "reference node " << x << " off the order-" << p << " lattice");
  return static_cast<int>(m);
}

// out = (M applied along factor f) in, tensor sizes updated in place.
Matrix apply_factor(const Matrix& in, std::array<int, 3>& sizes, int f, const Matrix& m,
                    int rows) {
  const int cols = sizes[static_cast<std::size_t>(f)];
  std::array<int, 3> out_sizes = sizes;
  out_sizes[static_cast<std::size_t>(f)] = rows;
  Matrix out(static_cast<std::size_t>(out_sizes[0] * out_sizes[1] * out_sizes[2]), mpq_class(0));
  for (int i2 = 0; i2 < out_sizes[2]; ++i2)
    for (int i1 = 0; i1 < out_sizes[1]; ++i1)
      for (int i0 = 0; i0 < out_sizes[0]; ++i0) {
        std::array<int, 3> o{i0, i1, i2};
        const int r = o[static_cast<std::size_t>(f)];
        mpq_class sum = 0;
        for (int c = 0; c < cols; ++c) {
          const mpq_class& w = m[static_cast<std::size_t>(r * cols + c)];
          if (sgn(w) == 0) continue;
          std::array<int, 3> s = o;
          s[static_cast<std::size_t>(f)] = c;
          sum += w * in[static_cast<std::size_t>(s[0] + sizes[0] * (s[1] + sizes[1] * s[2]))];
        }
        out[static_cast<std::size_t>(i0 + out_sizes[0] * (i1 + out_sizes[1] * i2))] = sum;
      }
  sizes = out_sizes;
  return out;
}

Matrix multiply(const Matrix& a, const Matrix& b, int n, int k, int m) {  // (n x k)(k x m)
  Matrix c(static_cast<std::size_t>(n * m), mpq_class(0));
  for (int i = 0; i < n; ++i)
    for (int l = 0; l < k; ++l) {
      const mpq_class& x = a[static_cast<std::size_t>(i * k + l)];
      if (sgn(x) == 0) continue;
      for (int j = 0; j < m; ++j) c[static_cast<std::size_t>(i * m + j)] += x * b[static_cast<std::size_t>(l * m + j)];
    }
  return c;
}

int index_of(const std::vector<MultiIndex>& list, const MultiIndex& a) {
  for (std::size_t i = 0; i < list.size(); ++i)
    if (list[i] == a) return static_cast<int>(i);
  QV_ASSERT(false, "multi-index not found");
  return -1;
}

// Bernstein derivative d/dlambda_{c+1} - d/dlambda_0 (degree p -> p - 1), times `scale`.
Matrix derivative_matrix(int d, int p, int c, const mpq_class& scale) {
  const auto rows = simplex_multi_indices(d, p - 1);
  const auto cols = simplex_multi_indices(d, p);
  Matrix m(rows.size() * cols.size(), mpq_class(0));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    MultiIndex plus = rows[r], minus = rows[r];
    ++plus[static_cast<std::size_t>(c + 1)];
    ++minus[0];
    m[r * cols.size() + static_cast<std::size_t>(index_of(cols, plus))] += p * scale;
    m[r * cols.size() + static_cast<std::size_t>(index_of(cols, minus))] -= p * scale;
  }
  return m;
}

// Degree elevation m -> m + 1: b'_alpha = sum_a alpha_a / (m + 1) b_{alpha - e_a}.
Matrix elevation_matrix(int d, int m) {
  const auto rows = simplex_multi_indices(d, m + 1);
  const auto cols = simplex_multi_indices(d, m);
  Matrix out(rows.size() * cols.size(), mpq_class(0));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (int a = 0; a <= d; ++a) {
      if (rows[r][static_cast<std::size_t>(a)] == 0) continue;
      MultiIndex lower = rows[r];
      --lower[static_cast<std::size_t>(a)];
      mpq_class w(rows[r][static_cast<std::size_t>(a)], m + 1);
      w.canonicalize();
      out[r * cols.size() + static_cast<std::size_t>(index_of(cols, lower))] += w;
    }
  return out;
}

std::array<double, 9> ideal_inverse_of(ElementFamily f) {
  const double r3 = 1 / sqrt_rn(3.0), r6 = 1 / sqrt_rn(6.0);
  switch (f) {
    case ElementFamily::triangle: return {1, -r3, 0, 0, 2 / sqrt_rn(3.0), 0, 0, 0, 0};
    case ElementFamily::tetrahedron:
      return {1, -r3, -r6, 0, 2 / sqrt_rn(3.0), -r6, 0, 0, sqrt_rn(1.5)};
    case ElementFamily::prism: return {1, -r3, 0, 0, 2 / sqrt_rn(3.0), 0, 0, 0, 2};
    case ElementFamily::quadrangle: return {1, 0, 0, 0, 1, 0, 0, 0, 0};
    case ElementFamily::hexahedron: return {1, 0, 0, 0, 1, 0, 0, 0, 1};
    // Gmsh's pyramid (base [-1,1]^2, apex (0,0,1)) to the ideal one (unit square base,
    // apex height 1/sqrt 2) is affine, J_i = diag(1/2, 1/2, 1/sqrt 2); scaled by 1/2.
    case ElementFamily::pyramid: return {1, 0, 0, 0, 1, 0, 0, 0, 1 / sqrt_rn(2.0)};
    default: return {};
  }
}

}  // namespace

int mu_max_order(ElementFamily family) noexcept {
  switch (family) {
    case ElementFamily::line: return 10;
    case ElementFamily::triangle: return 10;
    case ElementFamily::quadrangle: return 10;
    case ElementFamily::tetrahedron:
    case ElementFamily::prism:
    case ElementFamily::hexahedron: return 4;
    case ElementFamily::pyramid: return 9;
    default: return 0;
  }
}

int mu_certificate_max_order(ElementFamily family) noexcept {
  switch (family) {
    case ElementFamily::triangle: return 10;
    case ElementFamily::quadrangle: return 10;
    case ElementFamily::tetrahedron: return 3;  // 12 n = 24: 2925 coefficients
    case ElementFamily::prism:
    case ElementFamily::hexahedron:
    case ElementFamily::pyramid: return 2;      // 12 n = 24 per factor: 15625 (hexahedron)
    default: return 0;
  }
}

void MuSpace::init_w_space(const std::vector<int>& factor_dims, int n) {
  certificate_ = type_->order <= mu_certificate_max_order(type_->family);
  // Without the certificate only W (n) and the control matrices of M (2n) are formed.
  const std::vector<int> multiples =
      certificate_ ? std::vector<int>{1, 2, 4, 6, 8, 12} : std::vector<int>{1, 2};
  std::vector<const BernsteinSimplex*> w_factors;
  for (int d : factor_dims) {
    for (int m : multiples) degrees_[m].push_back({d, m * n});
    w_factors.push_back(&bernstein_simplex(d, n));
  }
  for (int m : multiples) sizes_[m] = bernstein_space_size(degrees_[m]);
  w_basis_ = std::make_unique<BezierBasis>(type_->family, type_->order, w_factors);
  prod11_ = &bernstein_product(degrees_[1], degrees_[1]);
  bisection_[0] = &bernstein_bisection(degrees_[1]);
  bisection_[1] = &bernstein_bisection(degrees_[2]);
  ideal_inv_ = ideal_inverse_of(type_->family);
}

void MuSpace::build_certificate_products() const {
  std::call_once(certificate_once_, [this] {
    std::vector<std::pair<int, int>> pairs{{2, 2}};
    if (dim_ == 3) pairs.insert(pairs.end(), {{4, 2}, {2, 4}, {4, 4}, {8, 4}, {6, 6}});
    for (const auto& [a, b] : pairs)
      certificate_prod_.push_back({{a, b}, &bernstein_product(degrees_[a], degrees_[b])});
  });
}

PyramidColumnMaps pyramid_column_maps(const ElementType& type) {
  QV_ASSERT(type.family == ElementFamily::pyramid && type.has_lagrange_basis && type.order >= 1,
            type.name << " is no Lagrange pyramid");
  const int r = type.order;
  const auto n = static_cast<std::size_t>(type.num_nodes);
  const PyramidShapeCoefficients sc = pyramid_shape_coefficients(type);
  const auto ws = static_cast<std::size_t>((r + 1) * (r + 1) * (r + 1));
  PyramidColumnMaps out;
  for (int c = 0; c < 3; ++c) {
    // Per axis: Bernstein coefficients from pyramid_scaled_derivative's scaled ones
    // (divide by C(deg, i)), then degree elevation deg -> r. Separable, exact.
    const std::array<int, 3> deg = pyramid_derivative_degrees(r, c);
    std::array<Matrix, 3> axis;
    for (std::size_t h = 0; h < 3; ++h) {
      const int a = deg[h];
      Matrix m(static_cast<std::size_t>((a + 1) * (a + 1)), mpq_class(0));
      for (int i = 0; i <= a; ++i) {
        mpz_class b;
        mpz_bin_uiui(b.get_mpz_t(), static_cast<unsigned long>(a), static_cast<unsigned long>(i));
        m[static_cast<std::size_t>(i * (a + 1) + i)] = mpq_class(mpz_class(1), b);
      }
      for (int e = a; e < r; ++e) m = multiply(elevation_matrix(1, e), m, e + 2, e + 1, a + 1);
      axis[h] = std::move(m);
    }
    auto& map = out.map[static_cast<std::size_t>(c)];
    map.assign(ws * n, 0.0);
    std::vector<double> row_abs(ws, 0.0);
    std::vector<mpq_class> column(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) column[j] = sc.coefficients[j * n + i];
      Matrix col = pyramid_scaled_derivative(r, c, sc.exponents, column);
      std::array<int, 3> sizes{deg[0] + 1, deg[1] + 1, deg[2] + 1};
      for (int h = 0; h < 3; ++h) col = apply_factor(col, sizes, h, axis[static_cast<std::size_t>(h)], r + 1);
      QV_ASSERT(col.size() == ws, "pyramid derivative map size " << col.size() << " vs " << ws);
      for (std::size_t k = 0; k < ws; ++k) {
        const double v = nearest_double(col[k]);
        map[k * n + i] = v;
        row_abs[k] += std::abs(v);
      }
    }
    double row_sum_max = 0;
    for (double s : row_abs) row_sum_max = std::max(row_sum_max, s);
    // |exact| <= |rounded| (1 + u), and the sum's own rounding.
    out.row_sum[static_cast<std::size_t>(c)] = row_sum_max * (1 + 1e-12 + rounding_gamma(static_cast<int>(n) + 2));
  }
  return out;
}

void MuSpace::init_pyramid_derivatives() {
  PyramidColumnMaps maps = pyramid_column_maps(*type_);
  QV_ASSERT(maps.map[0].size() == static_cast<std::size_t>(w_basis_->size() * num_nodes_), "pyramid W space");
  for (std::size_t c = 0; c < 3; ++c) {
    deriv_[c] = std::move(maps.map[c]);
    row_sum_[c] = maps.row_sum[c];
  }
}

MuSpace::MuSpace(const ElementType& type, TableSource source) : type_(&type) {
  QV_ASSERT(type.has_lagrange_basis && type.order >= 1 && type.order <= mu_max_order(type.family),
            "no mu space for " << type.name);
  dim_ = type.dim;
  num_nodes_ = type.num_nodes;
  if (type.family == ElementFamily::pyramid) {
    // W's columns are polynomials in the cube coordinates (u, v, t) (pyramid_space.hpp):
    // one tensor space of degree r per axis, subdivided like a hexahedron's.
    init_w_space({1, 1, 1}, type.order);
  } else {
    const auto shapes = factor_shapes(type.family);
    QV_ASSERT(!shapes.empty(), "no mu space for " << type.name);
    std::vector<int> dims;
    for (const FactorShape& s : shapes) dims.push_back(s.dim);
    init_w_space(dims, simplicial(type.family) ? type.order - 1 : type.order);
  }
  const MuTableView* generated = source == TableSource::generated_or_exact ? generated_mu_tables(type.gmsh_id) : nullptr;
  if (generated != nullptr) {
    const auto size = static_cast<std::size_t>(w_basis_->size()) * static_cast<std::size_t>(num_nodes_);
    for (std::size_t c = 0; c < static_cast<std::size_t>(dim_); ++c) {
      QV_ASSERT(generated->derivative[c].size() == size, "generated mu tables of " << type.name << ": size");
      deriv_[c].assign(generated->derivative[c].begin(), generated->derivative[c].end());
      row_sum_[c] = generated->row_sum[c];
    }
  } else if (type.family == ElementFamily::pyramid) {
    init_pyramid_derivatives();
  } else {
    init_derivatives();
  }
  for (std::size_t c = 0; c < static_cast<std::size_t>(dim_); ++c)
    sparse_[c] = SparseRows::of(deriv_[c], static_cast<std::size_t>(w_basis_->size()), static_cast<std::size_t>(num_nodes_));
}

MuTables MuSpace::tables() const {
  MuTables t;
  for (std::size_t c = 0; c < 3; ++c) {
    t.derivative[c] = deriv_[c];
    t.row_sum[c] = row_sum_[c];
  }
  return t;
}

void MuSpace::init_derivatives() {
  const ElementType& type = *type_;
  const auto shapes = factor_shapes(type.family);
  const int p = type.order;
  const auto nf = static_cast<int>(shapes.size());
  const bool simplex = simplicial(type.family);

  // Lattice of the geometry (degree p per factor) and its points' keys.
  std::vector<std::vector<MultiIndex>> geo(static_cast<std::size_t>(nf));
  std::array<int, 3> geo_sizes{1, 1, 1};
  for (int f = 0; f < nf; ++f) {
    geo[static_cast<std::size_t>(f)] = simplex_multi_indices(shapes[static_cast<std::size_t>(f)].dim, p);
    geo_sizes[static_cast<std::size_t>(f)] = static_cast<int>(geo[static_cast<std::size_t>(f)].size());
  }
  const int num_lattice = geo_sizes[0] * geo_sizes[1] * geo_sizes[2];
  std::vector<std::array<int, 3>> lattice_key(static_cast<std::size_t>(num_lattice), {0, 0, 0});
  for (int l = 0; l < num_lattice; ++l) {
    const std::array<int, 3> idx{l % geo_sizes[0], (l / geo_sizes[0]) % geo_sizes[1],
                                 l / (geo_sizes[0] * geo_sizes[1])};
    for (int f = 0; f < nf; ++f) {
      const FactorShape& s = shapes[static_cast<std::size_t>(f)];
      const MultiIndex& a = geo[static_cast<std::size_t>(f)][static_cast<std::size_t>(idx[static_cast<std::size_t>(f)])];
      for (int c = 0; c < s.dim; ++c) lattice_key[static_cast<std::size_t>(l)][static_cast<std::size_t>(s.first + c)] = a[static_cast<std::size_t>(c + 1)];
    }
  }
  // Node keys.
  const auto ref = reference_nodes(type);
  const auto n = static_cast<std::size_t>(num_nodes_);
  std::vector<std::array<int, 3>> node_key(n, {0, 0, 0});
  for (std::size_t i = 0; i < n; ++i)
    for (const FactorShape& s : shapes)
      for (int c = 0; c < s.dim; ++c)
        node_key[i][static_cast<std::size_t>(s.first + c)] = snap(ref[i][static_cast<std::size_t>(s.first + c)], p, s.interval);

  // E: lattice x nodes, the geometry's values at the lattice from the nodes' values.
  Matrix e(static_cast<std::size_t>(num_lattice) * n, mpq_class(0));
  if (type.complete) {
    std::map<std::array<int, 3>, std::size_t> node_of;
    for (std::size_t i = 0; i < n; ++i) node_of[node_key[i]] = i;
    for (int l = 0; l < num_lattice; ++l) {
      const auto it = node_of.find(lattice_key[static_cast<std::size_t>(l)]);
      QV_ASSERT(it != node_of.end(), "lattice point without a node in " << type.name);
      e[static_cast<std::size_t>(l) * n + it->second] = 1;
    }
  } else {
    // The incomplete space lies in the complete one: its interpolant's values at the
    // lattice, N_i(lattice point), by the exact inverse of the monomial Vandermonde matrix.
    const auto space = detail::polynomial_space(type, detail::FactorBasis::monomial);
    QV_ASSERT(space.exponents.size() == n, "space size of " << type.name);
    const auto coord = [&](const std::array<int, 3>& key, int c) {
      for (const FactorShape& s : shapes)
        if (c >= s.first && c < s.first + s.dim) {
          mpq_class t(key[static_cast<std::size_t>(c)], p);
          t.canonicalize();
          return s.interval ? mpq_class(2 * t - 1) : t;
        }
      return mpq_class(0);
    };
    const auto phi = [&](const std::array<int, 3>& key, std::size_t j) {
      mpq_class v = 1;
      for (int c = 0; c < dim_; ++c) {
        const mpq_class x = coord(key, c);
        for (int k = 0; k < space.exponents[j][static_cast<std::size_t>(c)]; ++k) v *= x;
      }
      return v;
    };
    std::vector<mpq_class> v(n * n);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) v[i * n + j] = phi(node_key[i], j);
    const std::vector<mpq_class> inv = exact_inverse(std::move(v), n, type);
    for (int l = 0; l < num_lattice; ++l)
      for (std::size_t j = 0; j < n; ++j) {
        const mpq_class ph = phi(lattice_key[static_cast<std::size_t>(l)], j);
        if (sgn(ph) == 0) continue;
        for (std::size_t i = 0; i < n; ++i) e[static_cast<std::size_t>(l) * n + i] += ph * inv[j * n + i];
      }
  }

  // Per direction: the factor maps (T, then derivative and elevation on its own factor).
  const auto ws = static_cast<std::size_t>(w_basis_->size());
  for (int c = 0; c < dim_; ++c) {
    std::vector<Matrix> maps(static_cast<std::size_t>(nf));
    std::vector<int> rows(static_cast<std::size_t>(nf));
    for (int f = 0; f < nf; ++f) {
      const FactorShape& s = shapes[static_cast<std::size_t>(f)];
      const BernsteinSimplex& g = bernstein_simplex(s.dim, p);
      const Matrix& t = g.exact().to_bezier;
      const int gs = g.size();
      if (c >= s.first && c < s.first + s.dim) {
        const mpq_class scale = s.interval ? mpq_class(1, 2) : mpq_class(1);
        Matrix d = derivative_matrix(s.dim, p, c - s.first, scale);
        const int dr = static_cast<int>(simplex_multi_indices(s.dim, p - 1).size());
        Matrix dt = multiply(d, t, dr, gs, gs);
        if (!simplex) {
          const Matrix el = elevation_matrix(s.dim, p - 1);
          dt = multiply(el, dt, gs, dr, gs);
          rows[static_cast<std::size_t>(f)] = gs;
        } else {
          rows[static_cast<std::size_t>(f)] = dr;
        }
        maps[static_cast<std::size_t>(f)] = std::move(dt);
      } else {
        maps[static_cast<std::size_t>(f)] = t;
        rows[static_cast<std::size_t>(f)] = gs;
      }
    }
    deriv_[c].assign(ws * n, 0.0);
    std::vector<mpq_class> exact_col;
    double row_sum_max = 0;
    std::vector<double> row_abs(ws, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      Matrix col(static_cast<std::size_t>(num_lattice));
      for (int l = 0; l < num_lattice; ++l) col[static_cast<std::size_t>(l)] = e[static_cast<std::size_t>(l) * n + i];
      std::array<int, 3> sizes = geo_sizes;
      for (int f = 0; f < nf; ++f) col = apply_factor(col, sizes, f, maps[static_cast<std::size_t>(f)], rows[static_cast<std::size_t>(f)]);
      QV_ASSERT(col.size() == ws, "derivative map size " << col.size() << " vs " << ws);
      for (std::size_t k = 0; k < ws; ++k) {
        const double v = nearest_double(col[k]);
        deriv_[c][k * n + i] = v;
        row_abs[k] += std::abs(v);
      }
    }
    for (double r : row_abs) row_sum_max = std::max(row_sum_max, r);
    // |exact| <= |rounded| (1 + 2u), and the sum's own rounding.
    row_sum_[c] = row_sum_max * (1 + 1e-12 + rounding_gamma(static_cast<int>(n) + 2));
  }
}

const BernsteinProduct& MuSpace::prod(int a, int b) const {
  if (a == 1 && b == 1) return *prod11_;
  QV_ASSERT(certificate_, "no certificate, so no product table (" << a << ", " << b << ")");
  build_certificate_products();
  for (const auto& [key, table] : certificate_prod_)
    if (key.first == a && key.second == b) return *table;
  QV_ASSERT(false, "no product table (" << a << ", " << b << ")");
  return *prod11_;
}

const MuSpace& mu_space(const ElementType& type) {
  static PerTypeCache<MuSpace> cache;
  return cache.get(type, [&] { return std::make_unique<const MuSpace>(type); });
}

}  // namespace quadval
