// The first-order fast path (src/analysis/linear_jacobian.hpp) against oracles that share
// none of its code: J expanded exactly (GMP rationals) in monomials from the multilinear
// map, converted to Bernstein form by the textbook monomial-to-Bernstein rule; exact dense
// samples of J; and the general path (jacobian_bounds) for the validity answers.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

#include "analysis/linear_jacobian.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

// Polynomial in (u, v, w) with degree <= 2 in each: coefficient of u^p v^q w^r at p+3q+9r.
using Poly = std::array<mpq_class, 27>;

Poly mul(const Poly& a, const Poly& b) {
  Poly c;
  for (int i = 0; i < 27; ++i) c[static_cast<std::size_t>(i)] = 0;
  for (int i = 0; i < 27; ++i) {
    if (sgn(a[static_cast<std::size_t>(i)]) == 0) continue;
    for (int j = 0; j < 27; ++j) {
      if (sgn(b[static_cast<std::size_t>(j)]) == 0) continue;
      const int p = i % 3 + j % 3, q = i / 3 % 3 + j / 3 % 3, r = i / 9 + j / 9;
      EXPECT_TRUE(p <= 2 && q <= 2 && r <= 2);
      c[static_cast<std::size_t>(p + 3 * q + 9 * r)] += a[static_cast<std::size_t>(i)] * b[static_cast<std::size_t>(j)];
    }
  }
  return c;
}

Poly zero() {
  Poly z;
  for (auto& c : z) c = 0;
  return z;
}

// The multilinear map of a first-order element of `type` on [0,1]^d (or the unit simplex):
// X[axis] as a polynomial. Vertex lattice positions come from Gmsh's reference nodes.
std::array<Poly, 3> multilinear_map(const ElementType& type, const std::vector<double>& x) {
  const auto ref = reference_nodes(type);
  std::array<Poly, 3> X{zero(), zero(), zero()};
  const bool cube = type.family == ElementFamily::hexahedron || type.family == ElementFamily::quadrangle;
  for (std::size_t n = 0; n < ref.size(); ++n) {
    // shape function of vertex n in monomials
    Poly shape = zero();
    shape[0] = 1;
    if (cube) {
      for (int d = 0; d < type.dim; ++d) {
        const double a = (ref[n][static_cast<std::size_t>(d)] + 1) / 2;  // 0 or 1
        Poly f = zero();
        const int unit = d == 0 ? 1 : d == 1 ? 3 : 9;
        if (a == 1) {
          f[static_cast<std::size_t>(unit)] = 1;  // t
        } else {
          f[0] = 1;  // 1 - t
          f[static_cast<std::size_t>(unit)] = -1;
        }
        shape = mul(shape, f);
      }
    } else {
      // simplex: barycentric coordinate of vertex n (reference vertices 0, e_1, e_2, e_3)
      shape = zero();
      if (n == 0) {
        shape[0] = 1;
        for (int d = 0; d < type.dim; ++d) shape[static_cast<std::size_t>(d == 0 ? 1 : d == 1 ? 3 : 9)] = -1;
      } else {
        for (int d = 0; d < type.dim; ++d) EXPECT_EQ(ref[n][static_cast<std::size_t>(d)], n - 1 == static_cast<std::size_t>(d) ? 1.0 : 0.0);
        shape[static_cast<std::size_t>(n == 1 ? 1 : n == 2 ? 3 : 9)] = 1;
      }
    }
    for (int axis = 0; axis < 3; ++axis)
      for (int i = 0; i < 27; ++i)
        X[static_cast<std::size_t>(axis)][static_cast<std::size_t>(i)] +=
            shape[static_cast<std::size_t>(i)] * mpq_class(x[3 * n + static_cast<std::size_t>(axis)]);
  }
  return X;
}

Poly derivative(const Poly& p, int d) {
  Poly r = zero();
  const int unit = d == 0 ? 1 : d == 1 ? 3 : 9;
  for (int i = 0; i < 27; ++i) {
    const int e = d == 0 ? i % 3 : d == 1 ? i / 3 % 3 : i / 9;
    if (e > 0) r[static_cast<std::size_t>(i - unit)] += e * p[static_cast<std::size_t>(i)];
  }
  return r;
}

