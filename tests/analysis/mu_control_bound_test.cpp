// The control-matrix bound of mu (src/analysis/mu_control_bound.hpp):
//  - the eigenvalue enclosure of one symmetric matrix against exact rational arithmetic
//    (GMP): M - min_lo I and max_hi I - M are positive semidefinite, M - min_hi I and
//    max_hi I - M are not positive definite (principal minors, exactly), for random,
//    near-multiple, near-singular and indefinite matrices, also when the matrix is any
//    point of the error box;
//  - mu_bounds with the control bound alone, and with the default combination, against
//    dense sampling of the singular values of W (mu_test_util.hpp, no shared code) on
//    random curved elements of every family and order up to 3, and the gap closing.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <algorithm>
#include <limits>
#include <cstdint>
#include <bit>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/mu_control_bound.hpp"
#include "analysis/mu_metric.hpp"
#include "analysis/mu_space.hpp"
#include "jacobian_test_util.hpp"
#include "mu_test_util.hpp"
#include "quadval/mu_bounds.hpp"

namespace quadval {
namespace {

using Exact = std::array<std::array<mpq_class, 3>, 3>;

// All principal minors of a symmetric D x D rational matrix >= 0 (PSD) or leading ones
// > 0 (PD), exactly.
template <int D>
bool psd(const Exact& a) {
  for (int i = 0; i < D; ++i)
    if (a[i][i] < 0) return false;
  for (int i = 0; i < D; ++i)
    for (int j = i + 1; j < D; ++j)
      if (a[i][i] * a[j][j] - a[i][j] * a[i][j] < 0) return false;
  if (D == 3) {
    const mpq_class det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[1][2]) -
                          a[0][1] * (a[0][1] * a[2][2] - a[1][2] * a[0][2]) +
                          a[0][2] * (a[0][1] * a[1][2] - a[1][1] * a[0][2]);
    if (det < 0) return false;
  }
  return true;
}
template <int D>
bool pd(const Exact& a) {
  if (!(a[0][0] > 0)) return false;
  if (!(a[0][0] * a[1][1] - a[0][1] * a[0][1] > 0)) return false;
  if (D == 2) return true;
  const mpq_class det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[1][2]) -
                        a[0][1] * (a[0][1] * a[2][2] - a[1][2] * a[0][2]) +
                        a[0][2] * (a[0][1] * a[1][2] - a[1][1] * a[0][2]);
  return det > 0;
}

