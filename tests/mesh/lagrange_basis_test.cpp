// Lagrange shape functions of every element type: Kronecker property, partition of unity,
// gradients against finite differences and closed forms, Gmsh 4.8.4's own values
// (tests/data/gmsh_lagrange_reference.json), face traces against the 2D elements.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "mesh/lagrange_test_data.hpp"
#include "mesh/polynomial_space.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval {
namespace {

using F = ElementFamily;

using testing_data::lagrange_types;

// Uniform-ish random points strictly inside the reference element (pyramid: zeta <= 0.9).
std::vector<RefPoint> random_points(F f, int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.02, 0.98);
  std::vector<RefPoint> out;
  while (static_cast<int>(out.size()) < n) {
    RefPoint x{u(gen), u(gen), u(gen)};
    switch (f) {
      case F::point: x = {0, 0, 0}; break;
      case F::line: x = {2 * x[0] - 1, 0, 0}; break;
      case F::quadrangle: x = {2 * x[0] - 1, 2 * x[1] - 1, 0}; break;
      case F::hexahedron: x = {2 * x[0] - 1, 2 * x[1] - 1, 2 * x[2] - 1}; break;
      case F::triangle:
        if (x[0] + x[1] >= 0.98) continue;
        x[2] = 0;
        break;
      case F::tetrahedron:
        if (x[0] + x[1] + x[2] >= 0.98) continue;
        break;
      case F::prism:
        if (x[0] + x[1] >= 0.98) continue;
        x[2] = 2 * x[2] - 1;
        break;
      case F::pyramid: {
        const double z = 0.9 * x[2];
        x = {(2 * x[0] - 1) * (1 - z), (2 * x[1] - 1) * (1 - z), z};
        break;
      }
      default: break;
    }
    out.push_back(x);
  }
  return out;
}

std::vector<double> values_at(const LagrangeBasis& b, const RefPoint& x) {
  std::vector<double> v(b.num_nodes());
  b.evaluate(x, v);
  return v;
}

std::vector<double> gradients_at(const LagrangeBasis& b, const RefPoint& x) {
  std::vector<double> g(3 * b.num_nodes());
  b.evaluate_gradients(x, g);
  return g;
}

// ---------------------------------------------------------------------------------------
// Closed-form oracle for complete line / quadrangle / hexahedron / triangle / tetrahedron /
// prism types: products of 1D equispaced Lagrange polynomials and Silvester's simplex
// polynomials, evaluated with forward-mode dual numbers for exact derivatives. Shares
// nothing with the Vandermonde construction under test.
struct Dual {
  double v, d;
};
Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.v * b.d + a.d * b.v}; }
Dual operator*(double s, Dual a) { return {s * a.v, s * a.d}; }
Dual operator*(Dual a, double s) { return {s * a.v, s * a.d}; }

// 1D Lagrange polynomial of node a among t_b = -1 + 2b/p, b = 0..p.
Dual lagrange_1d(int p, int a, Dual t) {
  Dual r{1, 0};
  for (int b = 0; b <= p; ++b)
    if (b != a) r = r * (1.0 / (2.0 * (a - b) / p)) * (t - Dual{-1 + 2.0 * b / p, 0});
  return r;
}
// Silvester: R_m(lambda) = prod_{s<m} (p lambda - s) / (s + 1).
Dual silvester(int p, int m, Dual lambda) {
  Dual r{1, 0};
  for (int s = 0; s < m; ++s) r = r * (1.0 / (s + 1)) * (p * lambda - Dual{double(s), 0});
  return r;
}

