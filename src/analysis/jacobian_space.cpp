// Gradients of the Lagrange shape functions at the Jacobian space's sampling points, in
// exact rational arithmetic first, then rounded (Paper III §4.4: "the Jacobian
// determinant is sampled on N_s points, equal to the dimension of its space").
//
// Complete types use the tensor structure: each factor (line, triangle, tetrahedron) has
// the closed-form equispaced Lagrange basis (Silvester's product formula), and a node's
// function is the product of its factors' functions. Incomplete (serendipity) types solve
// the Vandermonde system of their monomial space (src/mesh/polynomial_space) exactly.
#include "analysis/jacobian_space.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "analysis/exact_inverse.hpp"
#include "analysis/factor_shapes.hpp"
#include "analysis/type_cache.hpp"
#include "bezier/rational_rounding.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using MultiIndex = std::array<int, 4>;
constexpr double kUnit = std::numeric_limits<double>::epsilon() / 2;

// n / d in lowest terms (gmpxx does not reduce a num/den pair, and GMP needs it reduced).
mpq_class frac(long n, long d) {
  mpq_class q(n, d);
  q.canonicalize();
  return q;
}

// Silvester's P_m(l) = prod_{k<m} (p l - k) / (k + 1) at l = a / D, in integers:
// P_m = prod_{k<m} (p a - k D) / (D^m m!) and, since d/dl (p l - j) / (j + 1) = p / (j + 1),
// P_m' = p sum_j prod_{k<m, k!=j} (p a - k D) / (D^(m-1) m!). Returned: the numerators.
struct SilvesterNumerators {
  mpz_class value, deriv;
};
SilvesterNumerators silvester_numerators(int p, int m, long a, long den) {
  SilvesterNumerators r{1, 0};
  for (int k = 0; k < m; ++k) {
    const long f = p * a - k * den;
    r.deriv = r.deriv * f + r.value;  // product rule over the factors so far
    r.value *= f;
  }
  r.deriv *= p;
  return r;
}

// Value and local derivatives of the equispaced order-p simplex Lagrange function alpha
// at the barycentric point num / den (d + 1 entries): one exact rational per result, over
// the common denominators D^p prod alpha_a! (value) and D^(p-1) prod alpha_a! (derivatives).
void simplex_lagrange(int d, int p, const MultiIndex& alpha, const std::array<int, 4>& num, int den,
                      mpq_class& value, std::array<mpq_class, 3>& deriv) {
  std::array<SilvesterNumerators, 4> f;
  mpz_class denominator = 1;
  for (int a = 0; a <= d; ++a) {
    const auto as = static_cast<std::size_t>(a);
    f[as] = silvester_numerators(p, alpha[as], num[as], den);
    for (int k = 2; k <= alpha[as]; ++k) denominator *= k;
  }
  const auto product_except = [&](int skip) {
    mpz_class r = 1;
    for (int a = 0; a <= d; ++a)
      if (a != skip) r *= f[static_cast<std::size_t>(a)].value;
    return r;
  };
  mpz_class den_power;
  mpz_ui_pow_ui(den_power.get_mpz_t(), static_cast<unsigned long>(den), static_cast<unsigned long>(p - 1));
  const mpz_class deriv_den = den_power * denominator;
  value = mpq_class(product_except(-1), deriv_den * den);
  value.canonicalize();
  const mpz_class without0 = product_except(0);
  for (int c = 1; c <= d; ++c) {
    auto& out = deriv[static_cast<std::size_t>(c - 1)];
    out = mpq_class(f[static_cast<std::size_t>(c)].deriv * product_except(c) - f[0].deriv * without0, deriv_den);
    out.canonicalize();
  }
}

// A Gmsh reference coordinate snapped to the order-p lattice: numerator m of m / p in
// Bézier-domain units (interval directions: x = 2 m / p - 1).
int snap(double x, int p, bool interval) {
  const double t = interval ? (x + 1) * 0.5 * p : x * p;
  const double m = std::round(t);
  QV_ASSERT(std::abs(t - m) < 1e-9, "reference node " << x << " is off the order-" << p << " lattice");
  return static_cast<int>(m);
}

