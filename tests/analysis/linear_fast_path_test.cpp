// The first-order fast path (src/analysis/linear_jacobian.hpp) against oracles that share
// none of its code: J expanded exactly (GMP rationals) in monomials from the multilinear
// map, converted to Bernstein form by the textbook monomial-to-Bernstein rule; exact dense
// samples of J; and the general path (jacobian_bounds) for the validity answers.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

// Exact Bézier coefficients in the fast path's layout (hex i+3j+9k degree 2; quad a+2b
// degree 1; simplices the constant).
std::vector<mpq_class> exact_coefficients(const ElementType& type, const std::vector<double>& x) {
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
      const bool box = type.family == ElementFamily::hexahedron || type.family == ElementFamily::quadrangle;
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
    std::vector<double> soa(nv * 3 * kLinearChunk);
    for (std::size_t e = 0; e < count; ++e)
      for (std::size_t v = 0; v < nv; ++v)
        for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearChunk + e] = elements[first + e][v * 3 + a];
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
      if (dense_every > 0 && (first + e) % static_cast<std::size_t>(dense_every) == 0) {
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
    std::vector<double> soa(8 * 3 * kLinearChunk);
    const auto ref = reference_nodes(type);
    for (std::size_t v = 0; v < 8; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearChunk] = scale * ref[v][a];
    JacobianBounds b;
    bool decided[1] = {true};
    linear_validity_chunk(LinearKind::hexahedron, soa.data(), 1, &b, decided);
    EXPECT_FALSE(decided[0]) << scale;
  }
  // Non-finite coordinates are never decided either.
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<double> soa(8 * 3 * kLinearChunk);
    const auto ref = reference_nodes(type);
    for (std::size_t v = 0; v < 8; ++v)
      for (std::size_t a = 0; a < 3; ++a) soa[(v * 3 + a) * kLinearChunk] = ref[v][a];
    soa[(6 * 3 + 1) * kLinearChunk] = bad;
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

// check_mesh (fast path + general fallback) answers exactly as the general path per element.
TEST(LinearFastPath, CheckMeshAgreesWithGeneralPathPerElement) {
  std::mt19937 rng(31);
  for (int id : {5, 4}) {
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
