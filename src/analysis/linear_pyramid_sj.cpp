// The first stage of the scaled Jacobian for first-order pyramids (see linear_pyramid_sj.hpp).
#include "analysis/linear_pyramid_sj.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "analysis/edge_determinants.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "quadval/bezier_basis.hpp"

namespace quadval {
namespace {

using edge_determinants::det;
using edge_determinants::kW1;
using edge_determinants::norm1;
using edge_determinants::Vec;

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSlack = 1e-11, kSmall = 0x1p-200, kLarge = 0x1p200;

Vec minus(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec half(const Vec& a) { return {a[0] / 2, a[1] / 2, a[2] / 2}; }

}  // namespace

std::optional<QualityBounds> linear_pyramid_sj_bounds(const ScaledJacobianSpace& space, std::span<const double> x,
                                                      double tol) {
  // Offsets from vertex 0: y[1..3] the other base vertices, y[4] the apex.
  std::array<Vec, 5> y{};
  double scale = 0;
  for (std::size_t i = 1; i < 5; ++i) {
    y[i] = {x[3 * i] - x[0], x[3 * i + 1] - x[1], x[3 * i + 2] - x[2]};
    scale += norm1(y[i]);
  }
  if (!(scale >= kSmall && scale <= kLarge)) return std::nullopt;
  const double e = 4 * kUnit * scale;  // a control point's coordinate error
  // The columns' control points, per corner (i, j): u = -1, 1 and v = -1, 1.
  const Vec xi[2] = {half(y[1]), half(minus(y[2], y[3]))};        // by v
  const Vec eta[2] = {half(y[3]), half(minus(y[2], y[1]))};       // by u
  const Vec diagonal = minus(y[4], half({y[1][0] + y[3][0], y[1][1] + y[3][1], y[1][2] + y[3][2]}));
  const Vec anti = minus(y[4], half(y[2]));
  const Vec zeta[2][2] = {{diagonal, anti}, {anti, diagonal}};   // [u][v]
  const auto column = [&](int c, int i, int j) -> const Vec& { return c == 0 ? xi[j] : c == 1 ? eta[i] : zeta[i][j]; };

  // J's coefficients: [u index][v index], degree 2 each.
  const double ev = 3 * e;  // a control point's vector error, 1-norm
  double jac[3][3] = {};
  double j_err = 0, det_max = 0;
  for (int i = 0; i < 2; ++i)
    for (int i2 = 0; i2 < 2; ++i2)
      for (int j = 0; j < 2; ++j)
        for (int j2 = 0; j2 < 2; ++j2) {
          const Vec &a = xi[j], &b = eta[i], &c = zeta[i2][j2];
          double t = 0;
          const double d = det(a, b, c, t);
          const double na = norm1(a), nb = norm1(b), nc = norm1(c);
          const double err = 16 * kUnit * t + 2 * ev * (na * nb + nb * nc + nc * na) + 2 * ev * ev * (na + nb + nc) +
                             4 * ev * ev * ev;
          j_err = std::max(j_err, err);
          det_max = std::max(det_max, std::abs(d));
          jac[i + i2][j + j2] += kW1[i][i2] * kW1[j][j2] * d;
        }
  j_err = next_up((j_err + rounding_gamma(4) * det_max) * (1 + 1e-12) + 0x1p-1000);  // 2^-1000: gradual underflow
  double j_min = kInf;
  for (const auto& row : jac)
    for (double v : row) j_min = std::min(j_min, v);
  const double j_lo = next_down(j_min - j_err);
  if (!(j_lo > 0)) return std::nullopt;

  // Per frame: the largest norm of each column over the corners (lower bound), and sj at
  // each corner (upper bound).
  const double en = 16 * e;  // a frame column's norm error
  double lower = kInf, upper = kInf;
  for (const Frame& fr : space.frames()) {
    double big[3] = {0, 0, 0};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        double den = 1;
        for (std::size_t k = 0; k < 3; ++k) {
          Vec v{0, 0, 0};
          for (std::size_t c = 0; c < 3; ++c)
            for (std::size_t a = 0; a < 3; ++a) v[a] += fr[k][c] * column(static_cast<int>(c), i, j)[a];
          const double n = sqrt_rn(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          if (!(n >= 2 * en)) return std::nullopt;  // a column may vanish at this corner
          big[k] = std::max(big[k], n + en);
          den *= n - en;
        }
        upper = std::min(upper, (jac[2 * i][2 * j] + j_err) / den);
      }
    lower = std::min(lower, j_lo / (big[0] * big[1] * big[2]));
  }
  QualityBounds out{next_down(space.s_lo() * lower * (1 - kSlack)), next_up(space.s_hi() * upper * (1 + kSlack)), 0,
                    false};
  out.tolerance_met = next_up(out.upper - out.lower) <= tol;
  if (!out.tolerance_met) return std::nullopt;
  return out;
}

}  // namespace quadval
