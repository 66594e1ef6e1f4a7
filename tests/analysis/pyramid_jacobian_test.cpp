// Jacobian bounds of curved pyramids (thesis Paper IV), checked against oracles that share
// no code with the Bézier pipeline: Bergot's shape functions of lagrange_basis.hpp (dense
// sampling), exact rationals written here from the definition of Bergot's space (eq. 2),
// closed forms (affine pyramids), and Gmsh 4.8.4's answers on the warped pyramid meshes.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "analysis/jacobian_engine.hpp"
#include "analysis/jacobian_space.hpp"
#include "bezier/pyramid_basis.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/io.hpp"
#include "quadval/jacobian_bounds.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

std::vector<const ElementType*> pyramid_types(int max_order) {
  std::vector<const ElementType*> out;
  for (const ElementType& t : element_types())
    if (t.family == ElementFamily::pyramid && t.has_lagrange_basis && t.order >= 1 && t.order <= max_order)
      out.push_back(&t);
  return out;
}

// Points of Gmsh's reference pyramid, never the apex: a cube grid (u, v, t), t >= 1/m,
// random points, and points approaching the apex along rays (t down to 1e-4).
std::vector<RefPoint> pyramid_points(int m, int random_count, std::mt19937& rng) {
  std::vector<RefPoint> pts;
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= m; ++j)
      for (int k = 1; k <= m; ++k) pts.push_back(pyramid_cube_to_gmsh(double(i) / m, double(j) / m, double(k) / m));
  for (int r = 0; r < random_count; ++r) pts.push_back(pyramid_cube_to_gmsh(u(rng), u(rng), 1e-4 + u(rng)));
  for (double t : {1e-2, 1e-3, 1e-4})
    for (int i = 0; i <= 2; ++i)
      for (int j = 0; j <= 2; ++j) pts.push_back(pyramid_cube_to_gmsh(i / 2.0, j / 2.0, t));
  return pts;
}

double sampled_min(const ElementType& type, const std::vector<double>& x, const std::vector<RefPoint>& pts) {
  const LagrangeBasis& lb = lagrange_basis(type);
  double m = INFINITY;
  for (const RefPoint& p : pts) m = std::min(m, test::jacobian_at(lb, x, p, false));
  return m;
}

TEST(PyramidJacobian, CubeMapMatchesGmshReferencePyramid) {
  const auto v = reference_vertices(ElementFamily::pyramid);
  ASSERT_EQ(v.size(), 5u);
  // Base corners of the cube face t = 1 are Gmsh's vertices 0..3; t = 0 is the apex.
  const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int c = 0; c < 4; ++c) {
    const auto g = pyramid_cube_to_gmsh(corners[c][0], corners[c][1], 1);
    for (int d = 0; d < 3; ++d) EXPECT_EQ(g[static_cast<std::size_t>(d)], v[static_cast<std::size_t>(c)][static_cast<std::size_t>(d)]) << c;
  }
  const auto apex = pyramid_cube_to_gmsh(0.3, 0.9, 0);
  for (int d = 0; d < 3; ++d) EXPECT_EQ(apex[static_cast<std::size_t>(d)], v[4][static_cast<std::size_t>(d)]);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 100; ++i) {
    const double a = u(rng), b = u(rng), t = 0.01 + 0.99 * u(rng);
    const auto g = pyramid_cube_to_gmsh(a, b, t);
    EXPECT_LE(std::abs(g[0]), 1 - g[2] + 1e-15);  // inside Gmsh's pyramid
    EXPECT_LE(std::abs(g[1]), 1 - g[2] + 1e-15);
    const auto c = pyramid_gmsh_to_cube(g[0], g[1], g[2]);
    EXPECT_NEAR(c[0], a, 1e-13);
    EXPECT_NEAR(c[1], b, 1e-13);
    EXPECT_NEAR(c[2], t, 1e-15);
  }
  EXPECT_EQ(pyramid_generalized_size(2), 1 * 7 * 13 - 5);  // r/2 (3r+1)(6r+1) - 5
  EXPECT_EQ(pyramid_generalized_size(3), 3 * 10 * 19 / 2 - 5);
}