// The exact sample points of the basis in Gmsh reference coordinates.
std::vector<std::array<mpq_class, 3>> exact_sample_points(const BezierBasis& b,
                                                           const std::vector<FactorShape>& shapes) {
  std::vector<std::array<mpq_class, 3>> pts(static_cast<std::size_t>(b.size()));
  for (int k = 0; k < b.size(); ++k) {
    std::array<mpq_class, 3> x{0, 0, 0};
    for (std::size_t f = 0; f < shapes.size(); ++f) {
      const BernsteinSimplex& fac = *b.factors()[f];
      const auto num = fac.point_numerators(b.factor_index(k, static_cast<int>(f)));
      for (int c = 0; c < shapes[f].dim; ++c) {
        const mpq_class t = frac(num[static_cast<std::size_t>(c + 1)], fac.point_denominator());
        x[static_cast<std::size_t>(shapes[f].first + c)] = shapes[f].interval ? 2 * t - 1 : t;
      }
    }
    pts[static_cast<std::size_t>(k)] = x;
  }
  return pts;
}

// Factor-local matrices for the equispaced order-p factor basis at the factor's samples:
// value[k][a] and deriv[c][k][a] (derivative in the factor's Bézier coordinates).
struct FactorMatrices {
  int num_nodes = 0;
  std::vector<MultiIndex> nodes;           // multi-indices, |alpha| = p
  std::map<MultiIndex, int> index;
  std::vector<mpq_class> value;            // samples x nodes
  std::vector<mpq_class> deriv[3];
};

FactorMatrices factor_matrices(const BernsteinSimplex& samples, int p) {
  FactorMatrices m;
  const int d = samples.dim();
  // enumerate |alpha| = p
  const BernsteinSimplex& lattice = bernstein_simplex(d, p);
  for (const MultiIndex& a : lattice.multi_indices()) {
    m.index[a] = static_cast<int>(m.nodes.size());
    m.nodes.push_back(a);
  }
  m.num_nodes = static_cast<int>(m.nodes.size());
  const auto s = static_cast<std::size_t>(samples.size());
  const auto n = static_cast<std::size_t>(m.num_nodes);
  m.value.resize(s * n);
  for (int c = 0; c < d; ++c) m.deriv[c].resize(s * n);
  for (std::size_t k = 0; k < s; ++k) {
    const auto num = samples.point_numerators(static_cast<int>(k));
    for (std::size_t i = 0; i < n; ++i) {
      mpq_class v;
      std::array<mpq_class, 3> dv;
      simplex_lagrange(d, p, m.nodes[i], num, samples.point_denominator(), v, dv);
      m.value[k * n + i] = v;
      for (int c = 0; c < d; ++c) m.deriv[c][k * n + i] = dv[static_cast<std::size_t>(c)];
    }
  }
  return m;
}

// Per node of the element, its factor-local node index in each factor.
std::vector<std::array<int, 3>> node_factor_indices(const ElementType& type, int p,
                                                    std::span<const RefPoint> ref,
                                                    const std::vector<FactorShape>& shapes,
                                                    const std::vector<FactorMatrices>& fm) {
  std::vector<std::array<int, 3>> out;
  for (const RefPoint& x : ref) {
    std::array<int, 3> idx{0, 0, 0};
    for (std::size_t f = 0; f < shapes.size(); ++f) {
      MultiIndex a{0, 0, 0, 0};
      int sum = 0;
      for (int c = 0; c < shapes[f].dim; ++c) {
        a[static_cast<std::size_t>(c + 1)] = snap(x[static_cast<std::size_t>(shapes[f].first + c)], p, shapes[f].interval);
        sum += a[static_cast<std::size_t>(c + 1)];
      }
      a[0] = p - sum;
      const auto it = fm[f].index.find(a);
      QV_ASSERT(it != fm[f].index.end(), "node outside the lattice of " << type.name);
      idx[f] = it->second;
    }
    out.push_back(idx);
  }
  return out;
}

