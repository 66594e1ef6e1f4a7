// The degree-6n filter of the 3D mu certificate (mu_metric.cpp, certify_filter): on
// thousands of random straight and curved elements, the bounds computed with it are true
// bounds of the sampled measure (Eigen SVD of W at dense points, mu_test_util.hpp) and
// agree with the bounds of the exact degree-12n certificate alone (filter switched off).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "analysis/mu_control_bound.hpp"
#include "analysis/mu_metric.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

struct FilterOff {
  FilterOff() { mu_use_filter(false); }
  ~FilterOff() { mu_use_filter(true); }
};

// The filter is part of the degree-12n certificate, which mu_bounds now reaches only after
// the control-matrix bound (mu_control_bound.hpp): these tests select it alone.
struct CertificateOnly {
  CertificateOnly() { mu_use_control_bound(0); }
  ~CertificateOnly() { mu_use_control_bound(2); }
};

void check_type(int gmsh_id, int count, double tol, std::mt19937& rng) {
  const CertificateOnly certificate;
  const ElementType& t = *find_element_type(gmsh_id);
  SCOPED_TRACE(std::string(t.name));
  const LagrangeBasis& basis = lagrange_basis(t);
  const auto pts = test::dense_points(t.family, 5, 30, rng);
  QualityOptions opt;
  opt.abs_tol = tol;
  opt.max_subdivisions = 200;
  int valid = 0, met = 0;
  for (int e = 0; e < count; ++e) {
    // A third straight-sided (amplitude 0), the rest curved up to 0.15 / order.
    const double amplitude = (e % 3 == 0) ? 0.0 : (e % 3 == 1 ? 0.05 : 0.15) / t.order;
    const auto x = test::random_element(t, amplitude, rng);
    const QualityBounds fast = mu_bounds(t, x, opt, true);
    QualityBounds exact;
    {
      FilterOff off;
      exact = mu_bounds(t, x, opt, true);
    }
    ASSERT_LE(fast.lower, fast.upper);
    // Both brackets hold the true minimum, so they intersect.
    EXPECT_LE(fast.lower, exact.upper) << "element " << e;
    EXPECT_LE(exact.lower, fast.upper) << "element " << e;
    met += fast.tolerance_met;
    if (fast.upper == 0) continue;
    double lo = 1;
    bool negative = false;
    for (const auto& p : pts) {
      if (test::jacobian_at(basis, x, p, true) <= 0) negative = true;
      lo = std::min(lo, test::pointwise_mu(basis, x, p));
    }
    if (negative) continue;
    ++valid;
    EXPECT_LE(fast.lower, lo + 1e-13) << "element " << e;
    if (fast.tolerance_met) {
      EXPECT_LE(fast.upper - fast.lower, tol);
    }
  }
  EXPECT_GE(valid, count / 2);
  EXPECT_GE(met, count * 9 / 10);
}

TEST(MuFilter, LinearTetrahedraPrismsHexahedra) {
  std::mt19937 rng(77);
  check_type(4, 1200, 1e-3, rng);  // tetrahedron 4
  check_type(6, 600, 1e-3, rng);   // prism 6
  check_type(5, 600, 1e-3, rng);   // hexahedron 8
}

TEST(MuFilter, CurvedTetrahedra) {
  std::mt19937 rng(78);
  check_type(11, 1200, 1e-3, rng);  // tetrahedron 10
  check_type(29, 40, 1e-2, rng);    // tetrahedron 20
}

TEST(MuFilter, CurvedPrismsHexahedra) {
  std::mt19937 rng(79);
  check_type(13, 20, 1e-2, rng);  // prism 18
  check_type(12, 20, 1e-2, rng);  // hexahedron 27
}

}  // namespace
}  // namespace quadval
