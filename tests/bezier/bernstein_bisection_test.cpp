// Edge bisection of tensor-product Bernstein polynomials (bezier/bernstein_bisection.hpp)
// against an independent oracle: the Bernstein sum evaluated from its definition, at the
// same physical point through the parent and through the child whose vertices the test
// tracks itself (Maubach's rule as documented), plus the children's measures and
// diameters.
#include "bezier/bernstein_bisection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <span>
#include <vector>

namespace quadval {
namespace {

using Point = std::array<double, 3>;
using Simplex = std::vector<Point>;  // d + 1 vertices in factor coordinates, by slot

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// B^n_alpha at barycentric coordinates lambda, from the definition.
double bernstein(const std::array<int, 4>& alpha, int d, const std::array<double, 4>& lambda) {
  int n = 0;
  for (int a = 0; a <= d; ++a) n += alpha[static_cast<std::size_t>(a)];
  double v = factorial(n);
  for (int a = 0; a <= d; ++a) {
    v /= factorial(alpha[static_cast<std::size_t>(a)]);
    v *= std::pow(lambda[static_cast<std::size_t>(a)], alpha[static_cast<std::size_t>(a)]);
  }
  return v;
}

// Barycentric coordinates of x in simplex s (dimension d <= 3), by Cramer's rule.
std::array<double, 4> barycentric(const Simplex& s, int d, const Point& x) {
  std::array<double, 4> l{};
  if (d == 1) {
    l[1] = (x[0] - s[0][0]) / (s[1][0] - s[0][0]);
  } else {
    double m[3][3] = {};
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j) m[j][i] = s[static_cast<std::size_t>(i + 1)][static_cast<std::size_t>(j)] - s[0][static_cast<std::size_t>(j)];
    if (d == 2) m[2][2] = 1;
    const auto det = [](double a[3][3]) {
      return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
             a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double full = det(m);
    for (int i = 0; i < d; ++i) {
      double c[3][3];
      std::copy(&m[0][0], &m[0][0] + 9, &c[0][0]);
      for (int j = 0; j < d; ++j) c[j][i] = x[static_cast<std::size_t>(j)] - s[0][static_cast<std::size_t>(j)];
      l[static_cast<std::size_t>(i + 1)] = det(c) / full;
    }
  }
  l[0] = 1;
  for (int a = 1; a <= d; ++a) l[0] -= l[static_cast<std::size_t>(a)];
  return l;
}

double measure(const Simplex& s, int d) {
  if (d == 1) return std::abs(s[1][0] - s[0][0]);
  const Point a{s[1][0] - s[0][0], s[1][1] - s[0][1], s[1][2] - s[0][2]};
  const Point b{s[2][0] - s[0][0], s[2][1] - s[0][1], s[2][2] - s[0][2]};
  if (d == 2) return std::abs(a[0] * b[1] - a[1] * b[0]) / 2;
  const Point c{s[3][0] - s[0][0], s[3][1] - s[0][1], s[3][2] - s[0][2]};
  return std::abs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
}

double diameter(const Simplex& s) {
  double m = 0;
  for (const Point& p : s)
    for (const Point& q : s) m = std::max(m, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
  return m;
}

Simplex reference(int d) {
  Simplex s(static_cast<std::size_t>(d + 1), Point{0, 0, 0});
  for (int i = 1; i <= d; ++i) s[static_cast<std::size_t>(i)][static_cast<std::size_t>(i - 1)] = 1;
  return s;
}

struct Piece {
  std::vector<Simplex> simplex;  // per factor
  BisectionState state;
};

// The children's domains by the documented rule: factor by factor, dim bisections each;
// piece p gives 2p (slot b = x_k replaced by the midpoint) and 2p + 1 (slot a = x_0).
std::vector<Piece> children_of(const Piece& parent, std::span<const FactorDegree> factors) {
  std::vector<Piece> pieces{parent};
  for (std::size_t f = 0; f < factors.size(); ++f) {
    const int d = factors[f].dim;
    for (int level = 0; level < d; ++level) {
      std::vector<Piece> next;
      for (const Piece& p : pieces) {
        const auto& o = p.state.order[f];
        const int k = p.state.tag[f];
        const auto a = static_cast<std::size_t>(o[0]), b = static_cast<std::size_t>(o[static_cast<std::size_t>(k)]);
        const Simplex& s = p.simplex[f];
        Point mid{};
        for (std::size_t j = 0; j < 3; ++j) mid[j] = (s[a][j] + s[b][j]) / 2;
        Piece first = p, second = p;
        first.simplex[f][b] = mid;
        second.simplex[f][a] = mid;
        const auto tag = static_cast<std::int8_t>(k > 1 ? k - 1 : d);
        first.state.tag[f] = second.state.tag[f] = tag;
        for (int i = 0; i < k; ++i) second.state.order[f][static_cast<std::size_t>(i)] = o[static_cast<std::size_t>(i + 1)];
        second.state.order[f][static_cast<std::size_t>(k)] = static_cast<std::int8_t>(a);
        next.push_back(first);
        next.push_back(second);
      }
      pieces = std::move(next);
    }
  }
  return pieces;
}

// Value of a coefficient vector of `space` at a point (one point per factor) of the piece.
double value(const BernsteinBisection& space, const std::vector<double>& coeffs, const Piece& piece,
             const std::vector<Point>& x) {
  const auto fs = space.factors();
  std::vector<std::vector<double>> basis(fs.size());
  for (std::size_t f = 0; f < fs.size(); ++f) {
    const auto l = barycentric(piece.simplex[f], fs[f].dim, x[f]);
    for (const auto& alpha : simplex_multi_indices(fs[f].dim, fs[f].degree)) basis[f].push_back(bernstein(alpha, fs[f].dim, l));
  }
  double v = 0;
  for (int i = 0; i < space.size(); ++i) {
    double b = 1;
    int rest = i;
    for (std::size_t f = 0; f < fs.size(); ++f) {
      b *= basis[f][static_cast<std::size_t>(rest % static_cast<int>(basis[f].size()))];
      rest /= static_cast<int>(basis[f].size());
    }
    v += b * coeffs[static_cast<std::size_t>(i)];
  }
  return v;
}

// A random point of a simplex (d = factor dim), by normalised exponential weights.
Point random_point(const Simplex& s, std::mt19937& rng) {
  std::exponential_distribution<double> e(1.0);
  std::vector<double> w(s.size());
  double sum = 0;
  for (double& x : w) sum += (x = e(rng));
  Point p{};
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = 0; j < 3; ++j) p[j] += w[i] / sum * s[i][j];
  return p;
}

class BisectionTest : public testing::TestWithParam<std::vector<FactorDegree>> {};

TEST_P(BisectionTest, ChildrenReproduceTheParentAndHalveTheMeasure) {
  const BernsteinBisection space(GetParam());
  const auto fs = space.factors();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  // Two vectors at once: the second is the first's negative plus a constant.
  std::vector<double> parent(2 * static_cast<std::size_t>(space.size()));
  for (int i = 0; i < space.size(); ++i) {
    parent[static_cast<std::size_t>(i)] = u(rng);
    parent[static_cast<std::size_t>(space.size() + i)] = 3 - parent[static_cast<std::size_t>(i)];
  }
  Piece root;
  for (const FactorDegree& fd : fs) root.simplex.push_back(reference(fd.dim));
  root.state = space.root_state();

  // Two generations: the grandchildren of the root.
  std::vector<Piece> pieces{root};
  std::vector<std::vector<double>> coeffs{parent};
  std::vector<double> scratch;
  for (int gen = 0; gen < 2; ++gen) {
    std::vector<Piece> next_pieces;
    std::vector<std::vector<double>> next_coeffs;
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const auto nc = static_cast<std::size_t>(space.num_children());
      std::vector<double> out(nc * coeffs[p].size());
      std::vector<BisectionState> states(nc);
      space.split(coeffs[p].data(), 2, pieces[p].state, out.data(), states.data(), scratch);
      const std::vector<Piece> kids = children_of(pieces[p], fs);
      ASSERT_EQ(kids.size(), nc);
      for (std::size_t q = 0; q < nc; ++q) {
        EXPECT_EQ(states[q].depth, gen + 1);
        EXPECT_EQ(states[q].order, kids[q].state.order);
        EXPECT_EQ(states[q].tag, kids[q].state.tag);
        next_pieces.push_back(kids[q]);
        next_pieces.back().state = states[q];
        next_coeffs.emplace_back(out.begin() + static_cast<std::ptrdiff_t>(q * coeffs[p].size()),
                                 out.begin() + static_cast<std::ptrdiff_t>((q + 1) * coeffs[p].size()));
      }
    }
    pieces = std::move(next_pieces);
    coeffs = std::move(next_coeffs);
  }
  const std::size_t s = static_cast<std::size_t>(space.size());
  double total = 0;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    double m = 1;
    for (std::size_t f = 0; f < fs.size(); ++f) m *= measure(pieces[p].simplex[f], fs[f].dim) / measure(reference(fs[f].dim), fs[f].dim);
    EXPECT_NEAR(m, 1.0 / static_cast<double>(pieces.size()), 1e-15);
    total += m;
    const std::vector<double> first(coeffs[p].begin(), coeffs[p].begin() + static_cast<std::ptrdiff_t>(s));
    const std::vector<double> second(coeffs[p].begin() + static_cast<std::ptrdiff_t>(s), coeffs[p].end());
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<Point> x;
      for (std::size_t f = 0; f < fs.size(); ++f) x.push_back(random_point(pieces[p].simplex[f], rng));
      const double want = value(space, parent, root, x);
      EXPECT_NEAR(value(space, first, pieces[p], x), want, 1e-10 * (1 + std::abs(want)));
      EXPECT_NEAR(value(space, second, pieces[p], x), 3 - want, 1e-10 * (1 + std::abs(want)));
    }
    // Coefficients at the vertices are values there.
    for (int v : space.vertex_indices()) {
      // The vertex's slot per factor: the factor index of coefficient v, alpha = n e_slot.
      std::vector<Point> x;
      int rest = v;
      for (std::size_t f = 0; f < fs.size(); ++f) {
        const auto alphas = simplex_multi_indices(fs[f].dim, fs[f].degree);
        const auto& alpha = alphas[static_cast<std::size_t>(rest % static_cast<int>(alphas.size()))];
        rest /= static_cast<int>(alphas.size());
        std::size_t slot = 0;
        for (std::size_t a = 0; a < 4; ++a)
          if (alpha[a] == fs[f].degree) slot = a;
        x.push_back(pieces[p].simplex[f][slot]);
      }
      EXPECT_NEAR(first[static_cast<std::size_t>(v)], value(space, parent, root, x), 1e-12);
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-13);
}