// Fills gradient matrices (exact) of a complete type or its straight-sided element.
void tensor_gradients(const BezierBasis& b, const std::vector<FactorShape>& shapes,
                      const std::vector<FactorMatrices>& fm,
                      const std::vector<std::array<int, 3>>& node_idx,
                      std::vector<mpq_class> (&out)[3]) {
  const auto s = static_cast<std::size_t>(b.size());
  const std::size_t n = node_idx.size();
  int c_global = 0;
  for (std::size_t f = 0; f < shapes.size(); ++f) {
    for (int c = 0; c < shapes[f].dim; ++c, ++c_global) {
      auto& g = out[c_global];
      g.assign(s * n, mpq_class(0));
      for (std::size_t k = 0; k < s; ++k) {
        for (std::size_t i = 0; i < n; ++i) {
          mpq_class v = 1;
          for (std::size_t h = 0; h < shapes.size(); ++h) {
            const auto kh = static_cast<std::size_t>(b.factor_index(static_cast<int>(k), static_cast<int>(h)));
            const auto ih = static_cast<std::size_t>(node_idx[i][h]);
            const auto nh = static_cast<std::size_t>(fm[h].num_nodes);
            v *= (h == f) ? fm[h].deriv[c][kh * nh + ih] : fm[h].value[kh * nh + ih];
          }
          if (shapes[f].interval) v /= 2;  // d/dx = (1/2) d/dt
          g[k * n + i] = v;
        }
      }
    }
  }
}

// Exact gradients of an incomplete type from its monomial space (Gmsh coordinates).
void vandermonde_gradients(const ElementType& type, const BezierBasis& b,
                           const std::vector<FactorShape>& shapes,
                           std::vector<mpq_class> (&out)[3]) {
  const detail::PolynomialSpace space = detail::polynomial_space(type, detail::FactorBasis::monomial);
  const auto ref = reference_nodes(type);
  const std::size_t n = ref.size();
  QV_ASSERT(space.exponents.size() == n, "space size " << space.exponents.size() << " vs " << n);
  const int p = type.order;
  const int dim = type.dim;
  // exact node coordinates
  std::vector<std::array<mpq_class, 3>> nodes(n);
  for (std::size_t i = 0; i < n; ++i)
    for (const FactorShape& fs : shapes)
      for (int c = 0; c < fs.dim; ++c) {
        const int axis = fs.first + c;
        const mpq_class t = frac(snap(ref[i][static_cast<std::size_t>(axis)], p, fs.interval), p);
        nodes[i][static_cast<std::size_t>(axis)] = fs.interval ? 2 * t - 1 : t;
      }
  const auto power = [](const mpq_class& x, int e) {
    mpq_class r = 1;
    for (int k = 0; k < e; ++k) r *= x;
    return r;
  };
  // V[i][j] = phi_j(node i); C = V^{-1}.
  std::vector<mpq_class> v(n * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      mpq_class x = 1;
      for (int c = 0; c < dim; ++c) x *= power(nodes[i][static_cast<std::size_t>(c)], space.exponents[j][static_cast<std::size_t>(c)]);
      v[i * n + j] = x;
    }
  const std::vector<mpq_class> inv = exact_inverse(std::move(v), n, type);
  // C = V^{-1}: N_i = sum_j phi_j C[j][i].
  const auto pts = exact_sample_points(b, shapes);
  const std::size_t s = pts.size();
  for (int c = 0; c < dim; ++c) out[c].assign(s * n, mpq_class(0));
  std::vector<mpq_class> dphi(n);
  for (std::size_t k = 0; k < s; ++k) {
    for (int c = 0; c < dim; ++c) {
      for (std::size_t j = 0; j < n; ++j) {
        const auto& e = space.exponents[j];
        if (e[static_cast<std::size_t>(c)] == 0) {
          dphi[j] = 0;
          continue;
        }
        mpq_class x = e[static_cast<std::size_t>(c)];
        for (int a = 0; a < dim; ++a)
          x *= power(pts[k][static_cast<std::size_t>(a)], a == c ? e[static_cast<std::size_t>(a)] - 1 : e[static_cast<std::size_t>(a)]);
        dphi[j] = x;
      }
      for (std::size_t i = 0; i < n; ++i) {
        mpq_class g = 0;
        for (std::size_t j = 0; j < n; ++j)
          if (sgn(dphi[j]) != 0) g += dphi[j] * inv[j * n + i];
        out[c][k * n + i] = g;
      }
    }
  }
}

}  // namespace

