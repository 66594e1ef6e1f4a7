// Fast certified Jacobian coefficients of first-order elements; derivation and error bound
// in linear_jacobian.hpp. One element's arithmetic is written once (templates over how a
// coordinate is read) and used both per element and, inlined, across a chunk of elements.
#include "analysis/linear_jacobian.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "bezier/native_lanes.hpp"
#include "analysis/outward_rounding.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kErrFactor = 0x1p-48;  // 32 u, u = 2^-53 (linear_jacobian.hpp)
constexpr double kMinNorm = 0x1p-200, kMaxNorm = 0x1p200;

// The element arithmetic is written once over T: double (one element) or Lanes (kLanes
// elements side by side, GCC vector extension: the same IEEE operations lane by lane, so
// the results are bit-identical to the scalar ones; -ffp-contract=off applies to both).
constexpr int kLanes = kNativeLanes;
using Lanes = double __attribute__((vector_size(kLanes * sizeof(double))));
static_assert(kLinearChunk % kLanes == 0);

using Bits = std::int64_t __attribute__((vector_size(kLanes * sizeof(std::int64_t))));
static_assert(sizeof(Bits) == sizeof(Lanes));

inline double vabs(double a) { return std::abs(a); }
// |a| lane by lane as std::abs: the sign bit cleared (one AND, no compare and blend)
inline Lanes vabs(Lanes a) {
  return std::bit_cast<Lanes>(std::bit_cast<Bits>(a) & std::numeric_limits<std::int64_t>::max());
}
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

// Pyramid: c[a + 2b] = J along the lateral edge through base vertex (a, b), J being
// bilinear in (u, v) and constant in t (linear_jacobian.hpp).
template <class T, class Point>
inline T pyramid_coefficients(Point p, T* c) {
  constexpr int kBaseVertex[2][2] = {{0, 3}, {1, 2}};  // [a][b], as the quadrangle's
  const Vec3<T> apex = p(4);
  Vec3<T> eu[2], ev[2];  // eu[b], ev[a]
  T lu{}, lv{}, lw{};
  #pragma GCC unroll 2
  for (int s = 0; s < 2; ++s) {
    eu[s] = sub(p(kBaseVertex[1][s]), p(kBaseVertex[0][s]));
    ev[s] = sub(p(kBaseVertex[s][1]), p(kBaseVertex[s][0]));
    lu = vmax(lu, norm1(eu[s]));
    lv = vmax(lv, norm1(ev[s]));
  }
  #pragma GCC unroll 2
  for (int a = 0; a < 2; ++a)
    #pragma GCC unroll 2
    for (int b = 0; b < 2; ++b) {
      const Vec3<T> w = sub(apex, p(kBaseVertex[a][b]));
      lw = vmax(lw, norm1(w));
      // the 1/4 of d(xi, eta, zeta) / d(u, v, t) = -4 t^2 (its sign is in w = A - B); exact
      c[a + 2 * b] = dot(eu[b], cross(ev[a], w)) * 0.25;
    }
  return error_of(lu, lv, lw, 0.25);
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
    case LinearKind::pyramid: return pyramid_coefficients(p, c);
    case LinearKind::none: break;
  }
  return c[0] * 0 + kInf;
}

constexpr int num_coefficients(LinearKind kind) {
  switch (kind) {
    case LinearKind::hexahedron: return 27;
    case LinearKind::pyramid:
    case LinearKind::quadrangle: return 4;
    default: return 1;
  }
}

// Indices of the vertex coefficients (values of J; the pyramid's along its lateral edges).
constexpr bool is_vertex_coefficient(LinearKind kind, int n) {
  if (kind != LinearKind::hexahedron) return true;
  return n % 3 != 1 && (n / 3) % 3 != 1 && n / 9 != 1;
}