// Every pyramid type Gmsh defines (5, 13, 14 nodes, ids 118-131): the functions
// interpolate, sum to 1, and an affinely placed pyramid has J = det(A) everywhere.
TEST(PyramidJacobian, ShapeFunctionsOfEveryPyramidTypeReproduceAffineMaps) {
  const auto types = pyramid_types(9);
  EXPECT_EQ(types.size(), 3u + 14u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const ElementType* type : types) {
    SCOPED_TRACE(std::string(type->name));
    const LagrangeBasis& lb = lagrange_basis(*type);
    const auto nodes = reference_nodes(*type);
    const auto n = static_cast<std::size_t>(type->num_nodes);
    std::vector<double> val(n);
    for (std::size_t j = 0; j < n; ++j) {
      lb.evaluate(nodes[j], val);
      for (std::size_t i = 0; i < n; ++i) ASSERT_NEAR(val[i], i == j ? 1.0 : 0.0, 1e-7) << i << " at node " << j;
    }
    double a[3][3];
    for (auto& row : a)
      for (double& e : row) e = u(rng);
    a[0][0] += 2, a[1][1] += 2, a[2][2] += 2;
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    std::vector<double> x;
    for (const RefPoint& p : nodes)
      for (int i = 0; i < 3; ++i) x.push_back(a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2] + 5);
    for (const RefPoint& p : pyramid_points(3, 20, rng)) {
      lb.evaluate(p, val);
      double sum = 0;
      for (double v : val) sum += v;
      ASSERT_NEAR(sum, 1, 1e-8);
      ASSERT_NEAR(test::jacobian_at(lb, x, p, false), det, 1e-6 * std::abs(det));
    }
    // Every order is analysed (Bernstein products, no ill-conditioned conversion): the
    // bounds of an affine pyramid close on det(A), and the mirror image is invalid.
    ASSERT_TRUE(jacobian_bounds_supported(*type));
    BoundsWorkspace ws;
    BoundsOptions opt;
    opt.goal = BoundsGoal::measure;
    // Orders 5-9: the derivative maps' row sums (Lagrange derivatives of order up to 9,
    // ~1e4) scale the rounding bound to ~1e-5 |J| at order 9; ask what they can give.
    opt.rel_tol = type->order <= 4 ? 1e-6 : 1e-3;
    const JacobianBounds b = jacobian_bounds(*type, x, opt, ws);
    EXPECT_EQ(b.validity, Validity::valid);
    EXPECT_LE(b.jmin_lower, det);
    EXPECT_GE(b.jmin_upper, det);
    EXPECT_LE(b.jmax_lower, det);
    EXPECT_GE(b.jmax_upper, det);
    // The product path's rounding bound is ~1e-11 |J| up to order 4 (the sampled path's
    // was ~1e-4 |J| at orders 3-4: the conversion norm of degree-8..11 factors, cubed).
    EXPECT_TRUE(b.tolerance_met);
    const double gap = type->order <= 4 ? 1e-6 : 1e-3;
    EXPECT_LT(b.jmin_upper - b.jmin_lower, gap * det);
    EXPECT_LT(b.jmax_upper - b.jmax_lower, gap * det);
    for (std::size_t i = 0; i < x.size(); i += 3) x[i] = -x[i];
    EXPECT_EQ(jacobian_bounds(*type, x, opt, ws).validity, Validity::invalid);
  }
}

// Thousands of random curved pyramids of orders 1 to 4: no sampled J below the lower
// bound, and the gap within the tolerance asked.
TEST(PyramidJacobian, DenseSamplingNeverBelowTheLowerBound) {
  std::mt19937 rng(11);
  int total = 0, valid = 0, invalid = 0;
  for (const ElementType* type : pyramid_types(4)) {
    SCOPED_TRACE(std::string(type->name));
    const int count = type->order <= 2 ? 700 : type->order == 3 ? 40 : 10;
    const auto pts = pyramid_points(type->order <= 2 ? 6 : 4, 40, rng);
    BoundsWorkspace ws;
    BoundsOptions opt;
    opt.goal = BoundsGoal::measure;
    opt.rel_tol = 1e-3;
    opt.max_subdivisions = 4000;
    for (int e = 0; e < count; ++e) {
      const double amplitude = 0.05 + 0.3 * (e % 5) / 4.0;
      const auto x = test::random_element(*type, amplitude, rng);
      const JacobianBounds b = jacobian_bounds(*type, x, opt, ws);
      const double smin = sampled_min(*type, x, pts);
      const double scale = std::max(std::abs(b.jmax_upper), std::abs(b.jmin_lower));
      ASSERT_GE(smin, b.jmin_lower - 1e-12 * scale) << e;
      ASSERT_NE(b.validity, Validity::undetermined) << e;
      if (smin <= 0) { ASSERT_EQ(b.validity, Validity::invalid) << e; }
      if (b.validity == Validity::valid) { ASSERT_GT(b.jmin_lower, 0) << e; }
      // Met at every order: the coefficients' rounding (~1e-12 |J|) no longer limits it.
      ASSERT_TRUE(b.tolerance_met) << e;
      const double tol = opt.rel_tol * std::max(std::abs(b.jmin_upper), std::abs(b.jmax_lower));
      ASSERT_LE(b.jmin_upper - b.jmin_lower, tol * (1 + 1e-9)) << e;
      // The sampled minimum is within reach of the bounds (sampling is coarse near the
      // minimum, so allow 5% of |J|): catches bounds that are true but useless.
      if (type->order <= 2) { ASSERT_LE(smin - b.jmin_upper, 0.05 * scale) << e; }
      ++total;
      (b.validity == Validity::valid ? valid : invalid)++;
    }
  }
  std::cout << total << " random pyramids: " << valid << " valid, " << invalid << " invalid\n";
  EXPECT_GT(valid, 100);
  EXPECT_GT(invalid, 100);
}

