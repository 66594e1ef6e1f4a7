// The Jacobian space of pyramids by Bernstein products (Paper IV eqs. 2-3 and 6, with the
// products of Paper V Prop. 4): exact derivative maps from the nodes to the control points
// of X_xi, X_eta, X_zeta in cube coordinates, then JacobianProduct's convolutions.
//
// In cube coordinates (u, v, t) (bezier/pyramid_basis.hpp; X = 2u - 1, Y = 2v - 1), the
// functions of Bergot's space are phi = X^a Y^b t^k (a, b <= k <= r), and their
// derivatives in Gmsh's coordinates (xi = X t, eta = Y t, zeta = 1 - t) are polynomials:
//   dphi/dxi   = a X^(a-1) Y^b t^(k-1)          degrees (r-1, r,   r-1) in (u, v, t)
//   dphi/deta  = b X^a Y^(b-1) t^(k-1)          degrees (r,   r-1, r-1)
//   dphi/dzeta = (a + b - k) X^a Y^b t^(k-1)    degrees (r,   r,   r-1)
// so J = X_xi . (X_eta x X_zeta) has degrees (3r-1, 3r-1, 3r-3): the enriched basis (eq. 6).
// Their face t = 0 holds the limits of the derivatives along rays into the apex, never a
// value at the apex itself. Nothing here goes through the equispaced Lagrange-to-Bézier
// matrix of the J space (factor degree up to 26), whose norm grows like 2^n.
//
// The monomial coefficients of the shape functions are exact rationals (inverse of the
// generalized Vandermonde matrix). For complete types the matrix is written in the basis
//   X^a Y^b tau_m(t),  a, b <= m,  tau_m(t) = t^m prod_{l = m+1..r} (t - l / r),
// which spans the same space and is block triangular over the node layers t = l / r
// (tau_m vanishes on the layers above m): Gauss-Jordan stays sparse, ~10x faster at r = 9.
#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>

#include "analysis/pyramid_space.hpp"

#include "analysis/exact_inverse.hpp"
#include "analysis/jacobian_product.hpp"
#include "analysis/jacobian_space.hpp"
#include "analysis/product_tables.hpp"
#include "bezier/rational_rounding.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using Exponents = std::array<int, 3>;

mpq_class power(const mpq_class& x, int e) {
  mpq_class r = 1;
  for (int i = 0; i < e; ++i) r *= x;
  return r;
}

mpz_class binomial(int n, int k) {
  if (k < 0 || k > n) return 0;
  mpz_class r;
  mpz_bin_uiui(r.get_mpz_t(), static_cast<unsigned long>(n), static_cast<unsigned long>(k));
  return r;
}

// x snapped to the lattice m / p (Gmsh's pyramid nodes are multiples of 1/p).
mpq_class snap(double x, int p, const ElementType& type) {
  const double m = std::round(x * p);
  QV_ASSERT(std::abs(x * p - m) < 1e-9, "node coordinate " << x << " of " << type.name << " off the 1/" << p << " lattice");
  mpq_class q(static_cast<long>(m), p);
  q.canonicalize();
  return q;
}

// tau_m(t) = t^m prod_{l = m+1..r} (t - l / r), as coefficients of t^0..t^r.
std::vector<mpq_class> tau(int m, int r) {
  std::vector<mpq_class> c(static_cast<std::size_t>(r + 1), mpq_class(0));
  c[static_cast<std::size_t>(m)] = 1;
  for (int l = m + 1; l <= r; ++l) {
    mpq_class root(l, r);
    root.canonicalize();
    for (int k = r; k >= 0; --k) {  // c <- c * (t - root)
      const auto ks = static_cast<std::size_t>(k);
      c[ks] = (k > 0 ? c[ks - 1] : mpq_class(0)) - root * c[ks];
    }
  }
  return c;
}

}  // namespace