// Entry order of symmetric_eigen_enclosure: m00, m11, (m22,) m01, (m02, m12).
template <int D>
std::array<std::array<int, 2>, D*(D + 1) / 2> entry_positions() {
  if constexpr (D == 2) return {{{0, 0}, {1, 1}, {0, 1}}};
  else return {{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
}

// s (a I - M) for s = +-1, exactly, M from the entries m.
template <int D>
Exact shifted(const double* m, double a, int s) {
  Exact out;
  const auto pos = entry_positions<D>();
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const mpq_class v = mpq_class(-m[i]) * s;
    out[pos[i][0]][pos[i][1]] = out[pos[i][1]][pos[i][0]] = v;
  }
  for (int i = 0; i < D; ++i) out[i][i] += mpq_class(a) * s;
  return out;
}

template <int D>
void check_enclosure_of_random_matrices(unsigned seed) {
  constexpr int kEntries = D * (D + 1) / 2;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int tight = 0, positive = 0, fast_count = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // M = Q diag(l) Q^T with chosen spectra: generic, near-multiple, near-singular,
    // indefinite; then rounded to doubles (the matrix under test is the rounded one).
    Eigen::Matrix<double, D, D> q = Eigen::Matrix<double, D, D>::Random().householderQr().householderQ();
    Eigen::Matrix<double, D, 1> l = Eigen::Matrix<double, D, 1>::Random().cwiseAbs() * 3;
    switch (trial % 5) {
      case 1: l.setConstant(2.0), l(0) += 1e-9 * u(rng); break;  // near-multiple
      case 2: l(0) = 1e-7 * std::abs(u(rng)); break;               // near-singular
      case 3: l(0) = -0.5; break;                                  // indefinite
      default: break;
    }
    const Eigen::Matrix<double, D, D> mm = q * l.asDiagonal() * q.transpose();
    double m[kEntries];
    const auto pos = entry_positions<D>();
    for (int i = 0; i < kEntries; ++i) m[i] = mm(pos[i][0], pos[i][1]);
    const double err = trial % 2 == 0 ? 0.0 : 1e-6;
    const EigenEnclosure e = symmetric_eigen_enclosure<D>(m, err);
    ASSERT_LE(e.min_lo, e.min_hi);
    ASSERT_LE(e.max_lo, e.max_hi);
    // The eigenvector-free bounds (3 x 3), when they certify.
    double f_lo = 0, f_hi = 0;
    bool fast = false;
    if constexpr (D == 3) {
      fast = extreme_eigen_bounds3(m, err, f_lo, f_hi);
      if (fast) ++fast_count;
    }
    // Every matrix of the error box: its corners' signs and a random point.
    for (int s = 0; s < 3; ++s) {
      double p[kEntries];
      for (int i = 0; i < kEntries; ++i)
        p[i] = m[i] + (s == 0 ? 0.0 : s == 1 ? err * (u(rng) > 0 ? 1 : -1) : err * u(rng));
      ASSERT_TRUE(psd<D>(shifted<D>(p, e.min_lo, -1))) << "lambda_min < min_lo, trial " << trial;
      ASSERT_TRUE(psd<D>(shifted<D>(p, e.max_hi, 1))) << "lambda_max > max_hi, trial " << trial;
      ASSERT_FALSE(pd<D>(shifted<D>(p, e.min_hi, -1))) << "lambda_min > min_hi, trial " << trial;
      ASSERT_FALSE(pd<D>(shifted<D>(p, e.max_lo, 1))) << "lambda_max < max_lo, trial " << trial;
      if (fast) {
        ASSERT_TRUE(psd<D>(shifted<D>(p, f_lo, -1))) << "fast: lambda_min < min_lo, trial " << trial;
        ASSERT_TRUE(psd<D>(shifted<D>(p, f_hi, 1))) << "fast: lambda_max > max_hi, trial " << trial;
      }
    }
    // Tight: within the margins (1e-12 of the scale, 3 err) of the full enclosure (itself
    // within ~1e-10 when an eigenvalue is nearly repeated).
    if (fast && trial % 5 != 3) {
      const double scale = l.cwiseAbs().maxCoeff();
      const double rel = trial % 5 == 1 ? 1e-9 : 1e-11;
      EXPECT_LE(e.min_hi - f_lo, rel * scale + 10 * err) << "trial " << trial;
      EXPECT_LE(f_hi - e.max_lo, rel * scale + 10 * err) << "trial " << trial;
    }
    // Tight to rounding (and err) on well-conditioned positive definite matrices.
    if (trial % 5 != 3) {
      ++positive;
      const double scale = l.cwiseAbs().maxCoeff();
      const double width = std::max(e.min_hi - e.min_lo, e.max_hi - e.max_lo);
      // Gershgorin radii carry err times (sum |V_ai|)(sum |V_bj|) <= D err per entry; the
      // closed-form eigenvectors of a nearly repeated eigenvalue are accurate to ~1e-10.
      const double rel = trial % 5 == 1 ? 1e-9 : 1e-12;
      if (width <= rel * scale + 4 * D * D * err) ++tight;
    }
  }
  EXPECT_GE(tight, positive * 99 / 100) << tight << " of " << positive;
  // The eigenvector-free bounds certify all but the near-singular and near-multiple cases.
  if (D == 3) {
    EXPECT_GE(fast_count, 3000 * 3 / 5) << fast_count;
  }
}

TEST(MuControlBound, EigenEnclosure2x2MatchesExactArithmetic) { check_enclosure_of_random_matrices<2>(5); }
TEST(MuControlBound, EigenEnclosure3x3MatchesExactArithmetic) { check_enclosure_of_random_matrices<3>(6); }