// A smooth random warp of the reference pyramid, x + a sin(w . x + phi) per coordinate:
// curved like meshed geometry at every order (independent noise on the nodes of an
// order-9 element makes it invalid at any visible amplitude).
std::vector<double> warped_pyramid(const ElementType& type, double amplitude, std::mt19937& rng) {
  std::uniform_real_distribution<double> w(-2, 2), phase(0, 6.283);
  double k[3][3], ph[3];
  for (int c = 0; c < 3; ++c) {
    for (double& x : k[c]) x = w(rng);
    ph[c] = phase(rng);
  }
  std::vector<double> x;
  for (const RefPoint& p : reference_nodes(type))
    for (int c = 0; c < 3; ++c)
      x.push_back(p[static_cast<std::size_t>(c)] +
                  amplitude * std::sin(k[c][0] * p[0] + k[c][1] * p[1] + k[c][2] * p[2] + ph[c]));
  return x;
}

// Orders 5 to 9 (Gmsh ids 120-124, 127-131), complete and incomplete: the same guarantees
// against J sampled from lagrange_basis (Bergot's shape functions, not our Bézier code).
TEST(PyramidJacobian, HighOrdersDenseSamplingNeverBelowTheLowerBound) {
  std::mt19937 rng(13);
  int valid = 0, invalid = 0;
  for (const ElementType* type : pyramid_types(9)) {
    if (type->order < 5) continue;
    SCOPED_TRACE(std::string(type->name));
    const auto pts = pyramid_points(5, 60, rng);
    BoundsWorkspace ws;
    BoundsOptions opt;
    opt.goal = BoundsGoal::measure;
    opt.rel_tol = 1e-3;
    opt.max_subdivisions = 4000;
    const int count = type->num_nodes > 200 ? 4 : 10;
    for (int e = 0; e < count; ++e) {
      const auto x = warped_pyramid(*type, 0.05 + 0.4 * (e % 5) / 4.0, rng);
      const JacobianBounds b = jacobian_bounds(*type, x, opt, ws);
      const double smin = sampled_min(*type, x, pts);
      const double scale = std::max(std::abs(b.jmax_upper), std::abs(b.jmin_lower));
      ASSERT_GE(smin, b.jmin_lower - 1e-12 * scale) << e;
      ASSERT_NE(b.validity, Validity::undetermined) << e;
      if (smin <= 0) { ASSERT_EQ(b.validity, Validity::invalid) << e; }
      if (b.validity == Validity::valid) { ASSERT_GT(b.jmin_lower, 0) << e; }
      ASSERT_TRUE(b.tolerance_met) << e;
      const double tol = opt.rel_tol * std::max(std::abs(b.jmin_upper), std::abs(b.jmax_lower));
      ASSERT_LE(b.jmin_upper - b.jmin_lower, tol * (1 + 1e-9)) << e;
      ASSERT_LE(smin - b.jmin_upper, 0.05 * scale) << e;
      (b.validity == Validity::valid ? valid : invalid)++;
    }
  }
  std::cout << "orders 5-9: " << valid << " valid, " << invalid << " invalid\n";
  EXPECT_GT(valid, 10);
  EXPECT_GT(invalid, 10);
}

// ---- Exact oracle: Bergot's space written in pyramid coordinates, phi = xi^a eta^b
// (1-zeta)^(k-a-b) for a, b <= k (Paper IV eq. 2 with Gmsh's xi = X (1-zeta)); the
// 13-node pyramid drops (2, 2, 2) (lagrange_basis.hpp).
struct ExactPyramid {
  std::vector<std::array<int, 3>> exps;
  std::vector<mpq_class> coef;  // N_i = sum_j phi_j coef[j * n + i]
};

mpq_class qpow(const mpq_class& x, int e) {
  mpq_class r = 1;
  if (e < 0) {
    for (int i = 0; i < -e; ++i) r /= x;
    return r;
  }
  for (int i = 0; i < e; ++i) r *= x;
  return r;
}

mpq_class phi(const std::array<int, 3>& e, const mpq_class& xi, const mpq_class& eta, const mpq_class& zeta) {
  const mpq_class t = 1 - zeta;
  if (sgn(t) == 0) return e[2] == 0 ? 1 : 0;
  return qpow(xi, e[0]) * qpow(eta, e[1]) * qpow(t, e[2] - e[0] - e[1]);
}

