// The root bound of the scaled Jacobian of first-order hexahedra (see trilinear_hex_sj.hpp).
#include "analysis/trilinear_hex_sj.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "analysis/edge_determinants.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/bezier_basis.hpp"

namespace quadval {
namespace {

using edge_determinants::kW1;
using edge_determinants::settled_lanes;

constexpr double kUnit = 0x1p-53;
// Edges of 1-norm within [2^-100, 2^100]: every norm, square and product of six of them is
// a normal number.
constexpr double kSmall = 0x1p-100, kLarge = 0x1p100;

// Gmsh's vertex at reference index (i, j, k) in {0, 1}^3 (0: -1, 1: +1).
constexpr int kVertex[2][2][2] = {{{0, 4}, {3, 7}}, {{1, 5}, {2, 6}}};

// One hexahedron per lane: every operation is the scalar one lane by lane, so a lane gets
// the bits of its element alone (which runs in two lanes, trilinear_hex_sj_bounds).
template <int W>
struct HexLanes {
  using L = Lanes<W>;
  using Vec = std::array<L, 3>;

  static L up(L x) { return lanes3::up<W>(x); }
  static L down(L x) { return lanes3::down<W>(x); }
  // A bound widened to cover the rounding of its own computation, and 2^-1000 for gradual
  // underflow (which the relative error model above does not cover).
  static L widen(L e) { return up(up(e * (1 + 1e-12)) + 0x1p-1000); }
  static L norm1(const Vec& v) { return vabs(v[0]) + vabs(v[1]) + vabs(v[2]); }
  static L dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  // std::min(m, x) and std::max(m, x) as the scalar code takes them.
  static L least(L m, L x) { return x < m ? x : m; }
  static L largest(L m, L x) { return m < x ? x : m; }

  // det[a, b, c] as a . (b x c); t receives T, the sum of its six triple products'
  // magnitudes (edge_determinants.hpp).
  static L det(const Vec& a, const Vec& b, const Vec& c, L& t) {
    t = vabs(a[0]) * (vabs(b[1] * c[2]) + vabs(b[2] * c[1])) + vabs(a[1]) * (vabs(b[2] * c[0]) + vabs(b[0] * c[2])) +
        vabs(a[2]) * (vabs(b[0] * c[1]) + vabs(b[1] * c[0]));
    return a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }

  // The squared norm |c|^2 of a bilinear column with control points e[i][j] (degree 2 per
  // axis, 9 coefficients s[i][j]); returns the error bound, `m` the largest magnitude.
  static L squared_norm(const Vec (&e)[2][2], L (&s)[3][3], L& m) {
    L big{};  // the largest 1-norm of the edges
    for (const auto& row : e)
      for (const Vec& v : row) big = largest(big, norm1(v));
    for (auto& row : s) std::fill(std::begin(row), std::end(row), L{});
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k)
          for (int l = 0; l < 2; ++l) s[i + k][j + l] += kW1[i][k] * kW1[j][l] * dot(e[i][j], e[k][l]);
    m = L{};
    for (const auto& row : s)
      for (const L& v : row) m = largest(m, vabs(v));
    return widen((8 * kUnit + rounding_gamma(4)) * big * big);
  }