// N_node(x) and its derivative along coordinate `dir`, from the closed forms.
Dual closed_form(F f, int p, const RefPoint& node, const RefPoint& x, int dir) {
  Dual c[3];
  for (int d = 0; d < 3; ++d) c[d] = {x[d], d == dir ? 1.0 : 0.0};
  auto idx = [&](double v) { return static_cast<int>(std::lround(v)); };
  auto grid = [&](double v) { return idx((v + 1) * p / 2); };  // [-1,1] lattice index
  switch (f) {
    case F::line: return lagrange_1d(p, grid(node[0]), c[0]);
    case F::quadrangle:
      return lagrange_1d(p, grid(node[0]), c[0]) * lagrange_1d(p, grid(node[1]), c[1]);
    case F::hexahedron:
      return lagrange_1d(p, grid(node[0]), c[0]) * lagrange_1d(p, grid(node[1]), c[1]) *
             lagrange_1d(p, grid(node[2]), c[2]);
    case F::triangle: {
      const int i = idx(node[0] * p), j = idx(node[1] * p);
      return silvester(p, i, c[0]) * silvester(p, j, c[1]) *
             silvester(p, p - i - j, Dual{1, 0} - c[0] - c[1]);
    }
    case F::tetrahedron: {
      const int i = idx(node[0] * p), j = idx(node[1] * p), k = idx(node[2] * p);
      return silvester(p, i, c[0]) * silvester(p, j, c[1]) * silvester(p, k, c[2]) *
             silvester(p, p - i - j - k, Dual{1, 0} - c[0] - c[1] - c[2]);
    }
    case F::prism: {
      const int i = idx(node[0] * p), j = idx(node[1] * p);
      return silvester(p, i, c[0]) * silvester(p, j, c[1]) *
             silvester(p, p - i - j, Dual{1, 0} - c[0] - c[1]) *
             lagrange_1d(p, grid(node[2]), c[2]);
    }
    default: return {NAN, NAN};
  }
}

TEST(LagrangeBasis, CompleteTypesMatchClosedFormsUpToOrderTen) {
  int checked = 0;
  for (const ElementType* t : lagrange_types()) {
    if (!t->complete || t->family == F::pyramid || t->family == F::point) continue;
    SCOPED_TRACE(std::string(t->name));
    const LagrangeBasis& b = lagrange_basis(*t);
    const auto nodes = b.nodes();
    double worst_v = 0, worst_g = 0;
    for (const RefPoint& x : random_points(t->family, 3, 100 + t->gmsh_id)) {
      const auto v = values_at(b, x);
      const auto g = gradients_at(b, x);
      for (int i = 0; i < b.num_nodes(); ++i) {
        worst_v = std::max(worst_v, std::abs(v[i] - closed_form(t->family, t->order, nodes[i], x, 0).v));
        for (int d = 0; d < t->dim; ++d)
          worst_g = std::max(worst_g, std::abs(g[3 * i + d] -
                                               closed_form(t->family, t->order, nodes[i], x, d).d));
      }
    }
    EXPECT_LT(worst_v, 1e-9);
    EXPECT_LT(worst_g, 1e-7);
    ++checked;
  }
  // lines 1-10, triangles 1-10, quadrangles 1-10, tetrahedra 1-10, hexahedra 1-9, prisms 1-9
  EXPECT_EQ(checked, 10 + 10 + 10 + 10 + 9 + 9);
}

TEST(LagrangeBasis, KroneckerAtOwnNodes) {
  for (const ElementType* t : lagrange_types()) {
    SCOPED_TRACE(std::string(t->name));
    const LagrangeBasis& b = lagrange_basis(*t);
    const Eigen::MatrixXd v = b.evaluate_batch(b.nodes());
    const double err = (v - Eigen::MatrixXd::Identity(b.num_nodes(), b.num_nodes())).cwiseAbs().maxCoeff();
    EXPECT_LT(err, 1e-9);
  }
}