ExactPyramid exact_pyramid(const ElementType& type) {
  ExactPyramid p;
  for (int k = 0; k <= type.order; ++k)
    for (int a = 0; a <= k; ++a)
      for (int b = 0; b <= k; ++b)
        if (!(type.num_nodes == 13 && a == 2 && b == 2)) p.exps.push_back({a, b, k});
  const auto nodes = reference_nodes(type);
  const std::size_t n = nodes.size();
  EXPECT_EQ(p.exps.size(), n);
  const auto q = [](double x) { mpq_class r(x); return r; };  // nodes are dyadic (halves)
  std::vector<mpq_class> v(n * n), inv(n * n, mpq_class(0));
  for (std::size_t i = 0; i < n; ++i) {
    inv[i * n + i] = 1;
    for (std::size_t j = 0; j < n; ++j) v[i * n + j] = phi(p.exps[j], q(nodes[i][0]), q(nodes[i][1]), q(nodes[i][2]));
  }
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t r = c;
    while (sgn(v[r * n + c]) == 0) ++r;
    for (std::size_t k = 0; k < n; ++k) std::swap(v[r * n + k], v[c * n + k]), std::swap(inv[r * n + k], inv[c * n + k]);
    const mpq_class pv = v[c * n + c];
    for (std::size_t k = 0; k < n; ++k) v[c * n + k] /= pv, inv[c * n + k] /= pv;
    for (std::size_t r2 = 0; r2 < n; ++r2)
      if (r2 != c) {
        const mpq_class f = v[r2 * n + c];
        for (std::size_t k = 0; k < n; ++k) v[r2 * n + k] -= f * v[c * n + k], inv[r2 * n + k] -= f * inv[c * n + k];
      }
  }
  p.coef = std::move(inv);
  return p;
}

// Exact J at (xi, eta, zeta), zeta < 1: derivatives of xi^a eta^b t^m (m = k - a - b).
mpq_class exact_jacobian(const ExactPyramid& p, const std::vector<mpq_class>& x, const mpq_class& xi,
                         const mpq_class& eta, const mpq_class& zeta) {
  const std::size_t n = p.exps.size();
  const mpq_class t = 1 - zeta;
  mpq_class d[3][3];
  for (std::size_t j = 0; j < n; ++j) {
    const int a = p.exps[j][0], b = p.exps[j][1], m = p.exps[j][2] - a - b;
    const mpq_class gx = a == 0 ? mpq_class(0) : a * qpow(xi, a - 1) * qpow(eta, b) * qpow(t, m);
    const mpq_class gy = b == 0 ? mpq_class(0) : b * qpow(xi, a) * qpow(eta, b - 1) * qpow(t, m);
    const mpq_class gz = m == 0 ? mpq_class(0) : -m * qpow(xi, a) * qpow(eta, b) * qpow(t, m - 1);
    for (std::size_t i = 0; i < n; ++i) {
      const mpq_class& c = p.coef[j * n + i];
      if (sgn(c) == 0) continue;
      for (int k = 0; k < 3; ++k) {
        const mpq_class& xk = x[3 * i + static_cast<std::size_t>(k)];
        d[0][k] += c * gx * xk;
        d[1][k] += c * gy * xk;
        d[2][k] += c * gz * xk;
      }
    }
  }
  return d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
         d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
}