// ratio_at_least2 against exact rational arithmetic: whenever it certifies
// lambda_min >= r lambda_max, that holds at the corners of the error box and at random
// points in it (lambda = q -+ d, so with q > 0 the claim is q (1 - r) >= d (1 + r), squared
// below); r is drawn at random and within 1e-12 .. 1e-3 of the matrix's own ratio.
// The 2 x 2 enclosures four matrices at a time (the planar mu lanes): each lane the bits of
// symmetric_eigen_enclosure<2>'s ratio bounds for its matrix and error, ill-conditioned,
// indefinite and non-finite ones included.
TEST(MuControlBound, EnclosureRatiosInLanesAreTheScalarBits) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 500; ++trial) {
    Lanes<4> m[3], err;
    for (int l = 0; l < 4; ++l) {
      const double a = std::ldexp(u(rng), static_cast<int>(20 * u(rng))), b = a * (trial % 3 == 0 ? 1e-6 : u(rng));
      m[0][l] = a * a + b * b;
      m[1][l] = trial % 5 == 0 ? -m[0][l] : std::abs(u(rng)) * m[0][l];
      m[2][l] = 0.5 * u(rng) * std::sqrt(std::abs(m[0][l] * m[1][l]));
      err[l] = std::abs(u(rng)) * 1e-12 * m[0][l];
    }
    if (trial == 7) m[0][2] = std::numeric_limits<double>::infinity();
    const Lanes<4> lo = enclosure_ratio_lower2_lanes<4>(m, err), hi = enclosure_ratio_upper2_lanes<4>(m, err);
    for (int l = 0; l < 4; ++l) {
      const double ml[3] = {m[0][l], m[1][l], m[2][l]};
      const EigenEnclosure e = symmetric_eigen_enclosure<2>(ml, err[l]);
      EXPECT_EQ(std::bit_cast<std::uint64_t>(lo[l]), std::bit_cast<std::uint64_t>(e.ratio_lower())) << trial << " " << l;
      EXPECT_EQ(std::bit_cast<std::uint64_t>(hi[l]), std::bit_cast<std::uint64_t>(e.ratio_upper())) << trial << " " << l;
    }
  }
}

TEST(MuControlBound, RatioAtLeast2HoldsInExactArithmetic) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1, 1);
  int certified = 0, near_and_certified = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double scale = std::ldexp(1.0, static_cast<int>(40 * u(rng)));
    double m[3] = {scale * (1 + u(rng)), scale * (1 + u(rng)), scale * u(rng)};
    const double err = trial % 3 == 0 ? 0.0 : scale * 1e-7 * (1 + u(rng));
    const double q = 0.5 * (m[0] + m[1]), d = std::hypot(0.5 * (m[0] - m[1]), m[2]);
    const double ratio = q > d ? (q - d) / (q + d) : 0.0;
    const double gap = std::ldexp(1.0, -static_cast<int>(10 + 30 * (u(rng) + 1) / 2));  // 2^-10 .. 2^-40
    const double r = trial % 2 == 0 ? std::abs(u(rng)) * 0.999 : std::clamp(ratio * (1 + gap * u(rng)), 0.0, 0.999);
    if (!ratio_at_least2(m, err, r)) continue;
    ++certified;
    if (std::abs(r - ratio) < 1e-3 * ratio) ++near_and_certified;
    for (int s = 0; s < 6; ++s) {
      mpq_class p[3];
      for (int i = 0; i < 3; ++i) {
        const double sign = s < 4 ? ((s >> (i % 2)) & 1 ? 1.0 : -1.0) : u(rng);
        p[i] = mpq_class(m[i]) + mpq_class(err) * mpq_class(sign);
      }
      const mpq_class qe = (p[0] + p[1]) / 2, se = (p[0] - p[1]) / 2, rr(r);
      ASSERT_GT(qe, 0) << "trial " << trial;
      ASSERT_GE(qe * qe * (1 - rr) * (1 - rr), (se * se + p[2] * p[2]) * (1 + rr) * (1 + rr))
          << "lambda_min < r lambda_max, trial " << trial;
    }
  }
  EXPECT_GT(certified, 3000);
  EXPECT_GT(near_and_certified, 1000);  // tight: it certifies r close to the ratio itself
}