bool jacobian_supported(const ElementType& type) noexcept {
  return type.has_lagrange_basis && type.order >= 1 &&
         type.order <= max_supported_order(type.family);
}

int sampled_max_order(ElementFamily family) noexcept {
  switch (family) {
    case ElementFamily::line: return 10;
    case ElementFamily::triangle:
    case ElementFamily::quadrangle: return 6;
    case ElementFamily::tetrahedron: return 4;
    case ElementFamily::prism:
    case ElementFamily::hexahedron: return 3;
    case ElementFamily::pyramid: return max_supported_order(family);
    default: return 0;
  }
}

JacobianSpace::JacobianSpace(const ElementType& type)
    : type_(&type), basis_(&bezier_basis(type.family, type.order)) {
  QV_ASSERT(jacobian_supported(type), "no Jacobian space for " << type.name);
  if (type.family == ElementFamily::pyramid) { init_pyramid(); return; }
  num_nodes_ = type.num_nodes;
  num_samples_ = basis_->size();
  dim_ = type.dim;
  num_vertices_ = family_num_vertices(type.family);
  product_ = std::make_unique<const JacobianProduct>(type, *basis_);
  sampled_ = type.order <= sampled_max_order(type.family);
}

void JacobianSpace::build_gradients() const {
  QV_ASSERT(sampled_, "no sample gradients for " << type_->name);
  std::call_once(gradients_once_, [this] {
    const ElementType& type = *type_;
    const auto shapes = factor_shapes(type.family);
    const auto s = static_cast<std::size_t>(num_samples_);
    const auto n = static_cast<std::size_t>(num_nodes_);

    double row_sum = 0;
    if (type.complete) {
      // Double entries are products of rounded factor entries: relative error <= 2.5u
      // (at most three factors rounded to nearest, two products, an exact halving).
      std::vector<FactorMatrices> fm;
      for (std::size_t f = 0; f < shapes.size(); ++f) fm.push_back(factor_matrices(*basis_->factors()[f], type.order));
      const auto idx = node_factor_indices(type, type.order, reference_nodes(type), shapes, fm);
      int c_global = 0;
      for (std::size_t f = 0; f < shapes.size(); ++f) {
        for (int c = 0; c < shapes[f].dim; ++c, ++c_global) {
          auto& g = grad_[c_global];
          g.assign(s * n, 0.0);
          // rounded factor tables
          std::vector<std::vector<double>> val(shapes.size()), der(shapes.size());
          for (std::size_t h = 0; h < shapes.size(); ++h) {
            for (const auto& q : fm[h].value) val[h].push_back(nearest_double(q));
            for (const auto& q : fm[h].deriv[h == f ? c : 0]) der[h].push_back(nearest_double(q));
          }
          for (std::size_t k = 0; k < s; ++k)
            for (std::size_t i = 0; i < n; ++i) {
              double v = shapes[f].interval ? 0.5 : 1.0;
              for (std::size_t h = 0; h < shapes.size(); ++h) {
                const auto kh = static_cast<std::size_t>(basis_->factor_index(static_cast<int>(k), static_cast<int>(h)));
                const auto ih = static_cast<std::size_t>(idx[i][h]);
                const auto nh = static_cast<std::size_t>(fm[h].num_nodes);
                v *= (h == f) ? der[h][kh * nh + ih] : val[h][kh * nh + ih];
              }
              g[k * n + i] = v;
            }
        }
      }
      gradient_rel_error_ = 5 * kUnit;  // 2.5u, doubled as a margin (nearest_double is within u)
    } else {
      build_exact();
      for (int c = 0; c < dim_; ++c) {
        grad_[c].resize(s * n);
        for (std::size_t i = 0; i < s * n; ++i) grad_[c][i] = nearest_double(exact_[c][i]);
      }
      gradient_rel_error_ = 2 * kUnit;
    }
    for (int c = 0; c < dim_; ++c)
      for (std::size_t k = 0; k < s; ++k) {
        double r = 0;
        for (std::size_t i = 0; i < n; ++i) r += std::abs(grad_[c][k * n + i]);
        row_sum = std::max(row_sum, r);
      }
    // Covers the exact entries (|exact| <= |rounded| (1 + 2 eps)) and the sum's rounding.
    gradient_row_sum_ = row_sum * (1 + 4 * gradient_rel_error_ + rounding_gamma(static_cast<int>(n)));
  });
}