// Small random pyramids (coordinates multiples of 1/64) of orders 1, 2 and 4 (dyadic nodes): the
// floating-point bounds contain the exact values of J on a rational lattice reaching
// down to t = 1/64 near the apex, and the verdict agrees with them.
TEST(PyramidJacobian, FloatingPointBoundsContainExactValues) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> jitter(-12, 12);
  std::vector<std::array<mpq_class, 3>> lattice;
  for (int tt : {64, 48, 32, 16, 8, 1})
    for (int a = -2; a <= 2; ++a)
      for (int b = -2; b <= 2; ++b) {
        const mpq_class t(tt, 64);
        lattice.push_back({mpq_class(a, 2) * t, mpq_class(b, 2) * t, 1 - t});
      }
  for (auto& p : lattice)
    for (auto& c : p) c.canonicalize();
  std::vector<const ElementType*> types = pyramid_types(2);
  types.push_back(find_element_type(ElementFamily::pyramid, 4, true));  // nodes on 1/4: exact
  for (const ElementType* type : types) {
    SCOPED_TRACE(std::string(type->name));
    const ExactPyramid ep = exact_pyramid(*type);
    BoundsWorkspace ws;
    for (int e = 0; e < (type->order == 4 ? 3 : 60); ++e) {
      std::vector<double> x;
      for (const RefPoint& p : reference_nodes(*type))
        for (int k = 0; k < 3; ++k) x.push_back(std::round(64 * p[static_cast<std::size_t>(k)] * 2) / 64 + jitter(rng) * (e % 3 + 1) / 64.0);
      std::vector<mpq_class> xq(x.begin(), x.end());
      mpq_class emin = exact_jacobian(ep, xq, lattice[0][0], lattice[0][1], lattice[0][2]), emax = emin;
      for (const auto& p : lattice) {
        const mpq_class j = exact_jacobian(ep, xq, p[0], p[1], p[2]);
        if (j < emin) emin = j;
        if (j > emax) emax = j;
      }
      for (BoundsGoal goal : {BoundsGoal::validity, BoundsGoal::measure}) {
        BoundsOptions opt;
        opt.goal = goal;
        const JacobianBounds b = jacobian_bounds(*type, x, opt, ws);
        ASSERT_LE(mpq_class(b.jmin_lower), emin) << e;
        ASSERT_GE(mpq_class(b.jmax_upper), emax) << e;
        if (goal == BoundsGoal::measure) { ASSERT_GE(mpq_class(b.jmax_upper), mpq_class(b.jmax_lower)); }
        if (sgn(emin) <= 0) { ASSERT_EQ(b.validity, Validity::invalid) << e; }
        if (b.validity == Validity::valid) { ASSERT_GT(b.jmin_lower, 0) << e; }
      }
    }
  }
}

// J = 0 exactly at a base corner (vertices 1, 2, 3 collinear): rounding cannot decide
// the sign, so the exact fallback must, and J <= 0 there means invalid.
TEST(PyramidJacobian, ZeroAtACornerIsInvalidByExactArithmetic) {
  const ElementType& type = *find_element_type(ElementFamily::pyramid, 1, true);
  const std::vector<double> x = {0, 0, 0, 2, 0, 0, 1, 1, 0, 0, 2, 0, 0.5, 0.5, 1};
  const ExactPyramid ep = exact_pyramid(type);
  std::vector<mpq_class> xq(x.begin(), x.end());
  EXPECT_EQ(sgn(exact_jacobian(ep, xq, 1, 1, 0)), 0);  // the oracle agrees: J(corner 2) = 0
  EXPECT_GT(exact_jacobian(ep, xq, 0, 0, 0), 0);
  BoundsWorkspace ws;
  const JacobianBounds b = jacobian_bounds(type, x, BoundsOptions{}, ws);
  EXPECT_EQ(b.validity, Validity::invalid);
  EXPECT_LE(b.jmin_lower, 0);
  EXPECT_GE(b.jmin_upper, 0);
}

// ---- The generalized basis of eq. (4) against the enriched basis of eq. (6), exactly.
// J of an order-r pyramid, written in cube coordinates as sum_k B^n_k(t) P_k(u, v)
// (n = 3r-3), has its generalized coefficients g_ijk = Bernstein coefficients of P_k in
// degree k+2 and its enriched ones e_lmk = those of P_k in degree 3r-1 (the same P_k:
// both bases share the t factor). Degree elevation makes every e a convex combination of
// the g of its slice, with the corners equal, so min e >= min g and max e <= max g: eq. 4
// never settles a sign the enriched coefficients leave open. Here P_k comes from the
// exact oracle (tensor interpolation of exact J values), nothing from the Bézier code.
struct PyramidBases {
  int r = 0;
  std::vector<std::vector<mpq_class>> generalized;  // [k][i + (k+3) j]
  std::vector<mpq_class> enriched;                  // l + N (m + N k), N = 3r
  bool in_eq4_space = true;                         // deg P_k <= k+2 in u and in v
};

mpz_class binom(int n, int k) {
  if (k < 0 || k > n) return 0;
  mpz_class b;
  mpz_bin_uiui(b.get_mpz_t(), static_cast<unsigned long>(n), static_cast<unsigned long>(k));
  return b;
}

// Inverse of the Vandermonde matrix of the points (row: monomial power, column: point).
std::vector<mpq_class> inverse_vandermonde(const std::vector<mpq_class>& x) {
  const std::size_t n = x.size();
  std::vector<mpq_class> v(n * n), inv(n * n, mpq_class(0));
  for (std::size_t i = 0; i < n; ++i) {
    inv[i * n + i] = 1;
    for (std::size_t p = 0; p < n; ++p) v[i * n + p] = qpow(x[i], static_cast<int>(p));
  }
  for (std::size_t c = 0; c < n; ++c) {  // Gauss-Jordan on rows (points)
    const mpq_class pv = v[c * n + c];
    for (std::size_t k = 0; k < n; ++k) v[c * n + k] /= pv, inv[c * n + k] /= pv;
    for (std::size_t r2 = 0; r2 < n; ++r2)
      if (r2 != c) {
        const mpq_class f = v[r2 * n + c];
        if (sgn(f) == 0) continue;
        for (std::size_t k = 0; k < n; ++k) v[r2 * n + k] -= f * v[c * n + k], inv[r2 * n + k] -= f * inv[c * n + k];
      }
  }
  return inv;  // monomial coefficient p = sum_i inv[p * n + i] value_i
}