TEST(MuControlBound, RatioBoundsOfScaledIdentityAndStretch) {
  // Closed forms: diag(4, 1, 1) has ratio 1/4; c I has 1.
  const double m1[6] = {4, 1, 1, 0, 0, 0};
  const EigenEnclosure e1 = symmetric_eigen_enclosure<3>(m1, 0);
  EXPECT_LE(e1.ratio_lower(), 0.25);
  EXPECT_GE(e1.ratio_upper(), 0.25);
  EXPECT_NEAR(e1.ratio_lower(), 0.25, 1e-14);
  const double m2[3] = {2.5, 2.5, 0};
  EXPECT_NEAR(symmetric_eigen_enclosure<2>(m2, 0).ratio_lower(), 1.0, 1e-14);
  // Indefinite and singular control matrices give 0, never a positive bound.
  const double m3[6] = {1, 1, -1e-3, 0, 0, 0};
  EXPECT_EQ(symmetric_eigen_enclosure<3>(m3, 0).ratio_lower(), 0.0);
  const double m4[3] = {1, 1, 1};
  EXPECT_EQ(symmetric_eigen_enclosure<2>(m4, 0).ratio_lower(), 0.0);
}

TEST(MuControlBound, ControlRatioIsMinimumOverControlMatrices) {
  // Two control matrices per entry vector: diag(1, 1, 1) and diag(9, 1, 1) -> 1/9.
  const double m00[2] = {1, 9}, m11[2] = {1, 1}, m22[2] = {1, 1}, z[2] = {0, 0};
  const double* e[6] = {m00, m11, m22, z, z, z};
  const double err[6] = {0, 0, 0, 0, 0, 0};
  const double r = control_ratio_lower<3>(e, err, 2);
  EXPECT_LE(r, 1.0 / 9);
  EXPECT_NEAR(r, 1.0 / 9, 1e-11);  // the certification margins are 1e-12 relative
}

// 2D: the least ratio_lower of every control matrix's enclosure, bit for bit, whatever the
// count (lane blocks of 8 and a partial last one), on sets from nearly isotropic to
// stretched, some with an indefinite matrix (ratio 0) or an error radius.
TEST(MuControlBound, ControlRatio2IsTheLeastEnclosureOfEveryMatrix) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n : {1, 3, 7, 8, 9, 16, 17, 25, 28}) {
    for (int trial = 0; trial < 40; ++trial) {
      const double stretch = trial % 4 == 0 ? 0.99 : trial % 4 == 1 ? 0.5 : trial % 4 == 2 ? 0.05 : 1e-6;
      std::array<std::vector<double>, 3> entries;
      double least = 1;
      for (int k = 0; k < n; ++k) {
        const double angle = 3.2 * u(rng), c = std::cos(angle), s = std::sin(angle);
        const double l0 = 1 + 0.1 * u(rng);
        double l1 = stretch * (1 + 0.1 * u(rng));
        if (trial % 7 == 3 && k == n / 2) l1 = -0.01;  // one indefinite matrix
        entries[0].push_back(c * c * l0 + s * s * l1);
        entries[1].push_back(s * s * l0 + c * c * l1);
        entries[2].push_back(c * s * (l0 - l1));
      }
      const double err = trial % 3 == 0 ? 1e-9 : 0.0;
      const double errs[3] = {err, err / 2, err};
      const double* e[3] = {entries[0].data(), entries[1].data(), entries[2].data()};
      for (int k = 0; k < n; ++k) {
        const double m[3] = {entries[0][static_cast<std::size_t>(k)], entries[1][static_cast<std::size_t>(k)],
                             entries[2][static_cast<std::size_t>(k)]};
        least = std::min(least, symmetric_eigen_enclosure<2>(m, err).ratio_lower());
      }
      SCOPED_TRACE(testing::Message() << "n " << n << " trial " << trial);
      EXPECT_EQ(control_ratio_lower<2>(e, errs, n), least);
    }
  }
}