  // x[3 v + k]: vertex v's coordinate k, per lane. Bit l of the result set where out[l]
  // holds lane l's bounds.
  static unsigned bounds(const L* x, double tol, QualityBounds* out) {
    const auto vertex = [&](int i, int j, int k) {
      const int v = kVertex[i][j][k];
      return Vec{x[3 * v], x[3 * v + 1], x[3 * v + 2]};
    };
    const auto minus = [](const Vec& a, const Vec& b) { return Vec{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
    // The edges: e1[j][k] along xi at (eta, zeta) = (j, k), e2[i][k] along eta, e3[i][j]
    // along zeta.
    Vec e1[2][2], e2[2][2], e3[2][2];
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        e1[a][b] = minus(vertex(1, a, b), vertex(0, a, b));
        e2[a][b] = minus(vertex(a, 1, b), vertex(a, 0, b));
        e3[a][b] = minus(vertex(a, b, 1), vertex(a, b, 0));
      }
    lanes3::Mask<W> ok = lanes3::Mask<W>{} - 1;
    for (const auto* e : {&e1, &e2, &e3})
      for (const auto& row : *e)
        for (const Vec& v : row) ok &= (norm1(v) >= kSmall) & (norm1(v) <= kLarge);
    if (lanes3::mask_bits<W>(ok) == 0) return 0;

    // J: coefficient (p, q, r) gathers det[e1[b][c], e2[a][c'], e3[a'][b']] with p = a + a',
    // q = b + b', r = c + c'; each cross product e2 x e3 (and its terms' magnitudes, for T)
    // serves the four xi-edges.
    L jac[3][3][3] = {};
    L t_max{}, det_max{};
    for (int a = 0; a < 2; ++a)
      for (int c2 = 0; c2 < 2; ++c2)
        for (int a2 = 0; a2 < 2; ++a2)
          for (int b2 = 0; b2 < 2; ++b2) {
            const Vec& v = e2[a][c2];
            const Vec& w = e3[a2][b2];
            const Vec cr = {v[1] * w[2] - v[2] * w[1], v[2] * w[0] - v[0] * w[2], v[0] * w[1] - v[1] * w[0]};
            const Vec mag = {vabs(v[1] * w[2]) + vabs(v[2] * w[1]), vabs(v[2] * w[0]) + vabs(v[0] * w[2]),
                             vabs(v[0] * w[1]) + vabs(v[1] * w[0])};
            for (int b = 0; b < 2; ++b)
              for (int c = 0; c < 2; ++c) {
                const Vec& e = e1[b][c];
                const L d = dot(e, cr);
                t_max = largest(t_max, vabs(e[0]) * mag[0] + vabs(e[1]) * mag[1] + vabs(e[2]) * mag[2]);
                det_max = largest(det_max, vabs(d));
                jac[a + a2][b + b2][c + c2] += kW1[a][a2] * kW1[b][b2] * kW1[c][c2] * d;
              }
          }
    const L e_j = widen(16 * kUnit * t_max + rounding_gamma(8) * det_max);
    L m_j{};
    for (const auto& plane : jac)
      for (const auto& row : plane)
        for (const L& v : row) m_j = largest(m_j, vabs(v));

    // The squared column norms: s1 in (eta, zeta), s2 in (xi, zeta), s3 in (xi, eta).
    L s1[3][3], s2[3][3], s3[3][3], m1{}, m2{}, m3{};
    const L e1s = squared_norm(e1, s1, m1), e2s = squared_norm(e2, s2, m2), e3s = squared_norm(e3, s3, m3);

    // N = J^2 and D = s1 s2 s3, degree 4 per axis, as scaled convolutions: a coefficient of
    // degree 2 times C(2, i) per axis (1, 2, 1: exact), the sums of products, then divided
    // by C(4, k) per axis, which makes the weights C(2,i) C(2,j) / C(4,i+j) of the product.
    constexpr double kC2[3] = {1, 2, 1};
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) {
        for (int r = 0; r < 3; ++r) jac[p][q][r] *= kC2[p] * kC2[q] * kC2[r];
        s1[p][q] *= kC2[p] * kC2[q];
        s2[p][q] *= kC2[p] * kC2[q];
        s3[p][q] *= kC2[p] * kC2[q];
      }
    L n[5][5][5] = {}, d[5][5][5] = {};
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q)
        for (int r = 0; r < 3; ++r)
          for (int p2 = 0; p2 < 3; ++p2)
            for (int q2 = 0; q2 < 3; ++q2)
              for (int r2 = 0; r2 < 3; ++r2) n[p + p2][q + q2][r + r2] += jac[p][q][r] * jac[p2][q2][r2];
    // s1 s2 first: (eta, zeta) x (xi, zeta) -> [eta q1][zeta r][xi p2], then times s3 [p3][q3].
    L s12[3][5][3] = {};
    for (int q1 = 0; q1 < 3; ++q1)
      for (int r1 = 0; r1 < 3; ++r1)
        for (int r2 = 0; r2 < 3; ++r2)
          for (int p2 = 0; p2 < 3; ++p2) s12[q1][r1 + r2][p2] += s1[q1][r1] * s2[p2][r2];
    for (int p2 = 0; p2 < 3; ++p2)
      for (int p3 = 0; p3 < 3; ++p3)
        for (int q1 = 0; q1 < 3; ++q1)
          for (int q3 = 0; q3 < 3; ++q3)
            for (int r = 0; r < 5; ++r) d[p2 + p3][q1 + q3][r] += s12[q1][r][p2] * s3[p3][q3];
    constexpr double kInvC4[5] = {1, 0.25, 1.0 / 6, 0.25, 1};
    for (int p = 0; p < 5; ++p)
      for (int q = 0; q < 5; ++q)
        for (int r = 0; r < 5; ++r) {
          const double w = kInvC4[p] * kInvC4[q] * kInvC4[r];
          n[p][q][r] *= w;
          d[p][q][r] *= w;
        }
    const L e_n = widen(e_j * m_j + (m_j + e_j) * e_j + rounding_gamma(40) * m_j * m_j);
    const L e_d = widen(e1s * (m2 + e2s) * (m3 + e3s) + (m1 + e1s) * e2s * (m3 + e3s) + (m1 + e1s) * (m2 + e2s) * e3s +
                        rounding_gamma(40) * m1 * m2 * m3);
    ok &= lanes3::finite<W>(e_n) & lanes3::finite<W>(e_d);  // else an overflow