const std::vector<double>& JacobianSpace::gradient(int c) const {
  build_gradients();
  return grad_[c];
}

double JacobianSpace::gradient_row_sum() const {
  build_gradients();
  return gradient_row_sum_;
}

double JacobianSpace::gradient_rel_error() const {
  build_gradients();
  return gradient_rel_error_;
}

void JacobianSpace::build_straight() const {
  std::call_once(straight_once_, [this] {
    // Pyramids, and orders beyond sampled_max_order, have no sample gradients.
    if (type_->family == ElementFamily::pyramid || !has_sample_gradients()) return;
    // The order-1 factor bases through the vertices.
    const auto shapes = factor_shapes(type_->family);
    const auto s = static_cast<std::size_t>(num_samples_);
    std::vector<FactorMatrices> fm;
    for (std::size_t f = 0; f < shapes.size(); ++f) fm.push_back(factor_matrices(*basis_->factors()[f], 1));
    const ElementType* linear = find_element_type(type_->family, 1, true);
    const auto idx = node_factor_indices(*linear, 1, reference_nodes(*linear), shapes, fm);
    std::vector<mpq_class> g[3];
    tensor_gradients(*basis_, shapes, fm, idx, g);
    for (int c = 0; c < dim_; ++c) {
      straight_[c].resize(g[c].size());
      for (std::size_t i = 0; i < g[c].size(); ++i) straight_[c][i] = nearest_double(g[c][i]);
    }
    straight_rel_error_ = 2 * kUnit;
    const auto nv = static_cast<std::size_t>(num_vertices_);
    double r = 0;
    for (int c = 0; c < dim_; ++c)
      for (std::size_t k = 0; k < s; ++k) {
        double row = 0;
        for (std::size_t v = 0; v < nv; ++v) row += std::abs(straight_[c][k * nv + v]);
        r = std::max(r, row);
      }
    straight_row_sum_ = r * (1 + 4 * straight_rel_error_ + rounding_gamma(num_vertices_));
  });
}

const std::vector<double>& JacobianSpace::straight_gradient(int c) const {
  build_straight();
  return straight_[c];
}

double JacobianSpace::straight_row_sum() const {
  build_straight();
  return straight_row_sum_;
}

double JacobianSpace::straight_rel_error() const {
  build_straight();
  return straight_rel_error_;
}

void JacobianSpace::build_exact() const {
  std::call_once(exact_once_, [this] {
    const auto shapes = factor_shapes(type_->family);
    if (type_->complete) {
      std::vector<FactorMatrices> fm;
      for (std::size_t f = 0; f < shapes.size(); ++f)
        fm.push_back(factor_matrices(*basis_->factors()[f], type_->order));
      const auto idx = node_factor_indices(*type_, type_->order, reference_nodes(*type_), shapes, fm);
      tensor_gradients(*basis_, shapes, fm, idx, exact_);
    } else {
      vandermonde_gradients(*type_, *basis_, shapes, exact_);
    }
  });
}

const std::vector<mpq_class>& JacobianSpace::exact_gradient(int c) const {
  QV_ASSERT(has_sample_gradients(), "no sample gradients for " << type_->name);
  build_exact();
  return exact_[c];
}

const JacobianSpace& jacobian_space(const ElementType& type) {
  static PerTypeCache<JacobianSpace> cache;
  return cache.get(type, [&] { return std::make_unique<const JacobianSpace>(type); });
}

}  // namespace quadval
