// The first stage of the scaled Jacobian for first-order pyramids (see linear_pyramid_sj.hpp).
#include "analysis/linear_pyramid_sj.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "analysis/edge_determinants.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/bezier_basis.hpp"

namespace quadval {
namespace {

using edge_determinants::kW1;
using edge_determinants::settled_lanes;

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSlack = 1e-11, kSmall = 0x1p-200, kLarge = 0x1p200;

// One pyramid per lane: every operation is the scalar one lane by lane, so a lane gets the
// bits of its element alone (which runs in two lanes, linear_pyramid_sj_bounds).
template <int W>
struct PyramidLanes {
  using L = Lanes<W>;
  using Vec = std::array<L, 3>;

  static L least(L m, L x) { return x < m ? x : m; }    // std::min(m, x)
  static L largest(L m, L x) { return m < x ? x : m; }  // std::max(m, x)
  static L norm1(const Vec& v) { return vabs(v[0]) + vabs(v[1]) + vabs(v[2]); }
  static Vec minus(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
  static Vec half(const Vec& a) { return {a[0] / 2, a[1] / 2, a[2] / 2}; }
  // det[a, b, c] as a . (b x c), t the sum of its triple products' magnitudes
  // (edge_determinants.hpp).
  static L det(const Vec& a, const Vec& b, const Vec& c, L& t) {
    t = vabs(a[0]) * (vabs(b[1] * c[2]) + vabs(b[2] * c[1])) + vabs(a[1]) * (vabs(b[2] * c[0]) + vabs(b[0] * c[2])) +
        vabs(a[2]) * (vabs(b[0] * c[1]) + vabs(b[1] * c[0]));
    return a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }

  // x[3 n + k]: node n's coordinate k, per lane. Bit l of the result set where out[l]
  // holds lane l's bounds.
  static unsigned bounds(const ScaledJacobianSpace& space, const L* x, double tol, QualityBounds* out) {
    // Offsets from vertex 0: y[1..3] the other base vertices, y[4] the apex.
    std::array<Vec, 5> y{};
    L scale{};
    for (int i = 1; i < 5; ++i) {
      y[static_cast<std::size_t>(i)] = {x[3 * i] - x[0], x[3 * i + 1] - x[1], x[3 * i + 2] - x[2]};
      scale += norm1(y[static_cast<std::size_t>(i)]);
    }
    lanes3::Mask<W> ok = (scale >= kSmall) & (scale <= kLarge);
    if (lanes3::mask_bits<W>(ok) == 0) return 0;
    const L e = 4 * kUnit * scale;  // a control point's coordinate error
    // The columns' control points, per corner (i, j): u = -1, 1 and v = -1, 1.
    const Vec xi[2] = {half(y[1]), half(minus(y[2], y[3]))};   // by v
    const Vec eta[2] = {half(y[3]), half(minus(y[2], y[1]))};  // by u
    const Vec diagonal = minus(y[4], half({y[1][0] + y[3][0], y[1][1] + y[3][1], y[1][2] + y[3][2]}));
    const Vec anti = minus(y[4], half(y[2]));
    const Vec zeta[2][2] = {{diagonal, anti}, {anti, diagonal}};  // [u][v]
    const auto column = [&](int c, int i, int j) -> const Vec& { return c == 0 ? xi[j] : c == 1 ? eta[i] : zeta[i][j]; };

    // J's coefficients: [u index][v index], degree 2 each.
    const L ev = 3 * e;  // a control point's vector error, 1-norm
    L jac[3][3] = {};
    L j_err{}, det_max{};
    for (int i = 0; i < 2; ++i)
      for (int i2 = 0; i2 < 2; ++i2)
        for (int j = 0; j < 2; ++j)
          for (int j2 = 0; j2 < 2; ++j2) {
            const Vec &a = xi[j], &b = eta[i], &c = zeta[i2][j2];
            L t{};
            const L d = det(a, b, c, t);
            const L na = norm1(a), nb = norm1(b), nc = norm1(c);
            const L err = 16 * kUnit * t + 2 * ev * (na * nb + nb * nc + nc * na) + 2 * ev * ev * (na + nb + nc) +
                          4 * ev * ev * ev;
            j_err = largest(j_err, err);
            det_max = largest(det_max, vabs(d));
            jac[i + i2][j + j2] += kW1[i][i2] * kW1[j][j2] * d;
          }
    // 2^-1000: gradual underflow
    j_err = lanes3::up<W>((j_err + rounding_gamma(4) * det_max) * (1 + 1e-12) + 0x1p-1000);
    L j_min = broadcast_lanes<W>(kInf);
    for (const auto& row : jac)
      for (const L& v : row) j_min = least(j_min, v);
    const L j_lo = lanes3::down<W>(j_min - j_err);
    ok &= j_lo > 0;

    // Per frame: the largest norm of each column over the corners (lower bound), and sj at
    // each corner (upper bound).
    const L en = 16 * e;  // a frame column's norm error
    L lower = broadcast_lanes<W>(kInf), upper = lower;
    for (const Frame& fr : space.frames()) {
      L big[3] = {};
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          L den = L{} + 1;
          for (std::size_t k = 0; k < 3; ++k) {
            Vec v{};
            for (std::size_t c = 0; c < 3; ++c)
              for (std::size_t a = 0; a < 3; ++a) v[a] += fr[k][c] * column(static_cast<int>(c), i, j)[a];
            const L n = lanes3::root<W>(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            ok &= n >= 2 * en;  // else a column may vanish at this corner
            big[k] = largest(big[k], n + en);
            den *= n - en;
          }
          upper = least(upper, (jac[2 * i][2 * j] + j_err) / den);
        }
      lower = least(lower, j_lo / (big[0] * big[1] * big[2]));
    }
    const L lo = lanes3::down<W>(space.s_lo() * lower * (1 - kSlack));
    const L hi = lanes3::up<W>(space.s_hi() * upper * (1 + kSlack));
    ok &= lanes3::up<W>(hi - lo) <= tol;
    return settled_lanes<W>(ok, lo, hi, out);
  }
};

}  // namespace

std::optional<QualityBounds> linear_pyramid_sj_bounds(const ScaledJacobianSpace& space, std::span<const double> x,
                                                      double tol) {
  Lanes<2> lanes[15];
  for (int i = 0; i < 15; ++i) lanes[i] = broadcast_lanes<2>(x[static_cast<std::size_t>(i)]);
  QualityBounds out[2];
  if ((PyramidLanes<2>::bounds(space, lanes, tol, out) & 1u) == 0) return std::nullopt;
  return out[0];
}

unsigned linear_pyramid_sj_lanes(const ScaledJacobianSpace& space, const Lanes<kNativeLanes>* x, double tol,
                                 QualityBounds* out) {
  return PyramidLanes<kNativeLanes>::bounds(space, x, tol, out);
}

}  // namespace quadval
