// The midpoint probe (src/analysis/midpoint_probe.hpp) against exact rational evaluation of
// the Bernstein polynomial at the points, enumerated here on their own (barycentric
// coordinates of each factor's vertices and edge midpoints, multinomial weights in GMP),
// and a hand-made element that the probe decides without a subdivision.
#include "analysis/midpoint_probe.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "quadval/element_type.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {
namespace {

// A point of one factor in barycentric coordinates, and whether it is a vertex.
struct BaryPoint {
  std::array<mpq_class, 4> lambda;
  bool vertex;
};

std::vector<BaryPoint> factor_points(int dim) {
  std::vector<BaryPoint> out;
  for (int a = 0; a <= dim; ++a) {
    BaryPoint p{{0, 0, 0, 0}, true};
    p.lambda[static_cast<std::size_t>(a)] = 1;
    out.push_back(p);
  }
  for (int a = 0; a <= dim; ++a)
    for (int b = a + 1; b <= dim; ++b) {
      BaryPoint p{{0, 0, 0, 0}, false};
      p.lambda[static_cast<std::size_t>(a)] = mpq_class(1, 2);
      p.lambda[static_cast<std::size_t>(b)] = mpq_class(1, 2);
      out.push_back(p);
    }
  return out;
}

// B_alpha(lambda) = n! / prod alpha_k! * prod lambda_k^alpha_k, exactly.
mpq_class bernstein(const std::array<int, 4>& alpha, int dim, const std::array<mpq_class, 4>& lambda) {
  mpz_class num = 1;
  int n = 0;
  for (int k = 0; k <= dim; ++k) n += alpha[static_cast<std::size_t>(k)];
  for (int k = 2; k <= n; ++k) num *= k;
  mpq_class value = num;
  for (int k = 0; k <= dim; ++k) {
    const int a = alpha[static_cast<std::size_t>(k)];
    mpz_class f = 1;
    for (int j = 2; j <= a; ++j) f *= j;
    value /= mpq_class(f);
    for (int j = 0; j < a; ++j) value *= lambda[static_cast<std::size_t>(k)];
  }
  return value;
}

// The exact least value of sum_i c_i B_i over the probe points of the basis.
mpq_class exact_least(const BezierBasis& basis, const std::vector<double>& c) {
  const auto factors = basis.factors();
  std::vector<std::vector<BaryPoint>> points;
  for (const BernsteinSimplex* f : factors) points.push_back(factor_points(f->dim()));
  bool first = true;
  mpq_class least;
  std::array<std::size_t, 3> pick{0, 0, 0};
  for (;;) {
    bool all_vertices = true;
    for (std::size_t f = 0; f < factors.size(); ++f) all_vertices = all_vertices && points[f][pick[f]].vertex;
    if (!all_vertices) {
      mpq_class value = 0;
      for (int i = 0; i < basis.size(); ++i) {
        mpq_class w = c[static_cast<std::size_t>(i)];
        for (std::size_t f = 0; f < factors.size(); ++f) {
          const auto& alpha = factors[f]->multi_indices()[static_cast<std::size_t>(basis.factor_index(i, static_cast<int>(f)))];
          w *= bernstein(alpha, factors[f]->dim(), points[f][pick[f]].lambda);
        }
        value += w;
      }
      if (first || value < least) least = value;
      first = false;
    }
    std::size_t f = 0;
    while (f < factors.size() && ++pick[f] == points[f].size()) pick[f++] = 0;
    if (f == factors.size()) break;
  }
  EXPECT_FALSE(first) << "no probe point";
  return least;
}

TEST(MidpointProbe, BoundsTheExactLeastValueSharply) {
  std::mt19937 rng(20261203);
  std::uniform_real_distribution<double> u(-1, 1);
  int bases = 0;
  for (ElementFamily family : {ElementFamily::line, ElementFamily::triangle, ElementFamily::quadrangle,
                               ElementFamily::tetrahedron, ElementFamily::prism, ElementFamily::hexahedron})
    for (int order = 1; order <= 3; ++order) {
      const BezierBasis& basis = bezier_basis(family, order);
      SCOPED_TRACE(std::to_string(static_cast<int>(family)) + " order " + std::to_string(order));
      ++bases;
      for (int trial = 0; trial < 20; ++trial) {
        std::vector<double> c(static_cast<std::size_t>(basis.size()));
        for (double& x : c) x = u(rng) + (trial % 2 == 0 ? 0.5 : 0.0);
        const double err = trial % 3 == 0 ? 0.0 : 1e-9;
        const double probe = midpoint_probe_upper(basis, c.data(), err);
        const mpq_class least = exact_least(basis, c) + mpq_class(err);
        EXPECT_GE(mpq_class(probe), least) << "trial " << trial;  // a true upper bound
        // and a sharp one: the rounding's bound, and 1% on err
        EXPECT_LE(probe - least.get_d(), 1e-12 + 0.02 * err) << "trial " << trial;
      }
    }
  EXPECT_EQ(bases, 18);
}

// A quadratic quadrangle on [0, 2]^2 whose bottom midside node is pulled up to (1, 1.2).
// By hand, in Gmsh's coordinates on [-1, 1]^2: J = 1 at the four corners (x_xi = (1, +-2.4)
// at the bottom ones, x_eta = (0, 1)), but at the bottom edge's midpoint x_xi = (1, 0) and
// x_eta = (0, -0.8), so J = -0.8 there.
TEST(MidpointProbe, DecidesAnElementInvalidAtAnEdgeMidpointWithoutSubdividing) {
  const ElementType& quad9 = *find_element_type(ElementFamily::quadrangle, 2, true);
  const std::vector<double> x = {0, 0, 0,   2, 0, 0, 2, 2, 0,   0, 2, 0,  // corners
                                 1, 1.2, 0, 2, 1, 0, 1, 2, 0,   0, 1, 0,  // edge midpoints
                                 1, 1, 0};                                // centre
  BoundsWorkspace ws;
  const JacobianBounds b = jacobian_bounds(quad9, x, BoundsOptions{}, ws, /*planar=*/true);
  EXPECT_EQ(b.validity, Validity::invalid);
  EXPECT_EQ(b.subdivisions, 0);
  EXPECT_EQ(b.stage, 0);
  EXPECT_LE(b.jmin_upper, -0.8 + 1e-12);  // J there, in Gmsh's coordinates on [-1, 1]^2
  EXPECT_LE(b.jmin_lower, -0.8);
}

}  // namespace
}  // namespace quadval
