#include "polynomial_space.hpp"

#include <Eigen/LU>
#include <set>

#include "quadval/error.hpp"

namespace quadval::detail {
namespace {

using F = ElementFamily;
using Exponents = std::vector<std::array<int, 3>>;

// Gmsh's incomplete triangle: monomials on the edges of Pascal's triangle.
bool on_pascal_triangle_edge(int i, int j, int p) { return i == 0 || j == 0 || i + j == p; }

Exponents exponents_of(F f, int p, bool complete) {
  Exponents e;
  switch (f) {
    case F::point:
      e.push_back({0, 0, 0});
      break;
    case F::line:
      for (int i = 0; i <= p; ++i) e.push_back({i, 0, 0});
      break;
    case F::triangle:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
          if (complete || on_pascal_triangle_edge(i, j, p)) e.push_back({i, j, 0});
      break;
    case F::quadrangle:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; j <= p; ++j)
          if (complete || i <= 1 || j <= 1) e.push_back({i, j, 0});
      break;
    case F::tetrahedron:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
          for (int k = 0; i + j + k <= p; ++k) {
            // incomplete: on an edge of Pascal's tetrahedron (two barycentric exponents 0)
            const int zeros = (i == 0) + (j == 0) + (k == 0) + (i + j + k == p);
            if (complete || zeros >= 2) e.push_back({i, j, k});
          }
      break;
    case F::hexahedron:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; j <= p; ++j)
          for (int k = 0; k <= p; ++k)
            if (complete || (i > 1) + (j > 1) + (k > 1) <= 1) e.push_back({i, j, k});
      break;
    case F::prism:
      for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
          for (int k = 0; k <= p; ++k) {
            const bool incomplete_ok =
                (k <= 1 && on_pascal_triangle_edge(i, j, p)) || (k >= 2 && i + j <= 1);
            if (complete || incomplete_ok) e.push_back({i, j, k});
          }
      break;
    case F::pyramid:
      // Bergot's P^p (thesis Paper IV eq. 2): i, j <= k <= p. Incomplete: see the header.
      for (int k = 0; k <= p; ++k)
        for (int i = 0; i <= k; ++i)
          for (int j = 0; j <= k; ++j) {
            const bool incomplete_ok =
                (i <= 1 && j <= 1) || (k == std::max(i, j) && std::min(i, j) <= 1);
            if (complete || incomplete_ok) e.push_back({i, j, k});
          }
      break;
    default:
      QV_ASSERT(false, "no polynomial space for family " << family_name(f));
  }
  return e;
}

}  // namespace

bool is_downward_closed(const PolynomialSpace& s) {
  const std::set<std::array<int, 3>> set(s.exponents.begin(), s.exponents.end());
  auto has = [&](int a, int b, int c) { return set.count({a, b, c}) > 0; };
  for (const auto& e : s.exponents) {
    if (s.family == F::pyramid) {
      if (e[0] > 0 && !has(e[0] - 1, e[1], e[2])) return false;
      if (e[1] > 0 && !has(e[0], e[1] - 1, e[2])) return false;
      if (e[2] > std::max(e[0], e[1]) && !has(e[0], e[1], e[2] - 1)) return false;
    } else {
      for (int d = 0; d < 3; ++d) {
        auto f = e;
        if (f[d] == 0) continue;
        --f[d];
        if (!has(f[0], f[1], f[2])) return false;
      }
    }
  }
  return true;
}

PolynomialSpace polynomial_space(const ElementType& type, FactorBasis factors) {
  QV_ASSERT(type.has_lagrange_basis && type.order <= kMaxLagrangeOrder, type.name);
  PolynomialSpace s;
  s.family = type.family;
  s.dim = type.dim;
  s.order = type.order;
  s.exponents = exponents_of(type.family, type.order, type.complete);
  QV_ASSERT(static_cast<int>(s.exponents.size()) == type.num_nodes,
            type.name << ": " << s.exponents.size() << " functions");
  s.factors = factors;
  QV_ASSERT(factors != FactorBasis::legendre || is_downward_closed(s),
            type.name << ": Legendre factors would change the span");
  QV_ASSERT(factors != FactorBasis::bernstein ||
                (type.complete && (type.family == F::triangle || type.family == F::tetrahedron ||
                                   type.family == F::prism)),
            type.name << ": Bernstein factors need a complete simplex or prism");
  if (factors == FactorBasis::legendre) {
    // Map simplex coordinates [0, 1] onto [-1, 1], where Legendre factors are bounded by 1.
    const bool simplex_uv = type.family == F::triangle || type.family == F::tetrahedron ||
                            type.family == F::prism;
    if (simplex_uv) {
      const int n = type.family == F::tetrahedron ? 3 : 2;
      for (int d = 0; d < n; ++d) {
        s.scale[d] = 2.0;
        s.shift[d] = -1.0;
      }
    }
  }
  return s;
}

PolynomialSpace polynomial_space(const ElementType& type) {
  const bool simplex = type.family == F::triangle || type.family == F::tetrahedron ||
                       type.family == F::prism;
  if (type.complete && simplex && type.order >= 1)
    return polynomial_space(type, FactorBasis::bernstein);
  PolynomialSpace s = polynomial_space(type, FactorBasis::monomial);
  return is_downward_closed(s) ? polynomial_space(type, FactorBasis::legendre) : s;
}

namespace {

template <class S>
RowMajorMatrixT<S> inverse_vandermonde(const PolynomialSpace& space,
                                       std::span<const RefPoint> nodes) {
  using Matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  const auto n = static_cast<Eigen::Index>(space.exponents.size());
  QV_ASSERT(static_cast<Eigen::Index>(nodes.size()) == n,
            nodes.size() << " nodes for " << n << " functions");
  Matrix v(n, n);
  for (Eigen::Index k = 0; k < n; ++k)
    for_each_basis_function<false, S>(space, nodes[k], [&](int j, S phi, const auto&) {
      v(k, j) = phi;
    });
  const Eigen::FullPivLU<Matrix> lu(v);
  QV_ASSERT(lu.isInvertible(), "nodes are not unisolvent for the space (order "
                                   << space.order << ", family " << family_name(space.family)
                                   << ")");
  return lu.inverse();
}

}  // namespace

RowMajorMatrix lagrange_coefficients(const PolynomialSpace& space,
                                     std::span<const RefPoint> nodes) {
  return inverse_vandermonde<double>(space, nodes);
}

RowMajorMatrixT<long double> lagrange_coefficients_long(const PolynomialSpace& space,
                                                        std::span<const RefPoint> nodes) {
  return inverse_vandermonde<long double>(space, nodes);
}

}  // namespace quadval::detail
