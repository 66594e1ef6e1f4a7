// Fast certified Jacobian coefficients of first-order elements; derivation and error bound
// in linear_jacobian.hpp. One element's arithmetic is written once (templates over how a
// coordinate is read) and used both per element and, inlined, across a chunk of elements.
#include "analysis/linear_jacobian.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "analysis/outward_rounding.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kErrFactor = 0x1p-48;  // 32 u, u = 2^-53 (linear_jacobian.hpp)
constexpr double kMinNorm = 0x1p-200, kMaxNorm = 0x1p200;

// The element arithmetic is written once over T: double (one element) or Lanes (kLanes
// elements side by side, GCC vector extension: the same IEEE operations lane by lane, so
// the results are bit-identical to the scalar ones; -ffp-contract=off applies to both).
constexpr int kLanes = 8;
using Lanes = double __attribute__((vector_size(kLanes * sizeof(double))));
static_assert(kLinearChunk % kLanes == 0);

inline double vabs(double a) { return std::abs(a); }
inline Lanes vabs(Lanes a) { return a < 0 ? -a : a; }
inline double vmin(double a, double b) { return b < a ? b : a; }
inline Lanes vmin(Lanes a, Lanes b) { return b < a ? b : a; }
inline double vmax(double a, double b) { return a < b ? b : a; }
inline Lanes vmax(Lanes a, Lanes b) { return a < b ? b : a; }