// Exact J (Gmsh reference coordinates) as a polynomial on [0,1]^d or the unit simplex.
Poly exact_jacobian(const ElementType& type, const std::vector<double>& x) {
  const auto X = multilinear_map(type, x);
  const bool cube = type.family == ElementFamily::hexahedron || type.family == ElementFamily::quadrangle;
  Poly g[3][3];  // g[axis][d] = dX_axis / du_d
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < type.dim; ++d) g[a][d] = derivative(X[static_cast<std::size_t>(a)], d);
  Poly J = zero();
  if (type.dim == 3) {
    static constexpr int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    for (int s = 0; s < 6; ++s) {
      const Poly t = mul(mul(g[kPerm[s][0]][0], g[kPerm[s][1]][1]), g[kPerm[s][2]][2]);
      for (int i = 0; i < 27; ++i) J[static_cast<std::size_t>(i)] += (s < 3 ? 1 : -1) * t[static_cast<std::size_t>(i)];
    }
  } else {
    const Poly a = mul(g[0][0], g[1][1]), b = mul(g[0][1], g[1][0]);
    for (int i = 0; i < 27; ++i) J[static_cast<std::size_t>(i)] = a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)];
  }
  // [-1,1] reference directions: d/dxi = (1/2) d/du each.
  if (cube)
    for (auto& c : J) c /= type.dim == 3 ? 8 : 4;
  return J;
}

// Monomial -> Bernstein of degree n per direction: t^k = sum_i binom(i,k)/binom(n,k) B^n_i.
mpq_class to_bernstein_weight(int k, int i, int n) {
  const auto binom = [](int a, int b) {
    if (b < 0 || b > a) return 0;
    int r = 1;
    for (int j = 1; j <= b; ++j) r = r * (a - b + j) / j;
    return r;
  };
  return mpq_class(binom(i, k), binom(n, k));
}

// ---- Pyramid oracle: Gmsh's 5-node pyramid (Bergot's first order) written in Gmsh's own
// coordinates, N_ab = (t + s xi)(t + r eta) / (4 t) for the base vertex at (s, r, 0),
// N_apex = zeta, t = 1 - zeta; J = det of sum_n x_n (grad N_n)^T, exactly, at zeta < 1.
// Nothing here uses the cube coordinates or the bilinearity the fast path relies on.
mpq_class pyramid_jacobian_at(const std::vector<double>& x, const mpq_class& xi, const mpq_class& eta,
                              const mpq_class& zeta) {
  static constexpr int kSign[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};  // Gmsh nodes 0..3
  const mpq_class t = 1 - zeta;
  EXPECT_GT(t, 0);
  mpq_class g[3][3];  // g[axis][d] = d x_axis / d (xi, eta, zeta)_d
  for (int n = 0; n < 5; ++n) {
    mpq_class grad[3];
    if (n == 4) {
      grad[0] = 0, grad[1] = 0, grad[2] = 1;
    } else {
      const mpq_class fx = t + kSign[n][0] * xi, fy = t + kSign[n][1] * eta;
      grad[0] = kSign[n][0] * fy / (4 * t);
      grad[1] = kSign[n][1] * fx / (4 * t);
      grad[2] = fx * fy / (4 * t * t) - (fx + fy) / (4 * t);  // d/dzeta = -d/dt
    }
    for (int a = 0; a < 3; ++a)
      for (int d = 0; d < 3; ++d) g[a][d] += mpq_class(x[3 * static_cast<std::size_t>(n) + static_cast<std::size_t>(a)]) * grad[d];
  }
  return g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1]) - g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0]) +
         g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]);
}

// J at cube point (u, v, t): xi = (2u - 1) t, eta = (2v - 1) t, zeta = 1 - t.
mpq_class pyramid_jacobian_cube(const std::vector<double>& x, const mpq_class& u, const mpq_class& v,
                                const mpq_class& t) {
  return pyramid_jacobian_at(x, (2 * u - 1) * t, (2 * v - 1) * t, 1 - t);
}

