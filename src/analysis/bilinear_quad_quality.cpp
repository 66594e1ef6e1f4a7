// Closed-form quality bounds of bilinear quadrangles (see bilinear_quad_quality.hpp).
#include "analysis/bilinear_quad_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/straight_sided.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();
double down(double x) { return next_down(x); }
double up(double x) { return next_up(x); }

// An edge vector (x, y) of the first-order quadrangle, with bounds of its exact norm and
// squared norm.
struct Edge {
  double x, y, norm_lo, norm_hi, sq_lo, sq_hi;
};

Edge edge(std::span<const double> nodes, int to, int from) {
  Edge e;
  e.x = nodes[3 * static_cast<std::size_t>(to)] - nodes[3 * static_cast<std::size_t>(from)];
  e.y = nodes[3 * static_cast<std::size_t>(to) + 1] - nodes[3 * static_cast<std::size_t>(from) + 1];
  const double sq = e.x * e.x + e.y * e.y;
  const double n = sqrt_rn(sq);
  e.norm_lo = down(n * (1 - 1e-12));
  e.norm_hi = up(n * (1 + 1e-12));
  e.sq_lo = down(sq * (1 - 1e-12));
  e.sq_hi = up(sq * (1 + 1e-12));
  return e;
}

// One corner of the first-order quadrangle: its two edges (the columns there, times 2)
// and the bounds of their cross product.
struct Corner {
  const Edge* a;
  const Edge* b;
  double cross_lo, cross_hi;
};

// The element's corners and margins; false when it is not a planar bilinear quadrangle
// with J_1 proven positive at every corner, or its margin is infinite.
struct Quad {
  Edge e[2], f[2];
  std::array<Corner, 4> corner;
  double cross_lo = kInf;  // the least corner's
  double m = 0;            // |J - J_1| <= m
  std::array<double, 3> beta{0, 0, 0};

  bool read(const ElementType& type, std::span<const double> x, const KnownMargin* known) {
    if (type.family != ElementFamily::quadrangle || !in_a_z_plane(x)) return false;
    if (type.order > 1) {
      m = straight_margin_of(type, x.data(), known, beta);
      if (!(m < kInf)) return false;
    }
    // c_1 runs from e[0] / 2 (eta = -1) to e[1] / 2, c_2 from f[0] / 2 (xi = -1) to f[1] / 2.
    e[0] = edge(x, 1, 0);
    e[1] = edge(x, 2, 3);
    f[0] = edge(x, 3, 0);
    f[1] = edge(x, 2, 1);
    // Norms within [2^-400, 2^400]: their squares are normal numbers, within the relative
    // error bounds of `edge`.
    for (const Edge* g : {&e[0], &e[1], &f[0], &f[1]})
      if (!(g->norm_lo >= 0x1p-400 && g->norm_hi <= 0x1p400)) return false;
    // Corners 0..3 of Gmsh's quadrangle: (xi, eta) = (-1, -1), (1, -1), (1, 1), (-1, 1).
    constexpr int kE[4] = {0, 0, 1, 1}, kF[4] = {0, 1, 1, 0};
    for (std::size_t k = 0; k < 4; ++k) {
      Corner& c = corner[k];
      c.a = &e[kE[k]];
      c.b = &f[kF[k]];
      const double p = c.a->x * c.b->y, q = c.a->y * c.b->x;
      const double err = up(up(8 * kUnit * up(std::abs(p) + std::abs(q))) + 0x1p-1000);  // and gradual underflow
      c.cross_lo = down(p - q - err);
      c.cross_hi = up(up(p - q) + err);
      if (!(c.cross_lo > 0)) return false;  // J_1 not proven positive here
      cross_lo = std::min(cross_lo, c.cross_lo);
    }
    return true;
  }

  bool curved() const { return m > 0 || beta[0] > 0 || beta[1] > 0; }
  // J_1 >= j_lo() on the element, in the reference scale (J_1 = (a x b) / 4 at a corner).
  double j_lo() const { return cross_lo / 4; }
};

// mu at a corner: r = 2 / (g + sqrt(g^2 - 4)), g = (|a|^2 + |b|^2) / (a x b), decreasing in g.
double corner_mu_lower(const Corner& c) {
  const double g = up(up(c.a->sq_hi + c.b->sq_hi) / c.cross_lo);
  return down(2 / up(g + up(sqrt_rn(up(up(g * g) - 4)))));
}
double corner_mu_upper(const Corner& c) {
  const double g = down(down(c.a->sq_lo + c.b->sq_lo) / c.cross_hi);
  return std::min(1.0, up(2 / down(g + down(sqrt_rn(std::max(0.0, down(down(g * g) - 4)))))));
}