TEST(LagrangeBasis, PartitionOfUnityAndGradientsSumToZero) {
  for (const ElementType* t : lagrange_types()) {
    SCOPED_TRACE(std::string(t->name));
    const LagrangeBasis& b = lagrange_basis(*t);
    for (const RefPoint& x : random_points(t->family, 5, t->gmsh_id)) {
      const auto v = values_at(b, x);
      const auto g = gradients_at(b, x);
      double sum = 0, gs[3] = {0, 0, 0}, scale = 1;
      for (int i = 0; i < b.num_nodes(); ++i) {
        sum += v[i];
        for (int d = 0; d < 3; ++d) gs[d] += g[3 * i + d], scale = std::max(scale, std::abs(g[3 * i + d]));
      }
      EXPECT_NEAR(sum, 1.0, 1e-10);
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(gs[d], 0.0, 1e-10 * scale) << "d=" << d;
      for (int d = t->dim; d < 3; ++d)
        for (int i = 0; i < b.num_nodes(); ++i) EXPECT_EQ(g[3 * i + d], 0.0);
    }
  }
}

TEST(LagrangeBasis, GradientsMatchFiniteDifferences) {
  for (const ElementType* t : lagrange_types()) {
    if (t->dim == 0) continue;
    SCOPED_TRACE(std::string(t->name));
    const LagrangeBasis& b = lagrange_basis(*t);
    const double h = 1e-4;
    for (const RefPoint& x : random_points(t->family, 2, 7 * t->gmsh_id)) {
      const auto g = gradients_at(b, x);
      double scale = 1;
      for (double gi : g) scale = std::max(scale, std::abs(gi));
      for (int d = 0; d < t->dim; ++d) {
        auto shifted = [&](double s) { RefPoint y = x; y[d] += s; return values_at(b, y); };
        const auto p2 = shifted(2 * h), p1 = shifted(h), m1 = shifted(-h), m2 = shifted(-2 * h);
        for (int i = 0; i < b.num_nodes(); ++i) {
          const double fd = (-p2[i] + 8 * p1[i] - 8 * m1[i] + m2[i]) / (12 * h);
          EXPECT_NEAR(g[3 * i + d], fd, 1e-7 * scale) << "node " << i << " d " << d;
        }
      }
    }
  }
}

TEST(LagrangeBasis, MatchesGmshValuesForEveryTypeGmshSupports) {
  const auto& ref = testing_data::gmsh_reference();
  int compared = 0;
  for (const ElementType* t : lagrange_types()) {
    const auto it = ref.types.find(t->gmsh_id);
    if (it == ref.types.end()) continue;  // prisms of order >= 3: Gmsh cannot build them
    const auto& g = it->second;
    SCOPED_TRACE(std::string(t->name));
    ASSERT_TRUE(g.has_values);
    if (t->family == F::pyramid && !t->complete && t->order >= 3) {
      // Gmsh 4.8.4: "Serendipity pyramid for order N not yet implemented"; its functions
      // are not even 1 at their own nodes, so there is nothing to compare with.
      EXPECT_GT(g.gmsh_kronecker_error, 0.5);
      continue;
    }
    // Gmsh's values are only as accurate as its own Kronecker error at its nodes (it uses
    // monomials: 0.12 for Hexahedron 1000), so that error sets the tolerance.
    const double tol = 1e-11 + 4 * g.gmsh_kronecker_error;
    const LagrangeBasis& b = lagrange_basis(*t);
    for (std::size_t k = 0; k < g.points.size(); ++k) {
      const auto v = values_at(b, g.points[k]);
      for (int i = 0; i < b.num_nodes(); ++i)
        EXPECT_NEAR(v[i], g.values[k * b.num_nodes() + i], tol) << "point " << k << " node " << i;
    }
    ++compared;
  }
  EXPECT_EQ(compared, static_cast<int>(lagrange_types().size()) - 14 - 7);
}