// The pyramid's degree-(1, 1) Bézier coefficients in (u, v) (index a + 2b): J at the base
// corners. Checks on the way, exactly, what the fast path assumes: J at the midpoints and
// centre of the square is the bilinear interpolant of the corners (so the degree-(2, 2)
// coefficients of Paper IV are degree-elevated bilinear ones), and J at random rational
// points of the pyramid, down to t = 1/1000, is the bilinear interpolant too.
std::vector<mpq_class> exact_pyramid_corners(const std::vector<double>& x, std::mt19937& rng) {
  const mpq_class t0(1, 3);
  std::vector<mpq_class> c(4);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) c[static_cast<std::size_t>(a + 2 * b)] = pyramid_jacobian_cube(x, a, b, t0);
  const auto bilinear = [&](const mpq_class& u, const mpq_class& v) -> mpq_class {
    return (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + (1 - u) * v * c[2] + u * v * c[3];
  };
  std::vector<std::array<mpq_class, 3>> pts;
  const mpq_class h(1, 2);
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 2; ++j) pts.push_back({i * h, j * h, 1});
  std::uniform_int_distribution<int> num(0, 997);
  for (int k = 0; k < 3; ++k) pts.push_back({mpq_class(num(rng), 997), mpq_class(num(rng), 997), mpq_class(1 + num(rng), 1000)});
  for (auto& p : pts) {
    for (auto& q : p) q.canonicalize();
    EXPECT_EQ(pyramid_jacobian_cube(x, p[0], p[1], p[2]), bilinear(p[0], p[1])) << p[0] << " " << p[1] << " " << p[2];
  }
  return c;
}

// Exact Bézier coefficients in the fast path's layout (hex i+3j+9k degree 2; quad a+2b
// degree 1; simplices the constant).
std::vector<mpq_class> exact_coefficients(const ElementType& type, const std::vector<double>& x) {
  if (type.family == ElementFamily::pyramid) {
    std::mt19937 rng(static_cast<unsigned>(x.size()));
    return exact_pyramid_corners(x, rng);
  }
  const Poly J = exact_jacobian(type, x);
  const int n = type.family == ElementFamily::hexahedron ? 2 : type.family == ElementFamily::quadrangle ? 1 : 0;
  if (n == 0) {
    for (int i = 1; i < 27; ++i) EXPECT_EQ(sgn(J[static_cast<std::size_t>(i)]), 0);
    return {J[0]};
  }
  const int dims = type.dim;
  const int s = n + 1;
  const int count = dims == 3 ? s * s * s : s * s;
  std::vector<mpq_class> out(static_cast<std::size_t>(count));
  for (int idx = 0; idx < count; ++idx) {
    const int i = idx % s, j = idx / s % s, k = dims == 3 ? idx / (s * s) : 0;
    mpq_class sum = 0;
    for (int m = 0; m < 27; ++m) {
      const int p = m % 3, q = m / 3 % 3, r = m / 9;
      if (sgn(J[static_cast<std::size_t>(m)]) == 0) continue;
      EXPECT_TRUE(p <= n && q <= n && r <= (dims == 3 ? n : 0));
      sum += J[static_cast<std::size_t>(m)] * to_bernstein_weight(p, i, n) * to_bernstein_weight(q, j, n) *
             (dims == 3 ? to_bernstein_weight(r, k, n) : mpq_class(1));
    }
    out[static_cast<std::size_t>(idx)] = sum;
  }
  return out;
}

mpq_class evaluate(const Poly& J, const mpq_class& u, const mpq_class& v, const mpq_class& w) {
  mpq_class r = 0;
  for (int m = 0; m < 27; ++m) {
    if (sgn(J[static_cast<std::size_t>(m)]) == 0) continue;
    mpq_class t = J[static_cast<std::size_t>(m)];
    for (int e = 0; e < m % 3; ++e) t *= u;
    for (int e = 0; e < m / 3 % 3; ++e) t *= v;
    for (int e = 0; e < m / 9; ++e) t *= w;
    r += t;
  }
  return r;
}