PyramidShapeCoefficients pyramid_shape_coefficients(const ElementType& type) {
  QV_ASSERT(type.family == ElementFamily::pyramid && type.has_lagrange_basis, type.name << " is no Lagrange pyramid");
  PyramidShapeCoefficients out;
  out.exponents = detail::polynomial_space(type, detail::FactorBasis::monomial).exponents;
  const auto& ex = out.exponents;
  const auto ref = reference_nodes(type);
  const std::size_t n = ref.size();
  QV_ASSERT(ex.size() == n, "pyramid space " << ex.size() << " vs " << n << " nodes");
  const int p = type.order;
  // Node coordinates (X, Y, t); X, Y unused at the apex (t = 0).
  std::vector<std::array<mpq_class, 3>> node(n);
  for (std::size_t i = 0; i < n; ++i) {
    const mpq_class t = 1 - snap(ref[i][2], p, type);
    node[i][2] = t;
    if (sgn(t) != 0) node[i][0] = snap(ref[i][0], p, type) / t, node[i][1] = snap(ref[i][1], p, type) / t;
  }
  // Rows: nodes from the base layer up; columns: basis functions by decreasing m (k).
  std::vector<std::size_t> rows(n), cols(n);
  std::iota(rows.begin(), rows.end(), 0);
  std::iota(cols.begin(), cols.end(), 0);
  std::stable_sort(rows.begin(), rows.end(), [&](std::size_t a, std::size_t b) { return node[a][2] > node[b][2]; });
  std::stable_sort(cols.begin(), cols.end(), [&](std::size_t a, std::size_t b) { return ex[a][2] > ex[b][2]; });
  std::vector<std::vector<mpq_class>> taus;
  if (type.complete)
    for (int m = 0; m <= p; ++m) taus.push_back(tau(m, p));
  // phi_j(node i): X^a Y^b times t^k (monomials) or tau_k(t) (complete types).
  const auto basis_value = [&](std::size_t i, std::size_t j) {
    const mpq_class& t = node[i][2];
    mpq_class tpart = 0;
    if (type.complete) {
      const auto& c = taus[static_cast<std::size_t>(ex[j][2])];
      for (std::size_t k = c.size(); k-- > 0;) tpart = tpart * t + c[k];
    } else {
      tpart = power(t, ex[j][2]);
    }
    if (sgn(t) == 0) return ex[j][0] == 0 && ex[j][1] == 0 ? tpart : mpq_class(0);  // |X^a Y^b| t^k -> 0
    return mpq_class(power(node[i][0], ex[j][0]) * power(node[i][1], ex[j][1]) * tpart);
  };
  std::vector<mpq_class> v(n * n);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t c = 0; c < n; ++c) v[r * n + c] = basis_value(rows[r], cols[c]);
  const std::vector<mpq_class> inv = exact_inverse(std::move(v), n, type);  // (col c, row r)
  // coef[j * n + i]: N_i = sum_j phi_j coef[j][i], back in the original orders.
  std::vector<mpq_class> coef(n * n);
  for (std::size_t c = 0; c < n; ++c)
    for (std::size_t r = 0; r < n; ++r) coef[cols[c] * n + rows[r]] = inv[c * n + r];
  if (!type.complete) {
    out.coefficients = std::move(coef);
    return out;
  }
  // X^a Y^b tau_m(t) = sum_k tau_m[k] X^a Y^b t^k, with k >= m >= max(a, b): in the space.
  std::map<Exponents, std::size_t> index;
  for (std::size_t j = 0; j < n; ++j) index[ex[j]] = j;
  out.coefficients.assign(n * n, mpq_class(0));
  for (std::size_t j = 0; j < n; ++j) {
    const auto& c = taus[static_cast<std::size_t>(ex[j][2])];
    for (int k = ex[j][2]; k <= p; ++k) {
      const mpq_class& w = c[static_cast<std::size_t>(k)];
      if (sgn(w) == 0) continue;
      const std::size_t jk = index.at({ex[j][0], ex[j][1], k});
      for (std::size_t i = 0; i < n; ++i)
        if (sgn(coef[j * n + i]) != 0) out.coefficients[jk * n + i] += w * coef[j * n + i];
    }
  }
  return out;
}

std::array<int, 3> pyramid_derivative_degrees(int r, int c) noexcept {
  switch (c) {
    case 0: return {r - 1, r, r - 1};
    case 1: return {r, r - 1, r - 1};
    default: return {r, r, r - 1};
  }
}