    // The relaxation: sj^2 >= min_i (N_i - e_n) / (D_i + e_d), every D_i - e_d > 0: the
    // least quotient (NaN ignored) and the least denominator, as scan_ratios finds them.
    const L* nv = &n[0][0][0];
    const L* dv = &d[0][0][0];
    L extreme = broadcast_lanes<W>(std::numeric_limits<double>::infinity()), least_den = extreme;
    for (int i = 0; i < 125; ++i) {
      extreme = least(extreme, (nv[i] - e_n) / (dv[i] + e_d));
      least_den = least(least_den, dv[i] - e_d);
    }
    ok &= least_den > 0;
    // quotient_below (ratio_scan.hpp) where the least quotient is positive.
    const L below = down(down(extreme * (extreme < 0 ? L{} + (1 + 4 * kUnit) : L{} + (1 - 4 * kUnit))) -
                         std::numeric_limits<double>::denorm_min());
    const L r_lo = extreme > 0 ? below : L{};
    const L lower = r_lo > 0 ? down(lanes3::root<W>(r_lo)) : L{};
    // Upper: sj at the corners, where the columns are the three edges there.
    L upper = L{} + 1;  // Hadamard
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int c = 0; c < 2; ++c) {
          const Vec& u1 = e1[b][c];
          const Vec& u2 = e2[a][c];
          const Vec& u3 = e3[a][b];
          L t{};
          const L j = det(u1, u2, u3, t);
          const L den = down(lanes3::root<W>(dot(u1, u1)) * lanes3::root<W>(dot(u2, u2)) *
                             lanes3::root<W>(dot(u3, u3)) * (1 - 1e-12));
          upper = den > 0 ? least(upper, up(up(j + widen(16 * kUnit * t)) / (den > 0 ? den : L{} + 1))) : upper;
        }
    ok &= up(upper - lower) <= tol;
    return settled_lanes<W>(ok, lower, upper, out);
  }
};

}  // namespace

std::optional<QualityBounds> trilinear_hex_sj_bounds(std::span<const double> x, double tol) {
  Lanes<2> lanes[24];
  for (int i = 0; i < 24; ++i) lanes[i] = broadcast_lanes<2>(x[static_cast<std::size_t>(i)]);
  QualityBounds out[2];
  if ((HexLanes<2>::bounds(lanes, tol, out) & 1u) == 0) return std::nullopt;
  return out[0];
}

unsigned trilinear_hex_sj_lanes(const Lanes<kNativeLanes>* x, double tol, QualityBounds* out) {
  return HexLanes<kNativeLanes>::bounds(x, tol, out);
}

}  // namespace quadval