// Random first-order elements of `type`, including inverted, tiny, far-translated and
// nearly degenerate ones (a vertex moved onto, or within a few ulps of, the plane of its
// neighbours, which makes a vertex value of J zero or nearly so).
std::vector<std::vector<double>> random_elements(const ElementType& type, int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  const auto ref = reference_nodes(type);
  std::vector<std::vector<double>> out;
  const double amps[] = {0.02, 0.2, 0.45, 0.8};
  for (int e = 0; e < count; ++e) {
    const double amp = amps[e % 4];
    const double scale = (e % 7 == 0) ? 1e-9 : (e % 11 == 0) ? 1e6 : 1;
    const double shift = (e % 5 == 0) ? 1e4 : 0;
    std::vector<double> x;
    for (const auto& p : ref)
      for (int a = 0; a < 3; ++a) {
        const bool flat = type.dim == 2 && a == 2;
        x.push_back(flat ? 0.0 : shift + scale * (p[static_cast<std::size_t>(a)] + amp * u(rng)));
      }
    if (e % 3 == 1) {
      // vertex 0 onto the plane (3D) / line (2D) of its neighbours, then a tiny offset
      const bool box = type.family == ElementFamily::hexahedron || type.family == ElementFamily::quadrangle ||
                       type.family == ElementFamily::pyramid;
      const int nb[3] = {1, box ? 3 : 2, box ? 4 : 3};  // the edge-neighbours of vertex 0
      const double t0 = 0.3 + 0.2 * u(rng), t1 = 0.3 + 0.2 * u(rng);
      const int nv = type.dim;  // neighbours used
      for (int a = 0; a < (type.dim == 2 ? 2 : 3); ++a) {
        const double* p1 = &x[3 * static_cast<std::size_t>(nb[0]) + static_cast<std::size_t>(a)];
        const double* p2 = &x[3 * static_cast<std::size_t>(nb[1]) + static_cast<std::size_t>(a)];
        double v = *p1 + t0 * (*p2 - *p1);
        if (nv == 3) v += t1 * (x[3 * static_cast<std::size_t>(nb[2]) + static_cast<std::size_t>(a)] - *p1);
        x[static_cast<std::size_t>(a)] = v;
      }
      const int ulps = e % 4;  // 0: as computed (nearly exactly degenerate)
      for (int k = 0; k < ulps; ++k) x[0] = std::nextafter(x[0], e % 2 ? 1e300 : -1e300);
    }
    out.push_back(std::move(x));
  }
  return out;
}

struct Tally {
  int decided = 0, valid = 0, invalid = 0, open = 0;
};

// Runs every check of the fast path on `elements` of `type`; returns what it decided.
Tally check_type(const ElementType& type, const std::vector<std::vector<double>>& elements, int dense_every) {
  const bool planar = type.dim == 2;
  const LinearKind kind = linear_kind(type, planar);
  EXPECT_NE(kind, LinearKind::none);
  const auto nv = static_cast<std::size_t>(linear_num_vertices(kind));
  EXPECT_EQ(nv, static_cast<std::size_t>(type.num_nodes));
  BoundsWorkspace ws;
  Tally t;
  for (std::size_t first = 0; first < elements.size(); first += kLinearChunk) {
    const std::size_t count = std::min(kLinearChunk, elements.size() - first);
    std::vector<double> soa(nv * 3 * kLinearRow);
    for (std::size_t e = 0; e < count; ++e)
      for (std::size_t v = 0; v < nv; ++v)
        for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow + e] = elements[first + e][v * 3 + a];
    std::vector<JacobianBounds> fast(count);
    bool decided[kLinearChunk];
    linear_validity_chunk(kind, soa.data(), count, fast.data(), decided);
    for (std::size_t e = 0; e < count; ++e) {
      const std::vector<double>& x = elements[first + e];
      SCOPED_TRACE(::testing::Message() << type.name << " element " << first + e);
      const std::vector<mpq_class> exact = exact_coefficients(type, x);
      // Per-coefficient error bound.
      std::vector<double> c(exact.size());
      const double err = linear_jacobian_coefficients(kind, x.data(), c.data());
      if (std::isfinite(err))
        for (std::size_t i = 0; i < c.size(); ++i) {
          const mpq_class diff = abs(mpq_class(c[i]) - exact[i]);
          EXPECT_LE(diff, mpq_class(err)) << "coefficient " << i;
        }
      if (!decided[e]) {
        ++t.open;
        continue;
      }
      ++t.decided;
      const JacobianBounds& b = fast[e];
      // Same answer as the general path.
      const JacobianBounds general = jacobian_bounds(type, x, BoundsOptions{}, ws, planar);
      EXPECT_EQ(b.validity, general.validity);
      // fast: stage 1 (valid) or 0 (invalid); the general path's wider error bound may
      // need a later stage for the same answer, never an earlier one
      EXPECT_LE(b.stage, general.stage);
      (b.validity == Validity::valid ? t.valid : t.invalid) += 1;
      // Bounds contain the exact quantities: min/max coefficient bound J (convex hull),
      // vertex coefficients are values of J.
      mpq_class cmin = exact[0], cmax = exact[0], vmin, vmax;
      bool have_vertex = false;
      const int s = kind == LinearKind::hexahedron ? 3 : 2;
      for (std::size_t i = 0; i < exact.size(); ++i) {
        cmin = std::min(cmin, exact[i]);
        cmax = std::max(cmax, exact[i]);
        const int ii = static_cast<int>(i);
        const bool vertex = kind != LinearKind::hexahedron || (ii % s != 1 && ii / s % s != 1 && ii / (s * s) != 1);
        if (!vertex) continue;
        if (!have_vertex || exact[i] < vmin) vmin = exact[i];
        if (!have_vertex || exact[i] > vmax) vmax = exact[i];
        have_vertex = true;
      }
      EXPECT_LE(mpq_class(b.jmin_lower), cmin);
      EXPECT_GE(mpq_class(b.jmin_upper), vmin);
      EXPECT_LE(mpq_class(b.jmax_lower), vmax);
      EXPECT_GE(mpq_class(b.jmax_upper), cmax);
      if (b.validity == Validity::valid) {
        EXPECT_GT(cmin, 0);
      } else {
        EXPECT_LE(vmin, 0);
      }
      // Dense exact sampling never goes below the lower bound (nor above the upper).
      if (dense_every > 0 && (first + e) % static_cast<std::size_t>(dense_every) == 0 &&
          type.family == ElementFamily::pyramid) {
        const int m = 6;
        for (int i = 0; i <= m; ++i)
          for (int j = 0; j <= m; ++j)
            for (int k = 1; k <= m; ++k) {  // t = k / m > 0: never the apex
              const mpq_class val = pyramid_jacobian_cube(x, mpq_class(i, m), mpq_class(j, m), mpq_class(k, m));
              EXPECT_GE(val, mpq_class(b.jmin_lower));
              EXPECT_LE(val, mpq_class(b.jmax_upper));
            }
      } else if (dense_every > 0 && (first + e) % static_cast<std::size_t>(dense_every) == 0) {
        const Poly J = exact_jacobian(type, x);
        const int m = 6;
        for (int i = 0; i <= m; ++i)
          for (int j = 0; j <= m; ++j)
            for (int k = 0; k <= (type.dim == 3 ? m : 0); ++k) {
              const bool simplex = type.family == ElementFamily::triangle || type.family == ElementFamily::tetrahedron;
              if (simplex && i + j + k > m) continue;
              const mpq_class val = evaluate(J, mpq_class(i, m), mpq_class(j, m), mpq_class(k, m));
              EXPECT_GE(val, mpq_class(b.jmin_lower));
              EXPECT_LE(val, mpq_class(b.jmax_upper));
            }
      }
    }
  }
  std::cout << type.name << ": fast path decided " << t.valid << " valid, " << t.invalid
            << " invalid; left " << t.open << " to the general path\n";
  return t;
}