std::vector<mpq_class> pyramid_scaled_derivative(int r, int c, const std::vector<Exponents>& exponents,
                                                 const std::vector<mpq_class>& monomial) {
  const std::array<int, 3> deg = pyramid_derivative_degrees(r, c);
  std::array<std::size_t, 3> size{};
  for (std::size_t h = 0; h < 3; ++h) size[h] = static_cast<std::size_t>(deg[h] + 1);
  // Integer numerators over the common denominator of the inputs.
  mpz_class den = 1;
  for (const mpq_class& q : monomial) mpz_lcm(den.get_mpz_t(), den.get_mpz_t(), q.get_den_mpz_t());
  // The derivative in the monomial basis X^e0 Y^e1 t^e2 (degrees deg).
  std::vector<mpz_class> in(size[0] * size[1] * size[2], mpz_class(0));
  for (std::size_t j = 0; j < exponents.size(); ++j) {
    if (sgn(monomial[j]) == 0) continue;
    const int a = exponents[j][0], b = exponents[j][1], k = exponents[j][2];
    if (k == 0) continue;  // constant
    int factor = 0, ea = a, eb = b;
    if (c == 0) factor = a, ea = a - 1;
    if (c == 1) factor = b, eb = b - 1;
    if (c == 2) factor = a + b - k;
    if (factor == 0) continue;
    QV_ASSERT(ea <= deg[0] && eb <= deg[1] && k - 1 <= deg[2], "pyramid exponent beyond order " << r);
    const mpz_class num = monomial[j].get_num() * (den / monomial[j].get_den());
    in[static_cast<std::size_t>(ea) + size[0] * (static_cast<std::size_t>(eb) + size[1] * static_cast<std::size_t>(k - 1))] += factor * num;
  }
  // Axis by axis: monomial -> scaled Bernstein (C(n, i) times the Bernstein coefficient),
  // integer matrices: t^l -> C(n-l, i-l); X^e = (2u-1)^e -> sum_l C(e,l) 2^l (-1)^(e-l) C(n-l, i-l).
  for (std::size_t h = 0; h < 3; ++h) {
    const int n = deg[h];
    const auto s = size[h];
    std::vector<mpz_class> m(s * s, mpz_class(0));  // m[i * s + e]
    for (int i = 0; i <= n; ++i)
      for (int e = 0; e <= n; ++e) {
        mpz_class sum = 0;
        if (h == 2) {
          sum = binomial(n - e, i - e);
        } else {
          for (int l = 0; l <= e; ++l) {
            const mpz_class term = binomial(e, l) * (mpz_class(1) << l) * binomial(n - l, i - l);
            if ((e - l) % 2 == 0) sum += term; else sum -= term;
          }
        }
        m[static_cast<std::size_t>(i) * s + static_cast<std::size_t>(e)] = sum;
      }
    std::size_t inner = 1, outer = 1;
    for (std::size_t g = 0; g < h; ++g) inner *= size[g];
    for (std::size_t g = h + 1; g < 3; ++g) outer *= size[g];
    std::vector<mpz_class> out(in.size(), mpz_class(0));
    for (std::size_t o = 0; o < outer; ++o)
      for (std::size_t e = 0; e < s; ++e)
        for (std::size_t q = 0; q < inner; ++q) {
          const mpz_class& x = in[(o * s + e) * inner + q];
          if (sgn(x) == 0) continue;
          for (std::size_t i = 0; i < s; ++i)
            if (sgn(m[i * s + e]) != 0) out[(o * s + i) * inner + q] += m[i * s + e] * x;
        }
    in.swap(out);
  }
  std::vector<mpq_class> result(in.size());
  for (std::size_t q = 0; q < in.size(); ++q) {
    result[q] = mpq_class(in[q], den);
    result[q].canonicalize();
  }
  return result;
}

namespace {

// mult(k) of a pyramid space: the product of the binomials of k's per-axis indices.
mpz_class pyramid_mult(const std::array<int, 3>& degree, int k) {
  mpz_class w = 1;
  for (std::size_t h = 0; h < 3; ++h) {
    w *= binomial(degree[h], k % (degree[h] + 1));
    k /= degree[h] + 1;
  }
  return w;
}

}  // namespace

void JacobianProduct::init_pyramid(TableSource source) {
  const int r = order_;
  const ElementType& type = *type_;
  num_factors_ = r == 1 ? 2 : 3;  // r = 1: J does not depend on t (Paper IV §4.1)
  for (std::size_t h = 0; h < 3; ++h) {
    factor_dim_[h] = 1;
    factor_first_[h] = static_cast<int>(h);
    factor_interval_[h] = true;
  }
  const auto space_of = [&](std::array<int, 3> degree) {
    Space s;
    s.degree = degree;
    s.total = 1;
    for (std::size_t h = 0; h < 3; ++h) {
      s.size[h] = degree[h] + 1;
      s.total *= s.size[h];
    }
    return s;
  };
  std::array<int, 3> jdeg{0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    deriv_space_[cs] = space_of(pyramid_derivative_degrees(r, c));
    for (std::size_t h = 0; h < 3; ++h) jdeg[h] += deriv_space_[cs].degree[h];
  }
  const Space jspace = space_of(jdeg);
  QV_ASSERT(jspace.total == basis_->size() && static_cast<int>(basis_->factors().size()) == num_factors_,
            "J space of " << type.name << " differs from its basis");
  for (int h = 0; h < num_factors_; ++h)
    QV_ASSERT(basis_->factors()[static_cast<std::size_t>(h)]->degree() == jdeg[static_cast<std::size_t>(h)], "pyramid basis degree");
  std::array<int, 3> bc{0, 0, 0};
  for (std::size_t h = 0; h < 3; ++h) bc[h] = deriv_space_[1].degree[h] + deriv_space_[2].degree[h];
  const Space bcs = space_of(bc);
  cross_size_ = bcs.total;
  maps_[static_cast<std::size_t>(SampleMap::curved)].num_nodes = type.num_nodes;
  maps_[static_cast<std::size_t>(SampleMap::straight)].num_nodes = 5;

  // The rounded tables: generated at build time (product_tables.hpp; the exact data is then
  // built only when exact_coefficients first asks for it), else rounded here.
  const ProductTableView* generated =
      source == TableSource::generated_or_exact ? generated_product_tables(type.gmsh_id) : nullptr;
  if (generated != nullptr) {
    load_tables(*generated);
    if (cross_gather_.first.empty()) build_products(bcs, jspace);  // not generated (large)
  } else {
    build_products(bcs, jspace);
    build_exact();
    build_pyramid_rounded_tables();
  }
}