std::optional<QualityBounds> within(QualityBounds out, double tol) {
  if (!(out.lower > 0) || !(out.upper < kInf)) return std::nullopt;
  out.tolerance_met = up(out.upper - out.lower) <= tol;
  if (!out.tolerance_met) return std::nullopt;
  return out;
}

}  // namespace

std::optional<QualityBounds> bilinear_quad_sj_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known) {
  Quad quad;
  if (!quad.read(type, x, known)) return std::nullopt;
  double s_lo = kInf, upper = kInf;
  const Corner* least = nullptr;
  for (const Corner& c : quad.corner) {
    s_lo = std::min(s_lo, down(c.cross_lo / up(c.a->norm_hi * c.b->norm_hi)));
    const double hi = up(c.cross_hi / down(c.a->norm_lo * c.b->norm_lo));
    if (hi < upper) {
      upper = hi;
      least = &c;
    }
  }
  QualityBounds out{s_lo, upper, 0, false};
  if (quad.curved()) {
    const double j_lo = quad.j_lo(), m = quad.m;
    if (!(j_lo > m) || least == nullptr) return std::nullopt;
    const double a_max = std::max(quad.e[0].norm_hi, quad.e[1].norm_hi) / 2;
    const double b_max = std::max(quad.f[0].norm_hi, quad.f[1].norm_hi) / 2;
    const double a_lo = down(j_lo / b_max), b_lo = down(j_lo / a_max);
    const double shrink = up(up(1 + up(quad.beta[0] / a_lo)) * up(1 + up(quad.beta[1] / b_lo)));
    out.lower = down(down(s_lo * down(1 - up(m / j_lo))) / shrink);
    const double a = down(least->a->norm_lo / 2 - quad.beta[0]), b = down(least->b->norm_lo / 2 - quad.beta[1]);
    if (!(a > 0) || !(b > 0)) return std::nullopt;
    out.upper = up(up(least->cross_hi / 4 + m) / down(a * b));
  }
  out.upper = std::min(out.upper, 1.0);  // sj <= 1 for quadrangles (Hadamard)
  return within(out, tol);
}

std::optional<QualityBounds> bilinear_quad_mu_bounds(const ElementType& type, std::span<const double> x,
                                                     double tol, const KnownMargin* known) {
  Quad quad;
  if (!quad.read(type, x, known)) return std::nullopt;
  double r_lo = kInf, upper = kInf;
  const Corner* least = nullptr;
  for (const Corner& c : quad.corner) {
    r_lo = std::min(r_lo, corner_mu_lower(c));
    const double hi = corner_mu_upper(c);
    if (hi < upper) {
      upper = hi;
      least = &c;
    }
  }
  QualityBounds out{r_lo, upper, 0, false};
  if (quad.curved()) {
    if (least == nullptr) return std::nullopt;
    const double eps = up(sqrt_rn(up(up(quad.beta[0] * quad.beta[0]) + up(quad.beta[1] * quad.beta[1]))));
    const double s = down(sqrt_rn(quad.j_lo()));
    out.lower = down(down(down(r_lo * s) - eps) / up(s + eps));
    // At the least corner (columns a / 2, b / 2): sigma_max^2 = (t + sqrt(t^2 - 4 p^2)) / 2
    // with t = |c_1|^2 + |c_2|^2 and p = J_1, and sigma_min = p / sigma_max.
    const double t_lo = down(down(least->a->sq_lo + least->b->sq_lo) / 4), p_hi = up(least->cross_hi / 4);
    const double p_lo = down(least->cross_lo / 4);
    const double disc = std::max(0.0, down(down(t_lo * t_lo) - up(4 * up(p_hi * p_hi))));
    const double max_lo = down(sqrt_rn(down(down(t_lo + down(sqrt_rn(disc))) / 2)));
    const double min_hi = up(p_hi / max_lo);
    if (!(max_lo > eps) || !(p_lo > 0)) return std::nullopt;
    out.upper = std::min(1.0, up(up(min_hi + eps) / down(max_lo - eps)));
  }
  return within(out, tol);
}

}  // namespace quadval