TEST_P(BisectionTest, HalvingLevelsTimesIsOneSplit) {
  // levels() single bisections in breadth-first order give split()'s children, bit for
  // bit, with the same states; a second round continues the sequence.
  const BernsteinBisection space(GetParam());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto size = static_cast<std::size_t>(space.size());
  std::vector<double> parent(2 * size);
  for (double& v : parent) v = u(rng);
  std::vector<std::vector<double>> coeffs{parent};
  std::vector<BisectionState> states{space.root_state()};
  std::vector<double> scratch;
  for (int round = 0; round < 2; ++round) {
    // The reference: split() of every piece of the previous round.
    std::vector<std::vector<double>> want;
    std::vector<BisectionState> want_states;
    const auto nc = static_cast<std::size_t>(space.num_children());
    for (std::size_t p = 0; p < coeffs.size(); ++p) {
      std::vector<double> out(nc * 2 * size);
      std::vector<BisectionState> st(nc);
      space.split(coeffs[p].data(), 2, states[p], out.data(), st.data(), scratch);
      for (std::size_t q = 0; q < nc; ++q) {
        want.emplace_back(out.begin() + static_cast<std::ptrdiff_t>(q * 2 * size),
                          out.begin() + static_cast<std::ptrdiff_t>((q + 1) * 2 * size));
        want_states.push_back(st[q]);
      }
    }
    for (int level = 0; level < space.levels(); ++level) {
      std::vector<std::vector<double>> next;
      std::vector<BisectionState> next_states;
      for (std::size_t p = 0; p < coeffs.size(); ++p) {
        std::vector<double> out(4 * size);
        BisectionState st[2];
        space.halve(coeffs[p].data(), 2, states[p], out.data(), st);
        for (std::size_t q = 0; q < 2; ++q) {
          next.emplace_back(out.begin() + static_cast<std::ptrdiff_t>(q * 2 * size),
                            out.begin() + static_cast<std::ptrdiff_t>((q + 1) * 2 * size));
          next_states.push_back(st[q]);
        }
      }
      coeffs = std::move(next);
      states = std::move(next_states);
    }
    ASSERT_EQ(coeffs.size(), want.size());
    for (std::size_t p = 0; p < coeffs.size(); ++p) {
      EXPECT_EQ(coeffs[p], want[p]) << "round " << round << " piece " << p;
      EXPECT_EQ(states[p].order, want_states[p].order);
      EXPECT_EQ(states[p].tag, want_states[p].tag);
      EXPECT_EQ(states[p].depth, round + 1);
      EXPECT_EQ(states[p].step, (round + 1) * space.levels());
    }
  }
  int largest = 0;
  for (const FactorDegree& fd : space.factors()) largest = std::max(largest, fd.degree);
  EXPECT_GE(space.halving_rounding_relative(), largest * 0x1p-53);
  EXPECT_LT(space.halving_rounding_relative(), largest * 0x1p-53 * 1.01 + 1e-300);
}

