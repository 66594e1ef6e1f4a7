// The Jacobian space of pyramids: exact shape-function gradients at the samples of the
// enriched Bézier basis (Paper IV eq. 6), rounded for the batched double path.
#include "analysis/pyramid_space.hpp"

#include <cmath>
#include <limits>
#include <mutex>

#include "analysis/exact_inverse.hpp"
#include "analysis/jacobian_space.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/error.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

constexpr double kUnit = std::numeric_limits<double>::epsilon() / 2;

mpq_class power(const mpq_class& x, int e) {
  mpq_class r = 1;
  for (int i = 0; i < e; ++i) r *= x;
  return r;
}

// x snapped to the lattice m / p (exact Gmsh node coordinates are multiples of 1/p).
mpq_class snap(double x, int p, const ElementType& type) {
  const double m = std::round(x * p);
  QV_ASSERT(std::abs(x * p - m) < 1e-9, "node coordinate " << x << " of " << type.name << " off the 1/" << p << " lattice");
  mpq_class q(static_cast<long>(m), p);
  q.canonicalize();
  return q;
}

// The double nearest to q (within one ulp: get_d truncates, the correction rounds).
double nearest(const mpq_class& q) {
  const double d = q.get_d();
  return d + mpq_class(q - mpq_class(d)).get_d();
}

// Distinct coordinates m / degree (m = 0..degree) of a line factor; {1} for a missing one.
std::vector<mpq_class> factor_coordinates(const BezierBasis& basis, std::size_t f) {
  if (f >= basis.factors().size()) return {mpq_class(1)};
  const BernsteinSimplex& fac = *basis.factors()[f];
  std::vector<mpq_class> c(static_cast<std::size_t>(fac.size()));
  for (int i = 0; i < fac.size(); ++i) {
    mpq_class q(fac.point_numerators(i)[1], fac.point_denominator());
    q.canonicalize();
    c[static_cast<std::size_t>(i)] = q;
  }
  return c;
}

}  // namespace