TEST(LagrangeBasis, BatchMatchesPointwise) {
  for (int id : {3, 11, 14, 19, 29, 92, 118, 127, 90, 137}) {
    const LagrangeBasis& b = lagrange_basis(*find_element_type(id));
    SCOPED_TRACE(std::string(b.type().name));
    const auto pts = random_points(b.type().family, 6, id);
    const Eigen::MatrixXd v = b.evaluate_batch(pts);
    const auto g = b.evaluate_gradients_batch(pts);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const auto vk = values_at(b, pts[k]);
      const auto gk = gradients_at(b, pts[k]);
      for (int i = 0; i < b.num_nodes(); ++i) {
        EXPECT_NEAR(v(k, i), vk[i], 1e-12);
        for (int d = 0; d < 3; ++d) EXPECT_NEAR(g[d](k, i), gk[3 * i + d], 1e-10);
      }
    }
  }
}

// The linear pyramid: N_base = (1 - z + sx x)(1 - z + sy y) / (4 (1 - z)), N_apex = z.
TEST(LagrangeBasis, LinearPyramidMatchesClosedForm) {
  const LagrangeBasis& b = lagrange_basis(*find_element_type(7));
  const double sx[] = {-1, 1, 1, -1}, sy[] = {-1, -1, 1, 1};
  for (const RefPoint& x : random_points(F::pyramid, 10, 5)) {
    const auto v = values_at(b, x);
    const auto g = gradients_at(b, x);
    const double w = 1 - x[2];
    for (int i = 0; i < 4; ++i) {
      const double a = w + sx[i] * x[0], c = w + sy[i] * x[1];
      EXPECT_NEAR(v[i], a * c / (4 * w), 1e-14);
      EXPECT_NEAR(g[3 * i + 0], sx[i] * c / (4 * w), 1e-13);
      EXPECT_NEAR(g[3 * i + 1], sy[i] * a / (4 * w), 1e-13);
      // d/dz [a c / (4w)] = (-c - a) / (4w) + a c / (4 w^2)
      EXPECT_NEAR(g[3 * i + 2], (-a - c) / (4 * w) + a * c / (4 * w * w), 1e-12);
    }
    EXPECT_NEAR(v[4], x[2], 1e-14);
  }
}

TEST(LagrangeBasis, PyramidApexValuesAreContinuousAndGradientIsTheAxisLimit) {
  for (int id : {7, 14, 19, 118, 119, 126, 124}) {
    const LagrangeBasis& b = lagrange_basis(*find_element_type(id));
    SCOPED_TRACE(std::string(b.type().name));
    const RefPoint apex{0, 0, 1};
    const auto va = values_at(b, apex);
    const double eps = 1e-9;
    for (const RefPoint& dir : {RefPoint{0, 0, 1}, RefPoint{0.9, 0.9, 1}, RefPoint{-0.5, 0.7, 1}}) {
      const auto v = values_at(b, {dir[0] * eps, dir[1] * eps, 1 - eps});
      for (int i = 0; i < b.num_nodes(); ++i) EXPECT_NEAR(v[i], va[i], 1e-6);
    }
    const auto ga = gradients_at(b, apex);
    const auto gnear = gradients_at(b, {0, 0, 1 - 1e-11});
    for (int i = 0; i < 3 * b.num_nodes(); ++i) {
      EXPECT_TRUE(std::isfinite(ga[i]));
      EXPECT_NEAR(ga[i], gnear[i], 1e-6 * (1 + std::abs(ga[i])));
    }
  }
}

TEST(LagrangeBasis, LegendreAndBernsteinFactorsSpanTheSameSpaceAsMonomials) {
  // The better-conditioned factors must not change the functions (orders <= 4, where the
  // monomial Vandermonde matrix is still accurate).
  int checked = 0;
  for (const ElementType* t : lagrange_types()) {
    if (t->order > 4) continue;
    const auto chosen = detail::polynomial_space(*t);
    if (chosen.factors == detail::FactorBasis::monomial) continue;
    SCOPED_TRACE(std::string(t->name));
    const auto mono = detail::polynomial_space(*t, detail::FactorBasis::monomial);
    const auto nodes = reference_nodes(*t);
    const auto cm = detail::lagrange_coefficients(mono, nodes);
    const auto cc = detail::lagrange_coefficients(chosen, nodes);
    for (const RefPoint& x : random_points(t->family, 3, t->gmsh_id)) {
      Eigen::RowVectorXd pm(t->num_nodes), pc(t->num_nodes);
      detail::for_each_basis_function<false>(mono, x, [&](int j, double v, const auto&) { pm[j] = v; });
      detail::for_each_basis_function<false>(chosen, x, [&](int j, double v, const auto&) { pc[j] = v; });
      EXPECT_LT(((pm * cm) - (pc * cc)).cwiseAbs().maxCoeff(), 1e-11);
    }
    ++checked;
  }
  EXPECT_GE(checked, 35);
}