TEST_P(BisectionTest, VectorsAtOnceEqualOneAtATime) {
  // halve() of 11 vectors at once (lanes of 8 vectors, then 3) gives each vector's halves
  // bit for bit as halving it alone, through two generations of states.
  const BernsteinBisection space(GetParam());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto size = static_cast<std::size_t>(space.size());
  constexpr std::size_t kCount = 11;
  std::vector<double> parent(kCount * size);
  for (double& v : parent) v = u(rng);
  BisectionState state = space.root_state();
  for (int gen = 0; gen < space.levels() + 1; ++gen) {
    std::vector<double> together(2 * kCount * size);
    BisectionState st[2];
    space.halve(parent.data(), kCount, state, together.data(), st);
    for (std::size_t v = 0; v < kCount; ++v) {
      std::vector<double> alone(2 * size);
      BisectionState st1[2];
      space.halve(parent.data() + v * size, 1, state, alone.data(), st1);
      for (std::size_t q = 0; q < 2; ++q)
        for (std::size_t i = 0; i < size; ++i)
          ASSERT_EQ(together[(q * kCount + v) * size + i], alone[q * size + i])
              << "generation " << gen << " vector " << v << " child " << q << " coefficient " << i;
    }
    parent.assign(together.begin() + static_cast<std::ptrdiff_t>(kCount * size), together.end());
    state = st[1];
  }
}