// One-ulp steps, lane by lane, for the arguments the decision below can meet: the bits
// of next_up / next_down (outward_rounding.hpp) for every finite x, without branches. A
// finite nonzero x steps its bit pattern by one away from zero (up) or toward zero (down)
// as its sign says; +-0 goes to +-denorm_min. (Non-finite x: garbage, never written.)
inline Bits away_from_zero(Lanes x) { return (std::bit_cast<Bits>(x) >> 63) | 1; }  // +1 / -1 by sign
inline Lanes next_up_nonzero(Lanes x) {
  return std::bit_cast<Lanes>(std::bit_cast<Bits>(x) + away_from_zero(x));
}
inline Lanes next_down_nonzero(Lanes x) {
  return std::bit_cast<Lanes>(std::bit_cast<Bits>(x) - away_from_zero(x));
}
inline Lanes next_up_finite(Lanes x) {
  return x == 0 ? Lanes{} + std::numeric_limits<double>::denorm_min() : next_up_nonzero(x);
}
inline Lanes next_down_finite(Lanes x) {
  return x == 0 ? Lanes{} - std::numeric_limits<double>::denorm_min() : next_down_nonzero(x);
}

// The whole decision, kLanes elements at a time: coefficients, their min / max / sum, the
// outward-rounded bounds and the verdict all in vector registers, branch-free (bit for bit
// the bounds of one element at a time with next_up / next_down, as the test
// LinearFastPath.ChunkBoundsAreTheDocumentedOutwardRoundedValues checks); only the final
// stores are per element.
template <LinearKind kKind>
void decide_chunk(const double* soa, std::size_t row, std::size_t count, JacobianBounds* out, bool* decided,
                  const double* margins) {
  constexpr int n = num_coefficients(kKind);
  for (std::size_t e = 0; e < count; e += kLanes) {
    const auto point = [&](int v) {
      const double* q = soa + static_cast<std::size_t>(v) * 3 * row + e;
      Vec3<Lanes> r;
      std::memcpy(&r.x, q, sizeof(Lanes));
      std::memcpy(&r.y, q + row, sizeof(Lanes));
      std::memcpy(&r.z, q + 2 * row, sizeof(Lanes));
      return r;
    };
    Lanes c[n];
    // err (before rounding up) is a positive normal number (every L in [2^-200, 2^200]),
    // +inf, or a quiet NaN (NaN input), never 0: next_up is bits + 1 for the first, and
    // the others become (or stay) NaN, which decides nothing.
    Lanes err = next_up_nonzero(coefficients_of(kKind, point, c));
    if (margins != nullptr) {  // J within the margin of these coefficients' polynomial
      Lanes m;
      std::memcpy(&m, margins + e, sizeof m);
      err = next_up_nonzero(err + m);
    }
    // (sum from c[0], not 0 + c[0]: the same bits for every finite c[0], -0 included,
    // and a non-finite c[0] leaves the element undecided either way)
    Lanes lo = c[0], hi = c[0], vlo = c[0], vhi = c[0], sum = c[0];
#pragma GCC unroll 27
    for (int k = 1; k < n; ++k) {
      lo = vmin(lo, c[k]);
      hi = vmax(hi, c[k]);
      sum += c[k];
      if (is_vertex_coefficient(kKind, k)) {
        vlo = vmin(vlo, c[k]);
        vhi = vmax(vhi, c[k]);
      }
    }
    // valid: every coefficient proven > 0, next_down(lo - err) > 0, i.e. lo - err >
    // denorm_min; invalid: a vertex value proven <= 0, next_up(vlo + err) <= 0, i.e.
    // vlo + err < 0 (both exact equivalences for every double, NaN and +-inf included). A
    // NaN coefficient (only from non-finite input) may be skipped by min/max, but not by
    // the sum (|NaN| <= max is false, as is |inf| <= max); a NaN err decides nothing.
    // So a decided element has finite coefficients and err, and lo - err > 0 (valid) or
    // vlo + err < 0, hence lo - err < 0 (invalid): the min J bounds are rounded from
    // nonzero finite values, the max J bounds from finite ones.
    const Bits finite = vabs(sum) <= std::numeric_limits<double>::max();
    const Lanes lower = lo - err, vertex_upper = vlo + err;
    const Bits valid = finite & (lower > std::numeric_limits<double>::denorm_min());
    const Bits invalid = finite & (vertex_upper < 0);
    // for n a power of two, sum * (1 / n) is sum / n exactly (both the rounded sum / n)
    constexpr bool kPow2 = (n & (n - 1)) == 0;
    const Lanes javg = kPow2 ? sum * (1.0 / n) : sum / static_cast<double>(n);
    const Lanes bounds[5] = {next_down_nonzero(lower), next_up_nonzero(vertex_upper),
                             next_down_finite(vhi - err), next_up_finite(hi + err), javg};
    alignas(sizeof(Lanes)) double bound[5][kLanes];
    alignas(sizeof(Bits)) std::int64_t verdict[2][kLanes];
    std::memcpy(bound, bounds, sizeof bound);
    std::memcpy(verdict[0], &valid, sizeof(Bits));
    std::memcpy(verdict[1], &invalid, sizeof(Bits));
    const std::size_t lanes = std::min<std::size_t>(kLanes, count - e);
    for (std::size_t i = 0; i < lanes; ++i) {
      const bool is_valid = verdict[0][i] != 0;
      decided[e + i] = is_valid || verdict[1][i] != 0;
      if (!decided[e + i]) continue;
      JacobianBounds b;
      b.jmin_lower = bound[0][i];
      b.jmin_upper = bound[1][i];
      b.jmax_lower = bound[2][i];
      b.jmax_upper = bound[3][i];
      b.javg = bound[4][i];
      b.validity = is_valid ? Validity::valid : Validity::invalid;
      b.stage = is_valid ? 1 : 0;
      b.subdivisions = 0;
      out[e + i] = b;
    }
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
    case ElementFamily::pyramid: return LinearKind::pyramid;
    default: return LinearKind::none;
  }
}