// lambda_min(M) >= r lambda_max(M) for a symmetric 3 x 3 M, exactly: the eigenvalues of
// M (x) I - r I (x) M are lambda_i - r lambda_j, so the 9 x 9 Kronecker matrix is
// positive definite (rational LDL^T, every pivot > 0) exactly when every lambda_i > r
// lambda_j.
bool ratio_above_exactly(const Exact& m, const mpq_class& r) {
  std::array<std::array<mpq_class, 9>, 9> k;
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) {
      const int i = a / 3, j = a % 3, p = b / 3, q = b % 3;
      k[a][b] = (j == q ? m[i][p] : mpq_class(0)) - (i == p ? r * m[j][q] : mpq_class(0));
    }
  for (int c = 0; c < 9; ++c) {
    if (!(k[c][c] > 0)) return false;
    for (int a = c + 1; a < 9; ++a) {
      const mpq_class f = k[a][c] / k[c][c];
      for (int b = c; b < 9; ++b) k[a][b] -= f * k[c][b];
    }
  }
  return true;
}

TEST(MuControlBound, ControlRatioAgainstExactKroneckerCriterion) {
  // Sets of 27 control matrices Q diag(l) Q^T, each set around a common shape: the least
  // ratio of the set (computed here by Eigen, for tightness only) must be certified, and
  // every matrix of the set must satisfy lambda_min > r lambda_max exactly, also at the
  // corners of the error box. Shapes: nearly isotropic, one large and two equal
  // eigenvalues (where the eigenvalue-free test is sharp), two equal large ones (where it
  // is loose and the enclosure must take over), and spread ones. The same with a bound
  // that suffices (`enough`) below and above the least ratio.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::array<std::array<double, 3>, 4> shapes = {{{1, 0.97, 0.95}, {1, 0.6, 0.6}, {1, 1, 0.5}, {1, 0.5, 0.2}}};
  int sets = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const auto& shape = shapes[static_cast<std::size_t>(trial % 4)];
    const double err = trial % 3 == 0 ? 1e-9 : 0.0;
    std::vector<std::array<double, 6>> ms(27);
    double least = 1;
    for (auto& m : ms) {
      const Eigen::Matrix3d q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
      Eigen::Vector3d l;
      for (int i = 0; i < 3; ++i) l[i] = shape[static_cast<std::size_t>(i)] * (1 + 0.05 * u(rng));
      const Eigen::Matrix3d a = q * l.asDiagonal() * q.transpose();
      m = {a(0, 0), a(1, 1), a(2, 2), a(0, 1), a(0, 2), a(1, 2)};
      least = std::min(least, l.minCoeff() / l.maxCoeff());
    }
    std::array<std::vector<double>, 6> entries;
    for (int i = 0; i < 6; ++i)
      for (const auto& m : ms) entries[static_cast<std::size_t>(i)].push_back(m[static_cast<std::size_t>(i)]);
    const double* e[6];
    for (int i = 0; i < 6; ++i) e[i] = entries[static_cast<std::size_t>(i)].data();
    const double errs[6] = {err, err, err, err, err, err};
    // With enough (what settles the caller) below the least ratio, that is the bound; above
    // it, the bound stays tight.
    const double below = 0.9 * least, above = std::min(1.1 * least, 0.999);
    EXPECT_EQ(control_ratio_lower<3>(e, errs, 27, below), below);
    const double r_above = control_ratio_lower<3>(e, errs, 27, above);
    EXPECT_LE(r_above, above);
    EXPECT_GT(r_above, least * (1 - 1e-6));
    const double r = std::max(control_ratio_lower<3>(e, errs, 27), r_above);  // the stronger claim checked below
    SCOPED_TRACE(trial);
    EXPECT_GT(r, least * (1 - 1e-6));  // tight (the rotation's rounding moves l by ~1e-16)
    for (const auto& m : ms)
      for (int corner = 0; corner < (err > 0 ? 4 : 1); ++corner) {
        // The matrix itself, or a corner of its error box.
        std::array<double, 6> d{};
        for (int i = 0; i < 6; ++i) d[static_cast<std::size_t>(i)] = corner == 0 ? 0 : ((i + corner) % 2 ? err : -err);
        Exact x;
        const auto pos = entry_positions<3>();
        for (std::size_t i = 0; i < 6; ++i)
          x[pos[i][0]][pos[i][1]] = x[pos[i][1]][pos[i][0]] = mpq_class(m[i]) + mpq_class(d[i]);
        ASSERT_TRUE(ratio_above_exactly(x, mpq_class(r))) << "r " << r;
      }
    ++sets;
  }
  EXPECT_EQ(sets, 60);
}

