// Closed-form quality bounds of bilinear quadrangles (see bilinear_quad_quality.hpp).
#include "analysis/bilinear_quad_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "analysis/outward_rounding.hpp"
#include "analysis/scalar_or_lanes.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/straight_sided.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();

// T = double for one element, LaneBlock for one element per lane: the same operations, so
// the same bits (scalar_or_lanes.hpp).
using namespace scalar_or_lanes;
template <class T>
using MaskOf = decltype(T{} < T{});
// Logical not of a bool or of a lane mask (all ones or zero per lane).
template <class M>
M negation(M m) {
  return m == M{};
}
// Whether a bool, or any lane of a mask, is true.
template <class M>
bool any_lane(M m) {
  if constexpr (std::is_same_v<M, bool>) {
    return m;
  } else {
    for (std::size_t l = 0; l < sizeof(M) / sizeof(m[0]); ++l)
      if (m[l] != 0) return true;
    return false;
  }
}

// An edge vector (x, y) of the first-order quadrangle, with bounds of its exact norm and
// squared norm.
template <class T>
struct Edge {
  T x, y, norm_lo, norm_hi, sq_lo, sq_hi;
};

template <class T>
Edge<T> edge(const T* p, int to, int from) {
  Edge<T> e;
  e.x = p[2 * to] - p[2 * from];
  e.y = p[2 * to + 1] - p[2 * from + 1];
  const T sq = e.x * e.x + e.y * e.y;
  const T n = root(sq);
  e.norm_lo = down(n * (1 - 1e-12));
  e.norm_hi = up(n * (1 + 1e-12));
  e.sq_lo = down(sq * (1 - 1e-12));
  e.sq_hi = up(sq * (1 + 1e-12));
  return e;
}

// One corner of the first-order quadrangle: its two edges (the columns there, times 2)
// and the bounds of their cross product.
template <class T>
struct Corner {
  const Edge<T>* a;
  const Edge<T>* b;
  T cross_lo, cross_hi;
};

// The element's corners and margins; ok false where J_1 is not proven positive at every
// corner or an edge's norm is out of range.
template <class T>
struct Quad {
  Edge<T> e[2], f[2];
  std::array<Corner<T>, 4> corner;
  T cross_lo = T{} + kInf;  // the least corner's
  T m{};                    // |J - J_1| <= m
  T beta[2]{};
  MaskOf<T> ok{};

  // p: x, y of vertices 0..3; the margins as straight_margin_of's (0 at order 1).
  Quad(const T* p, T margin, T beta0, T beta1) : m(margin), beta{beta0, beta1} {
    // c_1 runs from e[0] / 2 (eta = -1) to e[1] / 2, c_2 from f[0] / 2 (xi = -1) to f[1] / 2.
    e[0] = edge(p, 1, 0);
    e[1] = edge(p, 2, 3);
    f[0] = edge(p, 3, 0);
    f[1] = edge(p, 2, 1);
    // Norms within [2^-400, 2^400]: their squares are normal numbers, within the relative
    // error bounds of `edge`.
    ok = T{} == T{};
    for (const Edge<T>* g : {&e[0], &e[1], &f[0], &f[1]}) ok = ok & (g->norm_lo >= 0x1p-400) & (g->norm_hi <= 0x1p400);
    // Corners 0..3 of Gmsh's quadrangle: (xi, eta) = (-1, -1), (1, -1), (1, 1), (-1, 1).
    constexpr int kE[4] = {0, 0, 1, 1}, kF[4] = {0, 1, 1, 0};
    for (std::size_t k = 0; k < 4; ++k) {
      Corner<T>& c = corner[k];
      c.a = &e[kE[k]];
      c.b = &f[kF[k]];
      const T p0 = c.a->x * c.b->y, q0 = c.a->y * c.b->x;
      const T err = up(up(8 * kUnit * up(vabs(p0) + vabs(q0))) + 0x1p-1000);  // and gradual underflow
      c.cross_lo = down(p0 - q0 - err);
      c.cross_hi = up(up(p0 - q0) + err);
      ok = ok & (c.cross_lo > 0);  // else J_1 not proven positive here
      cross_lo = vmin(cross_lo, c.cross_lo);
    }
  }
  Quad(const Quad&) = delete;  // the corners point into the edges

  MaskOf<T> curved() const { return (m > 0) | (beta[0] > 0) | (beta[1] > 0); }
  // J_1 >= j_lo() on the element, in the reference scale (J_1 = (a x b) / 4 at a corner).
  T j_lo() const { return cross_lo / 4; }
};