TEST(LinearFastPath, HexahedraMatchExactCoefficientsAndGeneralPath) {
  std::mt19937 rng(2026);
  const ElementType& type = *find_element_type(5);
  const auto elements = random_elements(type, 2000, rng);
  const Tally t = check_type(type, elements, 10);
  // The fast path must decide most elements both ways and leave the degenerate ones.
  EXPECT_GT(t.valid, 500);
  EXPECT_GT(t.invalid, 100);
  EXPECT_GT(t.open, 10);
}

TEST(LinearFastPath, TetrahedraMatchExactAndGeneralPath) {
  std::mt19937 rng(7);
  const ElementType& type = *find_element_type(4);
  const Tally t = check_type(type, random_elements(type, 3000, rng), 20);
  EXPECT_GT(t.valid, 500);
  EXPECT_GT(t.invalid, 100);
  EXPECT_GT(t.open, 10);
}

// First-order pyramids: the four corner coefficients against Gmsh's shape functions in
// exact rationals (which also confirm J bilinear in (u, v), constant along t), and the
// validity answers against the general path (the enriched degree-(2, 2) basis).
TEST(LinearFastPath, PyramidsMatchExactCoefficientsAndGeneralPath) {
  std::mt19937 rng(4);
  const ElementType& type = *find_element_type(7);
  const Tally t = check_type(type, random_elements(type, 2400, rng), 12);
  EXPECT_GT(t.valid, 500);
  EXPECT_GT(t.invalid, 100);
  EXPECT_GT(t.open, 10);
}