// Monomial coefficients m[a] (a <= deg) to Bernstein degree p: u^a = sum_i C(i,a)/C(p,a) B^p_i.
std::vector<mpq_class> to_bernstein(const std::vector<mpq_class>& m, int p) {
  std::vector<mpq_class> b(static_cast<std::size_t>(p + 1), mpq_class(0));
  for (std::size_t a = 0; a < m.size(); ++a) {
    if (sgn(m[a]) == 0) continue;
    const int ai = static_cast<int>(a);
    EXPECT_LE(ai, p);
    for (int i = ai; i <= p; ++i) b[static_cast<std::size_t>(i)] += m[a] * mpq_class(binom(i, ai), binom(p, ai));
  }
  for (auto& q : b) q.canonicalize();
  return b;
}

PyramidBases pyramid_bases(const ElementType& type, const std::vector<mpq_class>& xq) {
  PyramidBases out;
  const int r = type.order, N = 3 * r, nt = 3 * r - 2;  // points per axis (degrees N-1, nt-1)
  out.r = r;
  const ExactPyramid ep = exact_pyramid(type);
  std::vector<mpq_class> uu(static_cast<std::size_t>(N)), tt(static_cast<std::size_t>(nt));
  for (int i = 0; i < N; ++i) uu[static_cast<std::size_t>(i)] = mpq_class(i, N - 1), uu[static_cast<std::size_t>(i)].canonicalize();
  for (int k = 0; k < nt; ++k) tt[static_cast<std::size_t>(k)] = mpq_class(k + 1, nt), tt[static_cast<std::size_t>(k)].canonicalize();
  const auto iu = inverse_vandermonde(uu), it = inverse_vandermonde(tt);
  const auto idx = [N](int a, int b, int c) { return static_cast<std::size_t>(a + N * (b + N * c)); };
  std::vector<mpq_class> val(static_cast<std::size_t>(N * N * nt));
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j)
      for (int k = 0; k < nt; ++k) {
        const mpq_class& t = tt[static_cast<std::size_t>(k)];
        val[idx(i, j, k)] = exact_jacobian(ep, xq, (2 * uu[static_cast<std::size_t>(i)] - 1) * t,
                                           (2 * uu[static_cast<std::size_t>(j)] - 1) * t, 1 - t);
      }
  // values -> monomials in u, then v (inverse Vandermonde), then t -> Bernstein degree nt-1
  std::vector<mpq_class> m1(val.size()), m2(val.size());
  for (int a = 0; a < N; ++a)
    for (int j = 0; j < N; ++j)
      for (int k = 0; k < nt; ++k)
        for (int i = 0; i < N; ++i) m1[idx(a, j, k)] += iu[static_cast<std::size_t>(a * N + i)] * val[idx(i, j, k)];
  for (int a = 0; a < N; ++a)
    for (int b = 0; b < N; ++b)
      for (int k = 0; k < nt; ++k)
        for (int j = 0; j < N; ++j) m2[idx(a, b, k)] += iu[static_cast<std::size_t>(b * N + j)] * m1[idx(a, j, k)];
  std::vector<mpq_class> pk(val.size());  // P_k: monomial (a, b), Bernstein index k in t
  for (int a = 0; a < N; ++a)
    for (int b = 0; b < N; ++b) {
      std::vector<mpq_class> mono(static_cast<std::size_t>(nt), mpq_class(0));
      for (int c = 0; c < nt; ++c)
        for (int k = 0; k < nt; ++k) mono[static_cast<std::size_t>(c)] += it[static_cast<std::size_t>(c * nt + k)] * m2[idx(a, b, k)];
      const auto bern = to_bernstein(mono, nt - 1);
      for (int k = 0; k < nt; ++k) pk[idx(a, b, k)] = bern[static_cast<std::size_t>(k)];
    }
  out.enriched.assign(val.size(), mpq_class(0));
  for (int k = 0; k < nt; ++k) {
    const int p = k + 2;
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b)
        if ((a > p || b > p) && sgn(pk[idx(a, b, k)]) != 0) out.in_eq4_space = false;
    // Bernstein in u then v, of degree d, of the slice's monomials
    const auto slice_bernstein = [&](int d) {
      const auto D = static_cast<std::size_t>(d + 1);
      std::vector<mpq_class> tmp(D * static_cast<std::size_t>(N)), res(D * D);
      for (int b = 0; b < N; ++b) {
        std::vector<mpq_class> mono(static_cast<std::size_t>(std::min(N, d + 1)));
        for (std::size_t a = 0; a < mono.size(); ++a) mono[a] = pk[idx(static_cast<int>(a), b, k)];
        const auto bu = to_bernstein(mono, d);
        for (std::size_t i = 0; i < D; ++i) tmp[i + D * static_cast<std::size_t>(b)] = bu[i];
      }
      for (std::size_t i = 0; i < D; ++i) {
        std::vector<mpq_class> mono(static_cast<std::size_t>(std::min(N, d + 1)));
        for (std::size_t b = 0; b < mono.size(); ++b) mono[b] = tmp[i + D * b];
        const auto bv = to_bernstein(mono, d);
        for (std::size_t j = 0; j < D; ++j) res[i + D * j] = bv[j];
      }
      return res;
    };
    out.generalized.push_back(slice_bernstein(p));
    const auto e = slice_bernstein(N - 1);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) out.enriched[idx(i, j, k)] = e[static_cast<std::size_t>(i + N * j)];
  }
  return out;
}