template <class T>
struct Bounds {
  T lower, upper;
  MaskOf<T> ok;  ///< where these bounds hold and meet the tolerance
};

template <class T>
void within(Bounds<T>& out, double tol) {
  out.ok = out.ok & (out.lower > 0) & (out.upper < kInf);
  out.ok = out.ok & (up(out.upper - out.lower) <= tol);
}

// mu at a corner: r = 2 / (g + sqrt(g^2 - 4)), g = (|a|^2 + |b|^2) / (a x b), decreasing in g.
template <class T>
T corner_mu_lower(const Corner<T>& c) {
  const T g = up(up(c.a->sq_hi + c.b->sq_hi) / c.cross_lo);
  return down(2 / up(g + up(root(up(up(g * g) - 4)))));
}
template <class T>
T corner_mu_upper(const Corner<T>& c) {
  const T g = down(down(c.a->sq_lo + c.b->sq_lo) / c.cross_hi);
  return vmin(T{} + 1, up(2 / down(g + down(root(vmax(T{}, down(down(g * g) - 4)))))));
}

template <class T>
Bounds<T> sj_bounds(const Quad<T>& quad, double tol) {
  T s_lo = T{} + kInf, upper = T{} + kInf;
  // The corner of least upper bound (the first of them): its values.
  MaskOf<T> found{};
  T least_cross_hi{}, least_a_norm_lo{}, least_b_norm_lo{};
  for (const Corner<T>& c : quad.corner) {
    s_lo = vmin(s_lo, down(c.cross_lo / up(c.a->norm_hi * c.b->norm_hi)));
    const T hi = up(c.cross_hi / down(c.a->norm_lo * c.b->norm_lo));
    const MaskOf<T> better = hi < upper;
    upper = better ? hi : upper;
    least_cross_hi = better ? c.cross_hi : least_cross_hi;
    least_a_norm_lo = better ? c.a->norm_lo : least_a_norm_lo;
    least_b_norm_lo = better ? c.b->norm_lo : least_b_norm_lo;
    found = found | better;
  }
  Bounds<T> out{s_lo, upper, quad.ok};
  // Curved (none at order 1: skipped): widened by the margins.
  const MaskOf<T> curved = quad.curved();
  if (any_lane(curved)) {
    const T j_lo = quad.j_lo(), m = quad.m;
    const T a_max = vmax(quad.e[0].norm_hi, quad.e[1].norm_hi) / 2;
    const T b_max = vmax(quad.f[0].norm_hi, quad.f[1].norm_hi) / 2;
    const T a_lo = down(j_lo / b_max), b_lo = down(j_lo / a_max);
    const T shrink = up(up(1 + up(quad.beta[0] / a_lo)) * up(1 + up(quad.beta[1] / b_lo)));
    const T a = down(least_a_norm_lo / 2 - quad.beta[0]), b = down(least_b_norm_lo / 2 - quad.beta[1]);
    out.ok = out.ok & (negation(curved) | ((j_lo > m) & found & (a > 0) & (b > 0)));
    out.lower = curved ? down(down(s_lo * down(1 - up(m / j_lo))) / shrink) : out.lower;
    out.upper = curved ? up(up(least_cross_hi / 4 + m) / down(a * b)) : out.upper;
  }
  out.upper = vmin(out.upper, T{} + 1);  // sj <= 1 for quadrangles (Hadamard)
  within(out, tol);
  return out;
}