int linear_num_vertices(LinearKind kind) noexcept {
  switch (kind) {
    case LinearKind::triangle: return 3;
    case LinearKind::quadrangle: return 4;
    case LinearKind::tetrahedron: return 4;
    case LinearKind::hexahedron: return 8;
    case LinearKind::pyramid: return 5;
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

quadval::Lanes<kNativeLanes> linear_simplex_jacobian_lanes(LinearKind kind, const quadval::Lanes<kNativeLanes>* edges,
                                                           quadval::Lanes<kNativeLanes>& j) noexcept {
  using V = quadval::Lanes<kNativeLanes>;  // the chunks' lanes: one type
  // Vertex 0 at the origin: each edge x_{c+1} - 0 is exactly the given one.
  const auto point = [edges](int v) {
    if (v == 0) return Vec3<V>{};
    const V* e = edges + 3 * (v - 1);
    return Vec3<V>{e[0], e[1], e[2]};
  };
  // A finite err is a positive normal number (error_of), whose next_up is bits + 1.
  return next_up_nonzero(kind == LinearKind::triangle ? triangle_coefficients(point, &j) : tet_coefficients(point, &j));
}

void linear_validity_chunk(LinearKind kind, const double* soa, std::size_t count,
                           JacobianBounds* out, bool* decided, const double* margins, std::size_t row) noexcept {
  switch (kind) {
    case LinearKind::hexahedron: return decide_chunk<LinearKind::hexahedron>(soa, row, count, out, decided, margins);
    case LinearKind::quadrangle: return decide_chunk<LinearKind::quadrangle>(soa, row, count, out, decided, margins);
    case LinearKind::tetrahedron: return decide_chunk<LinearKind::tetrahedron>(soa, row, count, out, decided, margins);
    case LinearKind::triangle: return decide_chunk<LinearKind::triangle>(soa, row, count, out, decided, margins);
    case LinearKind::pyramid: return decide_chunk<LinearKind::pyramid>(soa, row, count, out, decided, margins);
    case LinearKind::none: break;
  }
  std::fill(decided, decided + count, false);
}

}  // namespace quadval