void exact_pyramid_gradients(const ElementType& type, const BezierBasis& basis,
                             std::vector<mpq_class> (&out)[3]) {
  QV_ASSERT(type.family == ElementFamily::pyramid && type.has_lagrange_basis, type.name << " is no Lagrange pyramid");
  const detail::PolynomialSpace space = detail::polynomial_space(type, detail::FactorBasis::monomial);
  const auto& ex = space.exponents;  // (a, b, k): X^a Y^b t^k
  const auto ref = reference_nodes(type);
  const std::size_t n = ref.size();
  QV_ASSERT(ex.size() == n, "pyramid space " << ex.size() << " vs " << n << " nodes");
  const int p = type.order;

  // Generalized Vandermonde V(i, j) = phi_j(node i); at the apex only phi = 1 (k = 0) is
  // non-zero (|X^a Y^b t^k| <= t^k).
  std::vector<mpq_class> v(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    const mpq_class t = 1 - snap(ref[i][2], p, type);
    for (std::size_t j = 0; j < n; ++j) {
      if (sgn(t) == 0) {
        v[i * n + j] = ex[j][2] == 0 ? 1 : 0;
        continue;
      }
      const mpq_class x = snap(ref[i][0], p, type) / t, y = snap(ref[i][1], p, type) / t;
      v[i * n + j] = power(x, ex[j][0]) * power(y, ex[j][1]) * power(t, ex[j][2]);
    }
  }
  const std::vector<mpq_class> coef = exact_inverse(std::move(v), n, type);  // N_i = sum_j phi_j C(j, i)

  const auto us = factor_coordinates(basis, 0), vs = factor_coordinates(basis, 1),
             ts = factor_coordinates(basis, 2);
  const std::size_t nu = us.size(), nv = vs.size(), nt = ts.size();
  const auto s = static_cast<std::size_t>(basis.size());
  QV_ASSERT(s == nu * nv * nt, "pyramid basis layout");
  const auto q1 = static_cast<std::size_t>(p + 1);
  // Powers X^e, Y^e of the sample coordinates, e = 0..p.
  std::vector<mpq_class> xp(nu * q1), yp(nv * q1);
  for (std::size_t a = 0; a < nu; ++a)
    for (std::size_t e = 0; e < q1; ++e) xp[a * q1 + e] = power(2 * us[a] - 1, static_cast<int>(e));
  for (std::size_t b = 0; b < nv; ++b)
    for (std::size_t e = 0; e < q1; ++e) yp[b * q1 + e] = power(2 * vs[b] - 1, static_cast<int>(e));
  for (auto& o : out) o.assign(s * n, mpq_class(0));

  // Sum factorisation per node i and t value: A_c(x-exp, y-exp) collects the t part, then
  // B_c(x-exp) the Y part at each v, then the X part at each u.
  std::vector<mpq_class> acc[3], bcc[3];
  for (auto& a : acc) a.resize(q1 * q1);
  for (auto& b : bcc) b.resize(q1);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < nt; ++c) {
      for (auto& a : acc)
        for (auto& z : a) z = 0;
      for (std::size_t j = 0; j < n; ++j) {
        const int a = ex[j][0], b = ex[j][1], k = ex[j][2];
        if (k == 0 || sgn(coef[j * n + i]) == 0) continue;
        const mpq_class w = coef[j * n + i] * power(ts[c], k - 1);
        // d/dxi: a X^(a-1) Y^b; d/deta: b X^a Y^(b-1); d/dzeta: (a+b-k) X^a Y^b.
        if (a > 0) acc[0][static_cast<std::size_t>(a - 1) * q1 + static_cast<std::size_t>(b)] += a * w;
        if (b > 0) acc[1][static_cast<std::size_t>(a) * q1 + static_cast<std::size_t>(b - 1)] += b * w;
        if (a + b != k) acc[2][static_cast<std::size_t>(a) * q1 + static_cast<std::size_t>(b)] += (a + b - k) * w;
      }
      for (std::size_t qv = 0; qv < nv; ++qv) {
        for (int d = 0; d < 3; ++d)
          for (std::size_t ea = 0; ea < q1; ++ea) {
            mpq_class sum = 0;
            for (std::size_t eb = 0; eb < q1; ++eb)
              if (sgn(acc[d][ea * q1 + eb]) != 0) sum += acc[d][ea * q1 + eb] * yp[qv * q1 + eb];
            bcc[d][ea] = sum;
          }
        for (std::size_t pu = 0; pu < nu; ++pu) {
          const std::size_t k = pu + nu * (qv + nv * c);
          for (int d = 0; d < 3; ++d) {
            mpq_class sum = 0;
            for (std::size_t ea = 0; ea < q1; ++ea)
              if (sgn(bcc[d][ea]) != 0) sum += bcc[d][ea] * xp[pu * q1 + ea];
            out[d][k * n + i] = sum;
          }
        }
      }
    }
  }
}

void JacobianSpace::init_pyramid() {
  const ElementType& type = *type_;
  num_nodes_ = type.num_nodes;
  num_samples_ = basis_->size();
  dim_ = 3;
  num_vertices_ = 5;
  const auto s = static_cast<std::size_t>(num_samples_);
  std::call_once(exact_once_, [&] { exact_pyramid_gradients(type, *basis_, exact_); });

  // Rounded matrices and the constants of jacobian_space.hpp: entries within 2u of the
  // exact ones; row sums enlarged to cover the exact entries and their summation.
  const auto round_rows = [&](const std::vector<mpq_class> (&exact)[3], std::vector<double> (&g)[3],
                              std::size_t n, double& row_sum) {
    double r = 0;
    for (int c = 0; c < 3; ++c) {
      g[c].resize(exact[c].size());
      for (std::size_t i = 0; i < exact[c].size(); ++i) g[c][i] = nearest(exact[c][i]);
      for (std::size_t k = 0; k < s; ++k) {
        double row = 0;
        for (std::size_t i = 0; i < n; ++i) row += std::abs(g[c][k * n + i]);
        r = std::max(r, row);
      }
    }
    row_sum = r * (1 + 8 * kUnit + rounding_gamma(static_cast<int>(n)));
  };
  gradient_rel_error_ = 2 * kUnit;
  round_rows(exact_, grad_, static_cast<std::size_t>(num_nodes_), gradient_row_sum_);

  const ElementType* linear = find_element_type(ElementFamily::pyramid, 1, true);
  std::vector<mpq_class> straight_exact[3];
  exact_pyramid_gradients(*linear, *basis_, straight_exact);
  straight_rel_error_ = 2 * kUnit;
  round_rows(straight_exact, straight_, 5, straight_row_sum_);
}

}  // namespace quadval