mpq_class bernstein(int n, int i, const mpq_class& x) {
  return mpq_class(binom(n, i)) * qpow(x, i) * qpow(1 - x, n - i);
}

struct LevelZero {
  int elements = 0, enriched_valid = 0, generalized_valid = 0, corner_invalid = 0;
  int sharper_min = 0;  // elements with min e > min g
};

// One element: both expansions reproduce J exactly at random rational points; the
// enriched coefficients lie in the convex hull of the generalized ones, corners equal.
void compare_bases(const ElementType& type, const std::vector<double>& x, std::mt19937& rng, LevelZero& tally) {
  const std::vector<mpq_class> xq(x.begin(), x.end());
  const PyramidBases pb = pyramid_bases(type, xq);
  ASSERT_TRUE(pb.in_eq4_space);  // J in the space of eq. (4): deg P_k <= k+2
  const int N = 3 * pb.r, n = 3 * pb.r - 3;
  const ExactPyramid ep = exact_pyramid(type);
  std::uniform_int_distribution<int> num(1, 96);
  for (int s = 0; s < 3; ++s) {
    const mpq_class u(num(rng), 97), v(num(rng), 97), t(num(rng), 97);
    const mpq_class want = exact_jacobian(ep, xq, (2 * u - 1) * t, (2 * v - 1) * t, 1 - t);
    mpq_class g = 0, e = 0;
    for (int k = 0; k <= n; ++k) {
      const mpq_class bt = bernstein(n, k, t);
      for (int i = 0; i <= k + 2; ++i)
        for (int j = 0; j <= k + 2; ++j)
          g += pb.generalized[static_cast<std::size_t>(k)][static_cast<std::size_t>(i + (k + 3) * j)] *
               bernstein(k + 2, i, u) * bernstein(k + 2, j, v) * bt;
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j)
          e += pb.enriched[static_cast<std::size_t>(i + N * (j + N * k))] * bernstein(N - 1, i, u) * bernstein(N - 1, j, v) * bt;
    }
    ASSERT_EQ(g, want);
    ASSERT_EQ(e, want);
  }
  mpq_class gmin = pb.generalized[0][0], gmax = gmin, emin = pb.enriched[0], emax = emin;
  bool corner_nonpositive = false;
  for (int k = 0; k <= n; ++k) {
    const auto& gk = pb.generalized[static_cast<std::size_t>(k)];
    for (const mpq_class& c : gk) gmin = std::min(gmin, c), gmax = std::max(gmax, c);
    for (int i : {0, 1})
      for (int j : {0, 1}) {  // corners of the slice: the same in both bases
        const mpq_class& gc = gk[static_cast<std::size_t>(i * (k + 2) + (k + 3) * j * (k + 2))];
        ASSERT_EQ(gc, pb.enriched[static_cast<std::size_t>(i * (N - 1) + N * (j * (N - 1) + N * k))]);
        if ((k == 0 || k == n) && sgn(gc) <= 0) corner_nonpositive = true;  // J at a vertex or apex limit
      }
  }
  for (const mpq_class& c : pb.enriched) emin = std::min(emin, c), emax = std::max(emax, c);
  ASSERT_GE(emin, gmin);
  ASSERT_LE(emax, gmax);
  ++tally.elements;
  tally.enriched_valid += sgn(emin) > 0;
  tally.generalized_valid += sgn(gmin) > 0;
  tally.corner_invalid += corner_nonpositive;
  tally.sharper_min += emin > gmin;
}