template <class T>
struct Vec3 {
  T x, y, z;
};
template <class T>
inline Vec3<T> sub(Vec3<T> a, Vec3<T> b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T>
inline Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T dot(Vec3<T> a, Vec3<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T>
inline T norm1(Vec3<T> a) { return vabs(a.x) + vabs(a.y) + vabs(a.z); }

// err for the product of the three (two) largest edge 1-norms, scaled by the exact
// reference factor; +inf (never settles anything) outside the guarded range or for NaN.
inline double error_of(double l0, double l1, double l2, double scale) {
  const bool ok = l0 >= kMinNorm && l0 <= kMaxNorm && l1 >= kMinNorm && l1 <= kMaxNorm &&
                  l2 >= kMinNorm && l2 <= kMaxNorm;
  return ok ? kErrFactor * scale * (l0 * l1 * l2) : kInf;
}
inline Lanes error_of(Lanes l0, Lanes l1, Lanes l2, double scale) {
  const auto ok = (l0 >= kMinNorm) & (l0 <= kMaxNorm) & (l1 >= kMinNorm) & (l1 <= kMaxNorm) &
                  (l2 >= kMinNorm) & (l2 <= kMaxNorm);
  const Lanes err = kErrFactor * scale * (l0 * l1 * l2);
  const Lanes inf = err * 0 + kInf;
  return ok ? err : inf;
}

// Gmsh hexahedron vertex of (a, b, c) in {0,1}^3.
constexpr int kHexVertex[2][2][2] = {{{0, 4}, {3, 7}}, {{1, 5}, {2, 6}}};  // [a][b][c]

// Hexahedron: 27 coefficients c[i + 3j + 9k]; returns err (before rounding up).
template <class T, class Point>
inline T hex_coefficients(Point p, T* c) {
  Vec3<T> eu[2][2], ev[2][2], ew[2][2];  // eu[b][c], ev[a][c], ew[a][b]
  T lu{}, lv{}, lw{};
  #pragma GCC unroll 2
  for (int s = 0; s < 2; ++s)
    #pragma GCC unroll 2
    for (int t = 0; t < 2; ++t) {
      eu[s][t] = sub(p(kHexVertex[1][s][t]), p(kHexVertex[0][s][t]));
      ev[s][t] = sub(p(kHexVertex[s][1][t]), p(kHexVertex[s][0][t]));
      ew[s][t] = sub(p(kHexVertex[s][t][1]), p(kHexVertex[s][t][0]));
      lu = vmax(lu, norm1(eu[s][t]));
      lv = vmax(lv, norm1(ev[s][t]));
      lw = vmax(lw, norm1(ew[s][t]));
    }
  // vw[a'][c'][a"][b"] = ev[a'][c'] x ew[a"][b"]
  Vec3<T> vw[2][2][2][2];
  #pragma GCC unroll 2
  for (int a1 = 0; a1 < 2; ++a1)
    #pragma GCC unroll 2
    for (int c1 = 0; c1 < 2; ++c1)
      #pragma GCC unroll 2
      for (int a2 = 0; a2 < 2; ++a2)
        #pragma GCC unroll 2
        for (int b2 = 0; b2 < 2; ++b2) vw[a1][c1][a2][b2] = cross(ev[a1][c1], ew[a2][b2]);
  // Every det[eu_bc, ev_a'c', ew_a"b"] goes, with its weight 1/(number of terms) (exact:
  // 1/2 per mixed pair), into coefficient (a' + a", b + b", c + c'): a plain mean.
  #pragma GCC unroll 27
  for (int n = 0; n < 27; ++n) c[n] = T{};
  #pragma GCC unroll 2
  for (int a1 = 0; a1 < 2; ++a1)
    #pragma GCC unroll 2
    for (int c1 = 0; c1 < 2; ++c1)
      #pragma GCC unroll 2
      for (int a2 = 0; a2 < 2; ++a2)
        #pragma GCC unroll 2
        for (int b2 = 0; b2 < 2; ++b2)
          #pragma GCC unroll 2
          for (int b = 0; b < 2; ++b)
            #pragma GCC unroll 2
            for (int cc = 0; cc < 2; ++cc) {
              const double w = (a1 != a2 ? 0.5 : 1.0) * (b != b2 ? 0.5 : 1.0) * (cc != c1 ? 0.5 : 1.0);
              c[(a1 + a2) + 3 * (b + b2) + 9 * (cc + c1)] += w * dot(eu[b][cc], vw[a1][c1][a2][b2]);
            }
  // the 1/8 of Gmsh's [-1,1]^3 (exact)
  #pragma GCC unroll 27
  for (int n = 0; n < 27; ++n) c[n] *= 0.125;
  return error_of(lu, lv, lw, 0.125);
}

// Quadrangle: c[a + 2b] = J at vertex (a, b) (Gmsh order 0..3 is ab = 00 10 11 01).
template <class T, class Point>
inline T quad_coefficients(Point p, T* c) {
  constexpr int kQuadVertex[2][2] = {{0, 3}, {1, 2}};  // [a][b]
  Vec3<T> eu[2], ev[2];
  T lu{}, lv{};
  #pragma GCC unroll 2
  for (int s = 0; s < 2; ++s) {
    eu[s] = sub(p(kQuadVertex[1][s]), p(kQuadVertex[0][s]));
    ev[s] = sub(p(kQuadVertex[s][1]), p(kQuadVertex[s][0]));
    eu[s].z = ev[s].z = T{};  // planar: J = x_u y_v - x_v y_u
    lu = vmax(lu, norm1(eu[s]));
    lv = vmax(lv, norm1(ev[s]));
  }
  #pragma GCC unroll 2
  for (int a = 0; a < 2; ++a)
    #pragma GCC unroll 2
    for (int b = 0; b < 2; ++b) c[a + 2 * b] = (eu[b].x * ev[a].y - ev[a].x * eu[b].y) * 0.25;
  return error_of(lu, lv, lv * 0 + 1, 0.25);
}

template <class T, class Point>
inline T tet_coefficients(Point p, T* c) {
  const Vec3<T> a = sub(p(1), p(0)), b = sub(p(2), p(0)), d = sub(p(3), p(0));
  c[0] = dot(a, cross(b, d));
  return error_of(norm1(a), norm1(b), norm1(d), 1);
}

template <class T, class Point>
inline T triangle_coefficients(Point p, T* c) {
  Vec3<T> a = sub(p(1), p(0)), b = sub(p(2), p(0));
  a.z = b.z = T{};
  c[0] = a.x * b.y - b.x * a.y;
  const T la = norm1(a);
  return error_of(la, norm1(b), la * 0 + 1, 1);
}

template <class T, class Point>
inline T coefficients_of(LinearKind kind, Point p, T* c) {
  switch (kind) {
    case LinearKind::hexahedron: return hex_coefficients(p, c);
    case LinearKind::quadrangle: return quad_coefficients(p, c);
    case LinearKind::tetrahedron: return tet_coefficients(p, c);
    case LinearKind::triangle: return triangle_coefficients(p, c);
    case LinearKind::none: break;
  }
  return c[0] * 0 + kInf;
}

constexpr int num_coefficients(LinearKind kind) {
  return kind == LinearKind::hexahedron ? 27 : kind == LinearKind::quadrangle ? 4 : 1;
}

// Indices of the vertex coefficients (values of J).
constexpr bool is_vertex_coefficient(LinearKind kind, int n) {
  if (kind != LinearKind::hexahedron) return true;
  return n % 3 != 1 && (n / 3) % 3 != 1 && n / 9 != 1;
}

// Per-element summary of the coefficients, filled by the vectorised pass.
struct Summary {
  double min_all[kLinearChunk], max_all[kLinearChunk];
  double min_vertex[kLinearChunk], max_vertex[kLinearChunk];
  double sum[kLinearChunk], err[kLinearChunk];
};

template <LinearKind kKind>
void summarise(const double* soa, std::size_t count, Summary& s) {
  constexpr int n = num_coefficients(kKind);
  for (std::size_t e = 0; e < count; e += kLanes) {
    const auto point = [&](int v) {
      const double* q = soa + static_cast<std::size_t>(v) * 3 * kLinearChunk + e;
      Vec3<Lanes> r;
      std::memcpy(&r.x, q, sizeof(Lanes));
      std::memcpy(&r.y, q + kLinearChunk, sizeof(Lanes));
      std::memcpy(&r.z, q + 2 * kLinearChunk, sizeof(Lanes));
      return r;
    };
    Lanes c[n];
    const Lanes err = coefficients_of(kKind, point, c);
    Lanes lo = c[0], hi = c[0], vlo = c[0], vhi = c[0], sum = c[0] * 0;
#pragma GCC unroll 27
    for (int k = 0; k < n; ++k) {
      lo = vmin(lo, c[k]);
      hi = vmax(hi, c[k]);
      sum += c[k];
      if (is_vertex_coefficient(kKind, k)) {
        vlo = vmin(vlo, c[k]);
        vhi = vmax(vhi, c[k]);
      }
    }
    std::memcpy(s.min_all + e, &lo, sizeof(Lanes));
    std::memcpy(s.max_all + e, &hi, sizeof(Lanes));
    std::memcpy(s.min_vertex + e, &vlo, sizeof(Lanes));
    std::memcpy(s.max_vertex + e, &vhi, sizeof(Lanes));
    std::memcpy(s.sum + e, &sum, sizeof(Lanes));
    std::memcpy(s.err + e, &err, sizeof(Lanes));
  }
}

}  // namespace

LinearKind linear_kind(const ElementType& type, bool planar) noexcept {
  if (type.order != 1 || !type.has_lagrange_basis) return LinearKind::none;
  switch (type.family) {
    case ElementFamily::triangle: return planar ? LinearKind::triangle : LinearKind::none;
    case ElementFamily::quadrangle: return planar ? LinearKind::quadrangle : LinearKind::none;
    case ElementFamily::tetrahedron: return LinearKind::tetrahedron;
    case ElementFamily::hexahedron: return LinearKind::hexahedron;
    default: return LinearKind::none;
  }
}

int linear_num_vertices(LinearKind kind) noexcept {
  switch (kind) {
    case LinearKind::triangle: return 3;
    case LinearKind::quadrangle: return 4;
    case LinearKind::tetrahedron: return 4;
    case LinearKind::hexahedron: return 8;
    case LinearKind::none: break;
  }
  return 0;
}

double linear_jacobian_coefficients(LinearKind kind, const double* nodes, double* coeffs) noexcept {
  const auto point = [nodes](int v) {
    const double* q = nodes + 3 * v;
    return Vec3<double>{q[0], q[1], q[2]};
  };
  const double err = coefficients_of(kind, point, coeffs);
  return next_up(err);
}

void linear_validity_chunk(LinearKind kind, const double* soa, std::size_t count,
                           JacobianBounds* out, bool* decided) noexcept {
  Summary s;
  switch (kind) {
    case LinearKind::hexahedron: summarise<LinearKind::hexahedron>(soa, count, s); break;
    case LinearKind::quadrangle: summarise<LinearKind::quadrangle>(soa, count, s); break;
    case LinearKind::tetrahedron: summarise<LinearKind::tetrahedron>(soa, count, s); break;
    case LinearKind::triangle: summarise<LinearKind::triangle>(soa, count, s); break;
    case LinearKind::none: std::fill(decided, decided + count, false); return;
  }
  const double n = num_coefficients(kind);
  for (std::size_t e = 0; e < count; ++e) {
    const double err = next_up(s.err[e]);
    const double lower = next_down(s.min_all[e] - err);
    const double vertex_upper = next_up(s.min_vertex[e] + err);
    // valid: every coefficient proven > 0; invalid: a vertex value proven <= 0. The +inf
    // error of the unguarded range satisfies neither; a NaN coefficient (only from
    // non-finite input) may be skipped by min/max, but not by the sum.
    const bool finite = std::isfinite(s.sum[e]);
    const bool valid = finite && lower > 0;
    const bool invalid = finite && vertex_upper <= 0;
    decided[e] = valid || invalid;
    if (!decided[e]) continue;
    JacobianBounds& b = out[e];
    b = JacobianBounds{};
    b.jmin_lower = lower;
    b.jmin_upper = vertex_upper;
    b.jmax_lower = next_down(s.max_vertex[e] - err);
    b.jmax_upper = next_up(s.max_all[e] + err);
    b.javg = s.sum[e] / n;
    b.validity = valid ? Validity::valid : Validity::invalid;
    b.stage = valid ? 1 : 0;
    b.subdivisions = 0;
  }
}

}  // namespace quadval