void JacobianProduct::build_pyramid_exact_data() const {
  // mult(gamma) of the J space (degrees: the basis's factors; 1 for a missing third).
  std::array<int, 3> jdeg{0, 0, 0};
  for (int h = 0; h < num_factors_; ++h)
    jdeg[static_cast<std::size_t>(h)] = basis_->factors()[static_cast<std::size_t>(h)]->degree();
  mult_.resize(static_cast<std::size_t>(basis_->size()));
  for (int k = 0; k < basis_->size(); ++k) mult_[static_cast<std::size_t>(k)] = pyramid_mult(jdeg, k);
  // Curved map: the type's own shape functions; straight: the 5-node pyramid's.
  for (SampleMap which : {SampleMap::curved, SampleMap::straight}) {
    const ElementType& shape = which == SampleMap::curved ? *type_ : *find_element_type(ElementFamily::pyramid, 1, true);
    maps_[static_cast<std::size_t>(which)].pyramid =
        std::make_shared<const PyramidShapeCoefficients>(pyramid_shape_coefficients(shape));
  }
}

void JacobianProduct::build_pyramid_rounded_tables() {
  for (int c = 0; c < 3; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    auto& inv = deriv_inv_mult_[cs];
    inv.resize(static_cast<std::size_t>(deriv_space_[cs].total));
    for (int k = 0; k < deriv_space_[cs].total; ++k)
      inv[static_cast<std::size_t>(k)] = nearest_double(mpq_class(1) / mpq_class(pyramid_mult(deriv_space_[cs].degree, k)));
  }
  inv_mult_.resize(mult_.size());
  for (std::size_t k = 0; k < mult_.size(); ++k) inv_mult_[k] = nearest_double(mpq_class(1) / mpq_class(mult_[k]));
  // The derivative maps of both geometries in the same derivative spaces (the straight
  // map's lower degrees written in the higher-degree Bernstein bases).
  for (Map& map : maps_) {
    const PyramidShapeCoefficients& sc = *map.pyramid;
    const auto n = static_cast<std::size_t>(map.num_nodes);
    for (int c = 0; c < 3; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      const auto rows = static_cast<std::size_t>(deriv_space_[cs].total);
      auto& g = map.matrix[cs];
      g.assign(rows * n, 0.0);
      std::vector<mpq_class> row_abs(rows, mpq_class(0)), column(n);
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) column[j] = sc.coefficients[j * n + i];
        const std::vector<mpq_class> d = pyramid_scaled_derivative(order_, c, sc.exponents, column);
        for (std::size_t k = 0; k < rows; ++k) {
          g[k * n + i] = nearest_double(d[k]);
          row_abs[k] += abs(d[k]);
        }
      }
      mpq_class worst = 0;
      for (std::size_t k = 0; k < rows; ++k)
        worst = std::max(worst, mpq_class(row_abs[k] * mpq_class(deriv_inv_mult_[cs][k]) * (1 + mpq_class(1, 1 << 20))));
      map.row_sum[cs] = round_up(worst);
    }
  }
}

void JacobianSpace::init_pyramid() {
  // Paper IV through Bernstein products only: no sampling matrices (has_sample_gradients()
  // is false), so bounds_from_samples takes the product path from the nodes.
  num_nodes_ = type_->num_nodes;
  num_samples_ = basis_->size();
  dim_ = 3;
  num_vertices_ = 5;
  product_ = std::make_unique<const JacobianProduct>(*type_, *basis_);
}

}  // namespace quadval