// corner_ratio_upper skips the corners whose R is certified to be at least its least bound
// so far: its value must equal, bit for bit, the least of the bounds at every corner
// (corner_ratio_upper_at, no skipping) and `below`, on random corner values of W ranging
// from nearly isotropic (most corners skipped) to strongly stretched.
TEST(MuControlBound, CornerBoundEqualsTheLeastOverEveryCorner) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-1, 1);
  int skipping_cases = 0;
  for (const ElementType& t : element_types()) {
    if (t.family == ElementFamily::line || !mu_supported(t) || t.order > 2) continue;
    SCOPED_TRACE(std::string(t.name));
    const MuSpace& space = mu_space(t);
    const auto ws = static_cast<std::size_t>(space.w_size());
    std::vector<double> w(static_cast<std::size_t>(space.dim()) * 3 * ws);
    for (int trial = 0; trial < 60; ++trial) {
      const double noise = trial % 3 == 0 ? 1e-3 : trial % 3 == 1 ? 0.1 : 0.8;
      for (int j = 0; j < space.dim(); ++j)
        for (int c = 0; c < 3; ++c)
          for (std::size_t k = 0; k < ws; ++k)
            w[(static_cast<std::size_t>(j) * 3 + static_cast<std::size_t>(c)) * ws + k] =
                (j == c ? 1.0 : 0.0) + noise * u(rng);
      const double err = trial % 2 == 0 ? 0.0 : 1e-9;
      const double below = trial % 4 == 3 ? 0.5 : 1.0;
      double want = below;
      for (const int k : space.w_basis().vertex_indices())
        want = std::min(want, corner_ratio_upper_at(space, w.data(), err, k));
      const double got = corner_ratio_upper(space, w.data(), err, nullptr, below);
      ASSERT_EQ(got, want) << "trial " << trial;
      if (noise < 0.01) ++skipping_cases;
    }
  }
  EXPECT_GT(skipping_cases, 100);
}

// mu_bounds with the given subdomain bound against dense sampling of W's singular values.
void check_against_sampling(int mode, double tol, unsigned seed) {
  mu_use_control_bound(mode);
  std::mt19937 rng(seed);
  QualityOptions opt;
  opt.abs_tol = tol;
  opt.max_subdivisions = 400;
  int elements = 0, met = 0;
  for (const ElementType& t : element_types()) {
    // Above mu_certificate_max_order: mu_high_order_test.cpp.
    if (t.family == ElementFamily::line || !mu_supported(t) || t.order > 3 ||
        t.order > mu_certificate_max_order(t.family))
      continue;
    SCOPED_TRACE(std::string(t.name));
    const LagrangeBasis& basis = lagrange_basis(t);
    const bool heavy = t.dim == 3 && t.order >= 2;
    const int count = heavy ? 10 : (t.dim == 3 ? 40 : 80);
    const auto pts = test::dense_points(t.family, t.dim == 3 ? 6 : 12, 60, rng);
    for (int e = 0; e < count; ++e) {
      const double amplitude = ((e % 3 == 0) ? 0.02 : (e % 3 == 1 ? 0.08 : 0.15)) / t.order;
      const auto x = test::random_element(t, amplitude, rng);
      const QualityBounds b = mu_bounds(t, x, opt, true);
      ++elements;
      ASSERT_LE(b.lower, b.upper);
      ASSERT_GE(b.lower, 0.0);
      if (b.tolerance_met) ++met;
      if (b.upper == 0) continue;
      const auto [lo, hi, negative] = test::sample_mu(basis, x, pts);
      if (negative) continue;
      ASSERT_GE(lo, b.lower - 1e-13) << "element " << e;
      ASSERT_LE(b.upper, hi + 1e-13) << "element " << e;
    }
  }
  mu_use_control_bound(2);
  EXPECT_GE(met, elements * 97 / 100) << met << " of " << elements;
}

TEST(MuControlBound, ControlBoundAloneNeverAboveSampledMinimum) { check_against_sampling(1, 1e-3, 31); }
TEST(MuControlBound, DefaultCombinationNeverAboveSampledMinimum) { check_against_sampling(2, 1e-3, 32); }

}  // namespace
}  // namespace quadval