// A pyramid placed by an affine map x = M p + s of the reference has J = det M everywhere:
// the four coefficients equal det M to rounding, the bounds contain it and close on it.
TEST(LinearFastPath, AffinePyramidHasConstantJacobian) {
  const ElementType& type = *find_element_type(7);
  const auto ref = reference_nodes(type);
  std::mt19937 rng(8);
  std::uniform_int_distribution<int> q(-16, 16);
  for (int e = 0; e < 200; ++e) {
    // dyadic entries: det M and the placed nodes are exact in doubles
    double m[3][3], s[3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[i][j] = q(rng) / 16.0 + (i == j ? 2 * (e % 2 ? 1 : -1) : 0);
      s[i] = q(rng) / 4.0;
    }
    std::vector<double> x;
    for (const RefPoint& p : ref)
      for (int i = 0; i < 3; ++i) x.push_back(m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + s[i]);
    const mpq_class det = mpq_class(m[0][0]) * (mpq_class(m[1][1]) * m[2][2] - mpq_class(m[1][2]) * m[2][1]) -
                          mpq_class(m[0][1]) * (mpq_class(m[1][0]) * m[2][2] - mpq_class(m[1][2]) * m[2][0]) +
                          mpq_class(m[0][2]) * (mpq_class(m[1][0]) * m[2][1] - mpq_class(m[1][1]) * m[2][0]);
    if (sgn(det) == 0) continue;
    double c[4];
    const double err = linear_jacobian_coefficients(LinearKind::pyramid, x.data(), c);
    ASSERT_TRUE(std::isfinite(err));
    for (double v : c) EXPECT_LE(abs(mpq_class(v) - det), mpq_class(err)) << e;
    std::vector<double> soa(5 * 3 * kLinearRow);
    for (std::size_t v = 0; v < 5; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow] = x[v * 3 + a];
    JacobianBounds b;
    bool decided[1] = {false};
    linear_validity_chunk(LinearKind::pyramid, soa.data(), 1, &b, decided);
    ASSERT_TRUE(decided[0]) << e;
    EXPECT_EQ(b.validity, sgn(det) > 0 ? Validity::valid : Validity::invalid);
    EXPECT_LE(mpq_class(b.jmin_lower), det);
    EXPECT_GE(mpq_class(b.jmin_upper), det);
    EXPECT_LE(mpq_class(b.jmax_lower), det);
    EXPECT_GE(mpq_class(b.jmax_upper), det);
    // closes to twice the rounding bound (plus the outward ulps: |c| <= P / 4 < err / (8 u))
    EXPECT_LE(b.jmin_upper - b.jmin_lower, 3 * err);
  }
}

// The minimum of a first-order pyramid's J is at a corner: a pyramid folded so that J is
// negative along one lateral edge only (the others and the centre positive) is invalid, and
// one whose base is a strongly twisted saddle but whose corners are positive is valid,
// as the exact oracle says on a dense lattice. (Paper IV's degree (2, 2) would allow an
// interior minimum; the bilinear J does not, and the fast path relies on that.)
TEST(LinearFastPath, PyramidMinimumIsAtACornerValue) {
  const ElementType& type = *find_element_type(7);
  BoundsWorkspace ws;
  // Saddle base: corners 1 and 3 lifted to z = 0.9, apex at height 1.
  const std::vector<double> saddle = {-1, -1, 0, 1, -1, 0.9, 1, 1, 0, -1, 1, 0.9, 0, 0, 1};
  // Vertex 2 pulled in past the base diagonal (a concave base), the apex leaning away.
  const std::vector<double> folded = {-1, -1, 0, 1, -1, 0, 0, -0.5, 0, -1, 1, 0, -0.75, 0.75, 1.75};
  for (const auto* x : {&saddle, &folded}) {
    std::mt19937 rng(1);
    const std::vector<mpq_class> corners = exact_pyramid_corners(*x, rng);
    const mpq_class cmin = *std::min_element(corners.begin(), corners.end());
    mpq_class lattice_min = corners[0];
    const int m = 8;
    for (int i = 0; i <= m; ++i)
      for (int j = 0; j <= m; ++j)
        for (int k = 1; k <= m; k += 3) lattice_min = std::min(lattice_min, pyramid_jacobian_cube(*x, mpq_class(i, m), mpq_class(j, m), mpq_class(k, m)));
    EXPECT_EQ(lattice_min, cmin);  // attained at a corner, never below it
    std::vector<double> soa(5 * 3 * kLinearRow);
    for (std::size_t v = 0; v < 5; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow] = (*x)[v * 3 + a];
    JacobianBounds b;
    bool decided[1] = {false};
    linear_validity_chunk(LinearKind::pyramid, soa.data(), 1, &b, decided);
    ASSERT_TRUE(decided[0]);
    const Validity want = sgn(cmin) > 0 ? Validity::valid : Validity::invalid;
    EXPECT_EQ(b.validity, want);
    EXPECT_EQ(jacobian_bounds(type, *x, BoundsOptions{}, ws).validity, want);
    EXPECT_LE(mpq_class(b.jmin_lower), cmin);
    EXPECT_GE(mpq_class(b.jmin_upper), cmin);
  }
  std::mt19937 rng(1);
  const auto s = exact_pyramid_corners(saddle, rng), f = exact_pyramid_corners(folded, rng);
  EXPECT_GT(*std::min_element(s.begin(), s.end()), 0);
  EXPECT_LT(f[3], 0);  // corner (1, 1) = Gmsh vertex 2
  EXPECT_GT(f[0], 0);
  EXPECT_GT(pyramid_jacobian_cube(folded, mpq_class(1, 2), mpq_class(1, 2), 1), 0);
}