template <class T>
Bounds<T> mu_bounds(const Quad<T>& quad, double tol) {
  T r_lo = T{} + kInf, upper = T{} + kInf;
  MaskOf<T> found{};
  T least_sq{}, least_cross_hi{}, least_cross_lo{};  // the least corner's |a|^2 + |b|^2 (low) and a x b
  for (const Corner<T>& c : quad.corner) {
    r_lo = vmin(r_lo, corner_mu_lower(c));
    const T hi = corner_mu_upper(c);
    const MaskOf<T> better = hi < upper;
    upper = better ? hi : upper;
    least_sq = better ? down(c.a->sq_lo + c.b->sq_lo) : least_sq;
    least_cross_hi = better ? c.cross_hi : least_cross_hi;
    least_cross_lo = better ? c.cross_lo : least_cross_lo;
    found = found | better;
  }
  Bounds<T> out{r_lo, upper, quad.ok};
  // Curved (none at order 1: skipped): the singular values move by at most eps.
  const MaskOf<T> curved = quad.curved();
  if (any_lane(curved)) {
    const T eps = up(root(up(up(quad.beta[0] * quad.beta[0]) + up(quad.beta[1] * quad.beta[1]))));
    const T s = down(root(quad.j_lo()));
    // At the least corner (columns a / 2, b / 2): sigma_max^2 = (t + sqrt(t^2 - 4 p^2)) / 2
    // with t = |c_1|^2 + |c_2|^2 and p = J_1, and sigma_min = p / sigma_max.
    const T t_lo = down(least_sq / 4), p_hi = up(least_cross_hi / 4);
    const T p_lo = down(least_cross_lo / 4);
    const T disc = vmax(T{}, down(down(t_lo * t_lo) - up(4 * up(p_hi * p_hi))));
    const T max_lo = down(root(down(down(t_lo + down(root(disc))) / 2)));
    const T min_hi = up(p_hi / max_lo);
    out.ok = out.ok & (negation(curved) | (found & (max_lo > eps) & (p_lo > 0)));
    out.lower = curved ? down(down(down(r_lo * s) - eps) / up(s + eps)) : out.lower;
    out.upper = curved ? vmin(T{} + 1, up(up(min_hi + eps) / down(max_lo - eps))) : out.upper;
  }
  within(out, tol);
  return out;
}

// The planar quadrangle of nodes x as Quad<double>'s input; false when it is not one, or
// its nodes are off the bilinear map by more than the margin allows.
bool quad_input(const ElementType& type, std::span<const double> x, const KnownMargin* known, double* p,
                double& m, std::array<double, 3>& beta) {
  if (type.family != ElementFamily::quadrangle || !in_a_z_plane(x)) return false;
  m = 0;
  beta = {0, 0, 0};
  if (type.order > 1) {
    m = straight_margin_of(type, x.data(), known, beta);
    if (!(m < kInf)) return false;
  }
  for (std::size_t k = 0; k < 4; ++k) {
    p[2 * k] = x[3 * k];
    p[2 * k + 1] = x[3 * k + 1];
  }
  return true;
}

template <class Measure>
std::optional<QualityBounds> one_quad(const ElementType& type, std::span<const double> x, double tol,
                                      const KnownMargin* known, Measure measure) {
  double p[8], m;
  std::array<double, 3> beta;
  if (!quad_input(type, x, known, p, m, beta)) return std::nullopt;
  const Quad<double> quad(p, m, beta[0], beta[1]);
  if (!quad.ok) return std::nullopt;
  const Bounds<double> b = measure(quad, tol);
  if (!b.ok) return std::nullopt;
  return QualityBounds{b.lower, b.upper, 0, true};
}

template <class Measure>
unsigned quad_lanes(const LaneBlock* p, const LaneBlock* beta, LaneBlock margin, double tol, QualityBounds* out,
                    Measure measure) {
  const Quad<LaneBlock> quad(p, margin, beta[0], beta[1]);
  const Bounds<LaneBlock> b = measure(quad, tol);
  const unsigned done = lanes3::mask_bits<kNativeLanes>(b.ok & (margin < kInf));
  for (int l = 0; l < kNativeLanes; ++l)
    if ((done >> l) & 1u) out[l] = QualityBounds{b.lower[l], b.upper[l], 0, true};
  return done;
}

}  // namespace

std::optional<QualityBounds> bilinear_quad_sj_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known) {
  return one_quad(type, x, tol, known, [](const Quad<double>& q, double t) { return sj_bounds(q, t); });
}

std::optional<QualityBounds> bilinear_quad_mu_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known) {
  return one_quad(type, x, tol, known, [](const Quad<double>& q, double t) { return mu_bounds(q, t); });
}

unsigned bilinear_quad_sj_lanes(const Lanes<kNativeLanes>* xy, const Lanes<kNativeLanes>* beta,
                                Lanes<kNativeLanes> margin, double tol, QualityBounds* out) {
  return quad_lanes(xy, beta, margin, tol, out, [](const Quad<LaneBlock>& q, double t) { return sj_bounds(q, t); });
}

unsigned bilinear_quad_mu_lanes(const Lanes<kNativeLanes>* xy, const Lanes<kNativeLanes>* beta,
                                Lanes<kNativeLanes> margin, double tol, QualityBounds* out) {
  return quad_lanes(xy, beta, margin, tol, out, [](const Quad<LaneBlock>& q, double t) { return mu_bounds(q, t); });
}

}  // namespace quadval