INSTANTIATE_TEST_SUITE_P(Spaces, BisectionTest,
                         testing::Values(std::vector<FactorDegree>{{1, 7}}, std::vector<FactorDegree>{{2, 6}},
                                         std::vector<FactorDegree>{{3, 5}}, std::vector<FactorDegree>{{1, 3}, {1, 4}},
                                         std::vector<FactorDegree>{{2, 3}, {1, 2}},
                                         std::vector<FactorDegree>{{1, 2}, {1, 3}, {1, 1}},
                                         // Runs of 8 lines in lanes and shorter ones (bisect's
                                         // paths): the spaces of N and D of quadratic hexahedra
                                         // and prisms.
                                         std::vector<FactorDegree>{{1, 10}, {1, 10}, {1, 10}},
                                         std::vector<FactorDegree>{{2, 6}, {1, 9}},
                                         // Lines longer than the register kernels' 17
                                         // coefficients (the general loop).
                                         std::vector<FactorDegree>{{1, 20}}, std::vector<FactorDegree>{{2, 18}},
                                         std::vector<FactorDegree>{{1, 3}, {1, 19}}));

TEST(Bisection, DiametersHalveEveryDimLevels) {
  // Maubach's refinement of the reference tetrahedron (diameter sqrt 2): d = 3 bisections
  // halve every edge, so from the second split on each split halves the largest
  // diameter of the descendants (the Kuhn simplex's classes repeat at half the size), and
  // none exceeds the first generation's.
  const std::vector<FactorDegree> tet{{3, 0}};
  const BernsteinBisection space(tet);
  Piece root;
  root.simplex = {reference(3)};
  root.state = space.root_state();
  std::vector<Piece> pieces{root};
  std::vector<double> worst;
  for (int k = 1; k <= 5; ++k) {
    std::vector<Piece> next;
    for (const Piece& p : pieces)
      for (const Piece& c : children_of(p, space.factors())) next.push_back(c);
    pieces = std::move(next);
    double w = 0;
    for (const Piece& p : pieces) w = std::max(w, diameter(p.simplex[0]));
    worst.push_back(w);
  }
  EXPECT_LE(worst[0], std::sqrt(2.0));
  for (std::size_t k = 2; k < worst.size(); ++k) EXPECT_NEAR(worst[k], worst[k - 1] / 2, 1e-15) << k;
}

TEST(Bisection, ChildrenNeverExceedTheParentsLargestCoefficient) {
  // What the early stop of the scaled Jacobian relies on (bernstein_bisection.hpp): the
  // computed averages never exceed the parent's largest computed coefficient.
  const BernsteinBisection space({{3, 12}});
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> parent(static_cast<std::size_t>(space.size()));
  for (double& v : parent) v = u(rng) * 1e-3 + 0.1;
  std::vector<double> out(8 * parent.size()), scratch;
  std::vector<BisectionState> states(8);
  space.split(parent.data(), 1, space.root_state(), out.data(), states.data(), scratch);
  const double largest = *std::max_element(parent.begin(), parent.end());
  for (double v : out) EXPECT_LE(v, largest);
  // Three bisections of degree 12 per split, one rounding of u per average.
  EXPECT_GE(space.rounding_relative(), 3 * 12 * 0x1p-53);
  EXPECT_LT(space.rounding_relative(), 3 * 12 * 0x1p-53 * 1.01);
}

}  // namespace
}  // namespace quadval