TEST(LinearFastPath, PlanarTrianglesAndQuadranglesMatchExactAndGeneralPath) {
  std::mt19937 rng(9);
  for (int id : {2, 3}) {
    const ElementType& type = *find_element_type(id);
    const Tally t = check_type(type, random_elements(type, 3000, rng), 20);
    EXPECT_GT(t.valid, 500) << type.name;
    EXPECT_GT(t.invalid, 100) << type.name;
    EXPECT_GT(t.open, 10) << type.name;
  }
}

TEST(LinearFastPath, OutsideTheGuardedRangeNothingIsDecided) {
  // Edge lengths below 2^-200 or above 2^200: the error bound's no-underflow argument
  // does not apply, so everything goes to the general path.
  const ElementType& type = *find_element_type(5);
  for (double scale : {1e-70, 1e70}) {
    std::vector<double> soa(8 * 3 * kLinearRow);
    const auto ref = reference_nodes(type);
    for (std::size_t v = 0; v < 8; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow] = scale * ref[v][a];
    JacobianBounds b;
    bool decided[1] = {true};
    linear_validity_chunk(LinearKind::hexahedron, soa.data(), 1, &b, decided);
    EXPECT_FALSE(decided[0]) << scale;
  }
  // Non-finite coordinates are never decided either.
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<double> soa(8 * 3 * kLinearRow);
    const auto ref = reference_nodes(type);
    for (std::size_t v = 0; v < 8; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearRow] = ref[v][a];
    soa[(6 * 3 + 1) * kLinearRow] = bad;
    JacobianBounds b;
    bool decided[1] = {true};
    linear_validity_chunk(LinearKind::hexahedron, soa.data(), 1, &b, decided);
    EXPECT_FALSE(decided[0]) << bad;
  }
  // Non-planar 2D elements have no fast path.
  EXPECT_EQ(linear_kind(*find_element_type(2), false), LinearKind::none);
  EXPECT_EQ(linear_kind(*find_element_type(3), false), LinearKind::none);
  EXPECT_EQ(linear_kind(*find_element_type(12), true), LinearKind::none);  // hex order 2
}