TEST(LagrangeBasis, FactorChoiceFollowsDownwardClosure) {
  using detail::FactorBasis;
  auto factors = [](int id) { return detail::polynomial_space(*find_element_type(id)).factors; };
  EXPECT_EQ(factors(98), FactorBasis::legendre);   // Hexahedron 1000
  EXPECT_EQ(factors(75), FactorBasis::bernstein);  // Tetrahedron 286
  EXPECT_EQ(factors(110), FactorBasis::bernstein); // Prism 550
  EXPECT_EQ(factors(105), FactorBasis::legendre);  // Hexahedron 104: at most one exponent > 1
  EXPECT_EQ(factors(124), FactorBasis::legendre);  // Pyramid 385 (Bergot)
  EXPECT_EQ(factors(19), FactorBasis::legendre);   // Pyramid 13: P^2 less x^2 y^2/(1-z)^2
  EXPECT_EQ(factors(20), FactorBasis::monomial);   // Triangle 9: 1,x,y,x2,y2,x3,y3,x2y,xy2 (no xy)
  EXPECT_EQ(factors(137), FactorBasis::monomial);  // Tetrahedron 16
  EXPECT_EQ(factors(125), FactorBasis::monomial);  // Pyramid 21
}

// Restricted to a face, a 3D basis must be the 2D basis of that face's element (so that
// neighbours sharing the face agree), and the functions of nodes off the face must vanish.
void expect_face_trace(const ElementType& t, int face_index, const ElementType& face_type) {
  const ReferenceFace& face = reference_faces(t.family)[face_index];
  const auto v = reference_vertices(t.family);
  auto map = [&](const RefPoint& uv) {
    RefPoint x{0, 0, 0};
    for (int d = 0; d < 3; ++d) {
      const RefPoint &a = v[face.vertices[0]], &b = v[face.vertices[1]], &c = v[face.vertices[2]];
      if (face.num_vertices == 3) {
        x[d] = a[d] + uv[0] * (b[d] - a[d]) + uv[1] * (c[d] - a[d]);
      } else {
        const RefPoint& e = v[face.vertices[3]];
        const double u0 = (1 - uv[0]) / 2, u1 = (1 + uv[0]) / 2, v0 = (1 - uv[1]) / 2, v1 = (1 + uv[1]) / 2;
        x[d] = u0 * v0 * a[d] + u1 * v0 * b[d] + u1 * v1 * c[d] + u0 * v1 * e[d];
      }
    }
    return x;
  };
  const LagrangeBasis& b3 = lagrange_basis(t);
  const LagrangeBasis& b2 = lagrange_basis(face_type);
  // Which 3D node each 2D node lands on.
  std::vector<int> on_face(b3.num_nodes(), -1);
  for (int k = 0; k < b2.num_nodes(); ++k) {
    const RefPoint x = map(b2.nodes()[k]);
    int found = -1;
    for (int i = 0; i < b3.num_nodes(); ++i) {
      const RefPoint& y = b3.nodes()[i];
      if (std::abs(x[0] - y[0]) + std::abs(x[1] - y[1]) + std::abs(x[2] - y[2]) < 1e-12) found = i;
    }
    ASSERT_GE(found, 0) << "face node " << k;
    on_face[found] = k;
  }
  for (const RefPoint& uv : random_points(face_type.family, 4, 31 * t.gmsh_id + face_index)) {
    const auto v3 = values_at(b3, map(uv));
    const auto v2 = values_at(b2, uv);
    for (int i = 0; i < b3.num_nodes(); ++i)
      EXPECT_NEAR(v3[i], on_face[i] >= 0 ? v2[on_face[i]] : 0.0, 1e-9)
          << "face " << face_index << " node " << i;
  }
}

