#pragma once
// The function space of each Lagrange element type, as a list of exponent tuples, and the
// evaluation of its basis functions phi_j and their gradients at a reference point.
// Internal to quadval (used by lagrange_basis.cpp and its tests).

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval::detail {

inline constexpr int kMaxLagrangeOrder = 10;

/// How exponents become basis functions.
/// monomial: t^n per coordinate. legendre: the Legendre polynomial P_n(t) per coordinate;
/// same span whenever the exponent set is downward closed (is_downward_closed), and far
/// better conditioned in [-1, 1] coordinates. bernstein (complete triangle, tetrahedron,
/// prism only): exponents (i, j[, k]) of a simplex of order p stand for the Bernstein
/// polynomial p!/(i! j! k! l!) x^i y^j z^k (1-x-y-z)^l, l = p - i - j - k (the prism's
/// third exponent is a Legendre factor in w); they span P_p, with a Vandermonde matrix at
/// the equispaced nodes conditioned about 3e3 at p = 10 against 8e7 for Legendre products.
enum class FactorBasis : std::uint8_t { monomial, legendre, bernstein };

/// A function space given by exponent tuples.
/// Polynomial families: phi_j(x) = prod_d q_{e_d}(t_d), t_d = scale[d] * x_d + shift[d].
/// Pyramid: e = (i, j, k) stands for (xi/(1-zeta))^i (eta/(1-zeta))^j (1-zeta)^k with
/// i, j <= k (thesis Paper IV eq. 2); as factors, phi = q_i(xi') q_j(eta') (1-zeta)^mu
/// r_{k-mu}(zeta), mu = max(i, j), r_m = (1-zeta)^m or P_m(2 zeta - 1).
struct PolynomialSpace {
  ElementFamily family = ElementFamily::point;
  int dim = 0;
  int order = 0;
  FactorBasis factors = FactorBasis::monomial;
  std::vector<std::array<int, 3>> exponents;
  std::array<double, 3> scale{1, 1, 1};
  std::array<double, 3> shift{0, 0, 0};
};

/// The exponents of Gmsh's space for `type` (see lagrange_basis.hpp for the list), with
/// Legendre factors when the set allows them, monomials otherwise.
/// @pre type.has_lagrange_basis, type.order <= kMaxLagrangeOrder
PolynomialSpace polynomial_space(const ElementType& type);

/// Same exponents with the given factor basis (legendre only if is_downward_closed).
PolynomialSpace polynomial_space(const ElementType& type, FactorBasis factors);

/// True when replacing each monomial factor by a Legendre one keeps the span: every
/// exponent decremented in one coordinate stays in the set (for the pyramid, i or j
/// decremented at the same k, or k decremented while k > max(i, j)).
bool is_downward_closed(const PolynomialSpace& space);

/// q_n(t) and dq_n/dt for n = 0..order, in scalar type S (double, or long double for the
/// ill-conditioned monomial spaces).
template <class S>
struct Factor1DT {
  std::array<S, kMaxLagrangeOrder + 1> v{};
  std::array<S, kMaxLagrangeOrder + 1> d{};
};
using Factor1D = Factor1DT<double>;

/// Monomials t^n or Legendre polynomials P_n(t) (Bonnet's recurrence), with derivatives.
template <class S>
void fill_factor(FactorBasis basis, S t, int order, Factor1DT<S>& out) noexcept {
  out.v[0] = 1;
  out.d[0] = 0;
  if (order == 0) return;
  out.v[1] = t;
  out.d[1] = 1;
  for (int n = 1; n < order; ++n) {
    if (basis == FactorBasis::legendre) {
      // (n+1) P_{n+1} = (2n+1) t P_n - n P_{n-1};  P'_{n+1} = P'_{n-1} + (2n+1) P_n.
      out.v[n + 1] = (S(2 * n + 1) * t * out.v[n] - S(n) * out.v[n - 1]) / S(n + 1);
      out.d[n + 1] = out.d[n - 1] + S(2 * n + 1) * out.v[n];
    } else {
      out.v[n + 1] = out.v[n] * t;
      out.d[n + 1] = S(n + 1) * out.v[n];
    }
  }
}

/// Calls visit(j, phi_j(x), grad) for every basis function j, grad = {dphi/dx0, dx1, dx2}
/// (zeros beyond the space's dimension). With WithGradients false, grad is all zero.
/// Pyramid precondition for gradients: zeta < 1 (see LagrangeBasis for zeta = 1).
template <bool WithGradients, class S = double, class Visit>
void for_each_basis_function(const PolynomialSpace& s, const RefPoint& xd, Visit&& visit) {
  const int p = s.order;
  const std::array<S, 3> x{S(xd[0]), S(xd[1]), S(xd[2])};
  if (s.factors == FactorBasis::bernstein) {
    // Barycentric powers: b[0] = 1 - sum, b[1..n] = coordinates (n = 2 or 3 simplex coords).
    const int n = s.family == ElementFamily::tetrahedron ? 3 : 2;
    Factor1DT<S> b[4], w;
    S rest = 1.0;
    for (int d = 0; d < n; ++d) rest -= x[d];
    fill_factor(FactorBasis::monomial, rest, p, b[0]);
    for (int d = 0; d < n; ++d) fill_factor(FactorBasis::monomial, x[d], p, b[d + 1]);
    if (n == 2) {
      if (s.family == ElementFamily::prism) {
        fill_factor(FactorBasis::legendre, x[2], p, w);
      } else {
        w.v[0] = 1.0;
      }
    }
    std::array<S, kMaxLagrangeOrder + 1> factorial{};
    factorial[0] = 1.0;
    for (int k = 1; k <= p; ++k) factorial[k] = factorial[k - 1] * S(k);
    const int count = static_cast<int>(s.exponents.size());
    for (int j = 0; j < count; ++j) {
      const auto& e = s.exponents[j];
      const int simplex_exps = n == 3 ? e[0] + e[1] + e[2] : e[0] + e[1];
      const int l = p - simplex_exps;
      S c = factorial[p] / factorial[l];
      S prod = b[0].v[l];
      for (int d = 0; d < n; ++d) c /= factorial[e[d]], prod *= b[d + 1].v[e[d]];
      const S wv = n == 3 ? 1.0 : w.v[e[2]];
      std::array<S, 3> g{0, 0, 0};
      if constexpr (WithGradients) {
        for (int d = 0; d < n; ++d) {
          // d/dx_d of x_d^{e_d} (1 - sum)^l times the other factors (no division).
          S t = b[d + 1].d[e[d]] * b[0].v[l] - b[d + 1].v[e[d]] * b[0].d[l];
          for (int o = 0; o < n; ++o)
            if (o != d) t *= b[o + 1].v[e[o]];
          g[d] = c * t * wv;
        }
        if (n == 2 && s.family == ElementFamily::prism) g[2] = c * prod * w.d[e[2]];
      }
      visit(j, c * prod * wv, g);
    }
    return;
  }
  if (s.family != ElementFamily::pyramid) {
    Factor1DT<S> f[3];
    for (int d = 0; d < 3; ++d) {
      if (d < s.dim) {
        fill_factor(s.factors, S(s.scale[d]) * x[d] + S(s.shift[d]), p, f[d]);
      } else {
        f[d].v[0] = 1.0;  // unused coordinate: only exponent 0 occurs
      }
    }
    const int n = static_cast<int>(s.exponents.size());
    for (int j = 0; j < n; ++j) {
      const auto& e = s.exponents[j];
      const S a = f[0].v[e[0]], b = f[1].v[e[1]], c = f[2].v[e[2]];
      std::array<S, 3> g{0, 0, 0};
      if constexpr (WithGradients) {
        g[0] = s.scale[0] * f[0].d[e[0]] * b * c;
        g[1] = s.scale[1] * a * f[1].d[e[1]] * c;
        g[2] = s.scale[2] * a * b * f[2].d[e[2]];
      }
      visit(j, a * b * c, g);
    }
    return;
  }
  // Pyramid: xi' = xi / w, eta' = eta / w, w = 1 - zeta. At the apex (w = 0) xi' and eta'
  // are set to 0: the value does not depend on them there, and the gradient becomes its
  // limit along the axis xi = eta = 0.
  const S w = 1.0 - x[2];
  const S xs = w != 0 ? x[0] / w : S(0);
  const S ys = w != 0 ? x[1] / w : S(0);
  Factor1DT<S> fx, fy;
  fill_factor(s.factors, xs, p, fx);
  fill_factor(s.factors, ys, p, fy);
  std::array<S, kMaxLagrangeOrder + 1> wpow{};
  wpow[0] = 1.0;
  for (int m = 1; m <= p; ++m) wpow[m] = wpow[m - 1] * w;
  Factor1DT<S> r;  // r_m(zeta) and dr_m/dzeta
  if (s.factors == FactorBasis::legendre) {
    fill_factor(FactorBasis::legendre, S(2) * x[2] - S(1), p, r);
    for (int m = 0; m <= p; ++m) r.d[m] *= S(2);
  } else {
    for (int m = 0; m <= p; ++m) {
      r.v[m] = wpow[m];
      r.d[m] = m > 0 ? -S(m) * wpow[m - 1] : S(0);
    }
  }
  const int n = static_cast<int>(s.exponents.size());
  for (int j = 0; j < n; ++j) {
    const auto& e = s.exponents[j];
    const int mu = std::max(e[0], e[1]);
    const int m = e[2] - mu;
    const S a = fx.v[e[0]], b = fy.v[e[1]];
    const S z = wpow[mu] * r.v[m];
    std::array<S, 3> g{0, 0, 0};
    if constexpr (WithGradients) {
      // z / w without dividing: mu >= 1 whenever a' or b' is non-zero.
      const S z_over_w = mu > 0 ? wpow[mu - 1] * r.v[m] : S(0);
      const S dz = (mu > 0 ? -S(mu) * wpow[mu - 1] * r.v[m] : S(0)) + wpow[mu] * r.d[m];
      g[0] = fx.d[e[0]] * b * z_over_w;
      g[1] = a * fy.d[e[1]] * z_over_w;
      g[2] = (fx.d[e[0]] * xs * b + a * fy.d[e[1]] * ys) * z_over_w + a * b * dz;
    }
    visit(j, a * b * z, g);
  }
}

template <class S>
using RowMajorMatrixT = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMajorMatrix = RowMajorMatrixT<double>;

/// C = V^{-1}, V(k, j) = phi_j(nodes[k]) the generalized Vandermonde matrix, so that
/// N_i = sum_j phi_j C(j, i) is 1 at nodes[i] and 0 at the others. Computed in double, or
/// in long double (lagrange_coefficients_long) for the monomial spaces.
/// @pre V is square and invertible (the nodes are unisolvent for the space)
RowMajorMatrix lagrange_coefficients(const PolynomialSpace& space,
                                     std::span<const RefPoint> nodes);
RowMajorMatrixT<long double> lagrange_coefficients_long(const PolynomialSpace& space,
                                                        std::span<const RefPoint> nodes);

}  // namespace quadval::detail