// The chunk's bounds are exactly the documented ones, bit for bit, for every kind: from
// the per-element coefficients and err of linear_jacobian_coefficients, decided where the
// sum is finite and min c - err > 0 (valid) or min vertex c + err <= 0 (invalid), each
// bound one std::nextafter outward. Partial chunks (count not a multiple of the lane
// width), non-finite and out-of-range elements among them; out[e] and decided[e] are left
// untouched beyond count, and out[e] wherever nothing was decided.
TEST(LinearFastPath, ChunkBoundsAreTheDocumentedOutwardRoundedValues) {
  std::mt19937 rng(77);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (int id : {2, 3, 4, 5, 7}) {
    const ElementType& type = *find_element_type(id);
    const LinearKind kind = linear_kind(type, type.dim == 2);
    const auto nv = static_cast<std::size_t>(linear_num_vertices(kind));
    const int ncoeff = kind == LinearKind::hexahedron ? 27 : (kind == LinearKind::quadrangle || kind == LinearKind::pyramid) ? 4 : 1;
    auto elements = random_elements(type, 1000, rng);
    for (std::size_t e = 3; e < elements.size(); e += 97) elements[e][e % (3 * nv)] = e % 2 ? nan : -inf;
    for (std::size_t e = 5; e < elements.size(); e += 89)
      for (double& c : elements[e]) c *= e % 2 ? 1e-70 : 1e70;
    std::size_t decided_count = 0;
    for (std::size_t first = 0, count = 253; first < elements.size(); first += count, count = count % 256 + 1) {
      count = std::min(count, elements.size() - first);
      std::vector<double> soa(nv * 3 * kLinearRow, 0.5);
      for (std::size_t e = 0; e < count; ++e)
        for (std::size_t k = 0; k < nv * 3; ++k) soa[k * kLinearRow + e] = elements[first + e][k];
      JacobianBounds sentinel;
      sentinel.jmin_lower = -12345;
      sentinel.stage = 99;
      std::vector<JacobianBounds> out(kLinearChunk, sentinel);
      bool decided[kLinearChunk];
      std::fill(decided, decided + kLinearChunk, true);
      linear_validity_chunk(kind, soa.data(), count, out.data(), decided);
      for (std::size_t e = 0; e < kLinearChunk; ++e) {
        SCOPED_TRACE(::testing::Message() << type.name << " element " << first + e << " of chunk " << count);
        const JacobianBounds& b = out[e];
        if (e >= count) {
          EXPECT_TRUE(decided[e]);  // untouched
          EXPECT_EQ(b.jmin_lower, -12345);
          EXPECT_EQ(b.stage, 99);
          continue;
        }
        double c[27];
        const double err = linear_jacobian_coefficients(kind, elements[first + e].data(), c);
        double lo = c[0], hi = c[0], vlo = c[0], vhi = c[0], sum = 0;
        for (int k = 0; k < ncoeff; ++k) {
          lo = std::min(lo, c[k]);
          hi = std::max(hi, c[k]);
          sum += c[k];
          const bool vertex = kind != LinearKind::hexahedron || (k % 3 != 1 && k / 3 % 3 != 1 && k / 9 != 1);
          if (vertex) {
            vlo = std::min(vlo, c[k]);
            vhi = std::max(vhi, c[k]);
          }
        }
        const double lower = std::nextafter(lo - err, -inf), vupper = std::nextafter(vlo + err, inf);
        const bool finite = std::isfinite(sum);
        const bool valid = finite && lower > 0, invalid = finite && vupper <= 0;
        ASSERT_EQ(decided[e], valid || invalid);
        if (!decided[e]) {
          EXPECT_EQ(b.jmin_lower, -12345);  // untouched
          EXPECT_EQ(b.stage, 99);
          continue;
        }
        ++decided_count;
        EXPECT_TRUE(same(b.jmin_lower, lower));
        EXPECT_TRUE(same(b.jmin_upper, vupper));
        EXPECT_TRUE(same(b.jmax_lower, std::nextafter(vhi - err, -inf)));
        EXPECT_TRUE(same(b.jmax_upper, std::nextafter(hi + err, inf)));
        EXPECT_EQ(b.javg, sum / ncoeff);
        EXPECT_EQ(b.validity, valid ? Validity::valid : Validity::invalid);
        EXPECT_EQ(b.stage, valid ? 1 : 0);
        EXPECT_EQ(b.subdivisions, 0);
        EXPECT_FALSE(b.exact);
        EXPECT_TRUE(b.tolerance_met);
      }
    }
    EXPECT_GT(decided_count, 700u) << type.name;
  }
}

// check_mesh (fast path + general fallback) answers exactly as the general path per element.
TEST(LinearFastPath, CheckMeshAgreesWithGeneralPathPerElement) {
  std::mt19937 rng(31);
  for (int id : {5, 4, 7}) {
    const ElementType& type = *find_element_type(id);
    auto elements = random_elements(type, 800, rng);
    // plus a few outside the guarded range
    for (int e = 0; e < 5; ++e) {
      auto x = elements[static_cast<std::size_t>(e)];
      for (double& c : x) c *= 1e-70;
      elements.push_back(std::move(x));
    }
    const Mesh mesh = test::mesh_of_elements(type, elements);
    CheckOptions o;
    o.threads = 2;
    const CheckReport r = check_mesh(mesh, o);
    ASSERT_EQ(r.elements.size(), elements.size());
    BoundsWorkspace ws;
    for (std::size_t e = 0; e < elements.size(); ++e) {
      const JacobianBounds g = jacobian_bounds(type, elements[e], BoundsOptions{}, ws);
      const ElementCheck& ec = r.elements[e];
      ASSERT_TRUE(ec.analysed);
      EXPECT_EQ(ec.bounds.validity, g.validity) << type.name << " element " << e;
      // both are certified: their ranges for min J must overlap
      EXPECT_LE(ec.bounds.jmin_lower, g.jmin_upper);
      EXPECT_LE(g.jmin_lower, ec.bounds.jmin_upper);
    }
  }
}

}  // namespace
}  // namespace quadval