// Random order-2 pyramids (14 and 13 nodes) on the 1/64 lattice.
TEST(PyramidJacobian, GeneralizedBasisOfEq4NeverSharperThanEnrichedAtLevelZero) {
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> jitter(-12, 12);
  LevelZero tally;
  for (const ElementType* type : pyramid_types(2)) {
    if (type->order < 2) continue;
    SCOPED_TRACE(std::string(type->name));
    const int count = 10;
    for (int e = 0; e < count; ++e) {
      std::vector<double> x;  // mild to strong curving: valid and invalid ones
      for (const RefPoint& p : reference_nodes(*type))
        for (int k = 0; k < 3; ++k) x.push_back(std::round(64 * p[static_cast<std::size_t>(k)]) / 64 + jitter(rng) * (e % 4) / 128.0);
      compare_bases(*type, x, rng, tally);
    }
  }
  std::cout << "level 0 on " << tally.elements << " random pyramids: min coefficient > 0 for " << tally.enriched_valid
            << " (enriched, eq. 6) vs " << tally.generalized_valid << " (generalized, eq. 4); enriched min sharper on "
            << tally.sharper_min << "; a corner <= 0 on " << tally.corner_invalid << "\n";
  EXPECT_LE(tally.generalized_valid, tally.enriched_valid);
  EXPECT_GT(tally.enriched_valid, 0);
}

using test::read_gmsh_ratios;

// Gmsh 4.8.4 on the warped pyramid meshes. Order 1: the same invalid set. Order 2: Gmsh
// calls almost every pyramid invalid with J_min = 0; we prove them valid (jmin_lower > 0),
// and dense sampling from the shape functions, down to 1e-4 from the apex, finds J above
// our lower bound and far from 0; the exact oracle agrees at rational points near the apex.
TEST(PyramidJacobian, GmshWarpedPyramidMeshes) {
  std::mt19937 rng(2);
  const auto pts = pyramid_points(6, 30, rng);
  for (const char* name : {"warped_pyramid_o1_N6_a0.1", "warped_pyramid_o2_N6_a0.15"}) {
    SCOPED_TRACE(name);
    const std::string base = std::string(QUADVAL_SHARED_DIR) + "/data/curved/" + name;
    const Mesh mesh = read_mesh(base + ".msh");
    const auto gmsh = read_gmsh_ratios(base + ".gmsh.csv");
    CheckOptions opts;
    opts.threads = 2;
    const CheckReport r = check_mesh(mesh, opts, base + ".msh");
    opts.threads = 1;
    EXPECT_EQ(check_csv(check_mesh(mesh, opts, base + ".msh")), check_csv(r));
    std::map<Tag, std::vector<double>> coords;
    for (const ElementBlock& b : mesh.blocks)
      for (std::size_t e = 0; e < b.size(); ++e) {
        std::vector<double> x = test::element_coordinates(mesh, b, e);
        coords[b.tags[e]] = std::move(x);
      }
    int agree = 0, gmsh_only = 0, checked_exact = 0;
    for (const ElementCheck& e : r.elements) {
      ASSERT_TRUE(e.analysed) << e.tag;
      ASSERT_NE(e.bounds.validity, Validity::undetermined) << e.tag;
      const bool gmsh_invalid = gmsh.at(e.tag) <= 0;
      const bool ours_invalid = e.bounds.validity == Validity::invalid;
      const auto& x = coords.at(e.tag);
      const double smin = sampled_min(*e.type, x, pts);
      EXPECT_GE(smin, e.bounds.jmin_lower) << e.tag;
      if (ours_invalid == gmsh_invalid) {
        ++agree;
        continue;
      }
      // Gmsh says invalid, we prove valid: J > 0 everywhere, including near the apex.
      ASSERT_FALSE(ours_invalid) << e.tag << ": we call it invalid, Gmsh valid";
      ASSERT_GT(e.bounds.jmin_lower, 0) << e.tag;
      ASSERT_GT(smin, 0) << e.tag;
      ++gmsh_only;
      if (checked_exact < 20 && e.type->order <= 2) {  // exact J at rational points near the apex
        const ExactPyramid ep = exact_pyramid(*e.type);
        std::vector<mpq_class> xq(x.begin(), x.end());
        for (int a = -1; a <= 1; ++a)
          for (int b = -1; b <= 1; ++b) {
            const mpq_class t(1, 1000000);
            const mpq_class j = exact_jacobian(ep, xq, a * t, b * t, 1 - t);
            ASSERT_GE(j, mpq_class(e.bounds.jmin_lower)) << e.tag;
          }
        ++checked_exact;
      }
    }
    std::cout << name << ": " << agree << " agree with Gmsh, " << gmsh_only
              << " called invalid by Gmsh only, proven valid here\n";
    if (std::string(name).find("_o1_") != std::string::npos) { EXPECT_EQ(gmsh_only, 0); }
  }
}

}  // namespace
}  // namespace quadval