TEST(LagrangeBasis, CompleteTypesRestrictToTheFaceElementOnEveryFace) {
  for (const ElementType* t : lagrange_types()) {
    if (t->dim != 3 || !t->complete || t->order > 6) continue;
    SCOPED_TRACE(std::string(t->name));
    const auto faces = reference_faces(t->family);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const F ff = faces[f].num_vertices == 3 ? F::triangle : F::quadrangle;
      expect_face_trace(*t, static_cast<int>(f), *find_element_type(ff, t->order, true));
    }
  }
}

TEST(LagrangeBasis, IncompleteTypesRestrictToIncompleteFaceElements) {
  // Faces where Gmsh's incomplete spaces are conforming: all hexahedron faces, the prism's
  // faces, the tetrahedron's face z = 0 (its Cartesian "Pascal edges" set is not symmetric
  // under vertex permutations), and the pyramid's base.
  for (const ElementType* t : lagrange_types()) {
    if (t->dim != 3 || t->complete || t->order > 6) continue;
    SCOPED_TRACE(std::string(t->name));
    const auto faces = reference_faces(t->family);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const bool tri = faces[f].num_vertices == 3;
      const bool conforming = t->family == F::hexahedron || t->family == F::prism ||
                              (t->family == F::tetrahedron && f == 0) ||
                              (t->family == F::pyramid && !tri);
      if (!conforming) continue;
      const ElementType* face_type =
          find_element_type(tri ? F::triangle : F::quadrangle, t->order, false);
      ASSERT_NE(face_type, nullptr);
      expect_face_trace(*t, static_cast<int>(f), *face_type);
    }
  }
}

TEST(LagrangeBasis, CacheIsBuiltOnceAndSharedAcrossThreads) {
  const ElementType& t = *find_element_type(96);  // Hexahedron 512, not used elsewhere
  std::vector<const LagrangeBasis*> seen(8, nullptr);
  std::vector<std::thread> threads;
  for (int k = 0; k < 8; ++k) threads.emplace_back([&, k] { seen[k] = &lagrange_basis(t); });
  for (auto& th : threads) th.join();
  for (const LagrangeBasis* b : seen) EXPECT_EQ(b, seen[0]);
  EXPECT_EQ(&seen[0]->type(), &t);
}

TEST(LagrangeBasis, TypesWithoutLagrangeBasisAreRejected) {
  EXPECT_THROW(lagrange_basis(*find_element_type(35)), std::invalid_argument);
  EXPECT_THROW(lagrange_basis(*find_element_type(89)), std::invalid_argument);
}

TEST(ElementTypeLookup, IncompleteRequestForTypesWithoutFaceNodesGivesTheCompleteType) {
  // As gmsh.model.mesh.getElementType(family, order, serendip=True) answers.
  EXPECT_EQ(find_element_type(F::triangle, 2, false)->gmsh_id, 9);
  EXPECT_EQ(find_element_type(F::tetrahedron, 2, false)->gmsh_id, 11);
  EXPECT_EQ(find_element_type(F::line, 3, false)->gmsh_id, 26);
  EXPECT_EQ(find_element_type(F::tetrahedron, 3, false)->gmsh_id, 137);
  EXPECT_EQ(find_element_type(F::prism, 3, false)->gmsh_id, 111);
  EXPECT_EQ(find_element_type(F::point, 0, false)->gmsh_id, 15);
  EXPECT_EQ(find_element_type(F::hexahedron, 10, true), nullptr);
}

}  // namespace
}  // namespace quadval
