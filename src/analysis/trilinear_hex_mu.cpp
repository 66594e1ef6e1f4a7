// R's bounds of a first-order hexahedron from its control matrices, in lanes (see the
// header for the method and its rounding).
#include "analysis/trilinear_hex_mu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "analysis/sqrt_rn.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

using namespace lanes3;

constexpr double kUnit = 0x1p-53;
constexpr int kPoints = 27;
constexpr int kSlots = VertexProducts::kSlots;  // 4 blocks of 8 lanes; the spare ones repeat point 0

// Gmsh's vertex at Bernstein index (i, j, k), i + 2 j + 4 k.
constexpr int kNode[8] = {0, 1, 3, 2, 4, 5, 7, 6};

// The control points (d0, d1, d2) of degree 2, as d0 + 3 d1 + 9 d2, by slot: the 8
// corners first (slot q: corner q = (i, j, k) -> (2i, 2j, 2k)), so that lane block 0 serves
// the upper bound too, then the others in order; the spare slots repeat slot 0. Per entry
// of M, the slot's source among the values diagonal_entry and cross_entry compute.
constexpr int kCross[3][2] = {{0, 1}, {0, 2}, {1, 2}};  // entries m01, m02, m12

struct Layout {
  std::array<int, kSlots> point{};
  std::array<int, kPoints> slot{};  // point -> its slot
  std::array<std::array<std::uint8_t, kSlots>, 3> diagonal_source{};  // b + 3 c (along x + 1, x + 2)
  std::array<std::array<std::uint8_t, kSlots>, 3> cross_source{};     // 9 a + 3 b + c (along x, y, z)
};

Layout make_layout() {
  Layout l;
  const auto is_corner = [](int p) { return p % 3 != 1 && (p / 3) % 3 != 1 && p / 9 != 1; };
  int s = 0;
  for (int q = 0; q < 8; ++q) l.point[static_cast<std::size_t>(s++)] = 2 * (q & 1) + 6 * ((q >> 1) & 1) + 18 * (q >> 2);
  for (int p = 0; p < kPoints; ++p)
    if (!is_corner(p)) l.point[static_cast<std::size_t>(s++)] = p;
  QV_ASSERT(s == kPoints, s << " control points");
  for (int t = 0; t < kPoints; ++t) l.slot[static_cast<std::size_t>(l.point[static_cast<std::size_t>(t)])] = t;
  for (; s < kSlots; ++s) l.point[static_cast<std::size_t>(s)] = l.point[0];
  for (int t = 0; t < kSlots; ++t) {
    const int p = l.point[static_cast<std::size_t>(t)];
    const int d[3] = {p % 3, (p / 3) % 3, p / 9};
    for (int x = 0; x < 3; ++x) {
      l.diagonal_source[static_cast<std::size_t>(x)][static_cast<std::size_t>(t)] =
          static_cast<std::uint8_t>(d[(x + 1) % 3] + 3 * d[(x + 2) % 3]);
      const int y = kCross[x][1], xx = kCross[x][0], z = 3 - xx - y;
      l.cross_source[static_cast<std::size_t>(x)][static_cast<std::size_t>(t)] =
          static_cast<std::uint8_t>(9 * d[xx] + 3 * d[y] + d[z]);
    }
  }
  return l;
}

const Layout& layout() {
  static const Layout l = make_layout();
  return l;
}

double dot(const double* f, const double* g) { return f[0] * g[0] + f[1] * g[1] + f[2] * g[2]; }

// The control values of M_xx = |w_x|^2, by slot. w_x is constant along x: with u, v the
// other two directions, its control values F[iu][iv]; M_xx(b, c) is the mean of
// F[u1][v1] . F[u2][v2] over u1 + u2 = b, v1 + v2 = c, the same at every index along x.
void diagonal_entry(const double (*w)[3], int x, const Layout& lay, double* out) {
  const int u = (x + 1) % 3, v = (x + 2) % 3;
  const double* f[2][2];
  for (int iu = 0; iu < 2; ++iu)
    for (int iv = 0; iv < 2; ++iv) f[iu][iv] = w[(iu << u) | (iv << v)];
  double h[3][3] = {};
  for (int u1 = 0; u1 < 2; ++u1)
    for (int v1 = 0; v1 < 2; ++v1)
      for (int u2 = 0; u2 < 2; ++u2)
        for (int v2 = 0; v2 < 2; ++v2) h[u1 + u2][v1 + v2] += dot(f[u1][v1], f[u2][v2]);
  double mean[9];
  for (int b = 0; b < 3; ++b)
    for (int c = 0; c < 3; ++c) mean[b + 3 * c] = h[b][c] * ((b == 1 ? 0.5 : 1.0) * (c == 1 ? 0.5 : 1.0));
  const auto& source = lay.diagonal_source[static_cast<std::size_t>(x)];
  for (int t = 0; t < kSlots; ++t) out[t] = mean[source[static_cast<std::size_t>(t)]];
}

// The control values of M_xy = w_x . w_y (entry kCross[e]), z the third direction, by
// slot: w_x varies along y and z (F[j][k]), w_y along x and z (G[i][k]); their product
// H[i][j][c] (degree 1, 1, 2 along x, y, z) is the mean of F[j][k1] . G[i][k2] over
// k1 + k2 = c, then raised to degree 2 along x and y (the value at index 1 the mean of
// those at 0 and 1).
void cross_entry(const double (*w)[8][3], int e, const Layout& lay, double* out) {
  const int x = kCross[e][0], y = kCross[e][1], z = 3 - x - y;
  double h[2][2][3] = {};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k1 = 0; k1 < 2; ++k1)
        for (int k2 = 0; k2 < 2; ++k2) h[i][j][k1 + k2] += dot(w[x][(j << y) | (k1 << z)], w[y][(i << x) | (k2 << z)]);
  constexpr int kFrom[3][2] = {{0, 0}, {0, 1}, {1, 1}};  // degree-1 indices averaged at 0, 1, 2
  double raised[27];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        raised[9 * a + 3 * b + c] = (h[kFrom[a][0]][kFrom[b][0]][c] + h[kFrom[a][1]][kFrom[b][0]][c] +
                                     h[kFrom[a][0]][kFrom[b][1]][c] + h[kFrom[a][1]][kFrom[b][1]][c]) *
                                    (c == 1 ? 0.125 : 0.25);
  const auto& source = lay.cross_source[static_cast<std::size_t>(e)];
  for (int t = 0; t < kSlots; ++t) out[t] = raised[source[static_cast<std::size_t>(t)]];
}

double largest_entry(const double (*w)[8][3]) {
  double a = 0;
  for (int c = 0; c < 3; ++c)
    for (int q = 0; q < 8; ++q)
      for (int k = 0; k < 3; ++k) a = std::max(a, std::abs(w[c][q][k]));
  return a;
}

// The bound on every control value's error (see the header).
double entry_error(double a, double delta) {
  return next_up((3 * (2 * a + delta) * delta + rounding_gamma(10) * 3 * a * a) * kSlack);
}

// R's bounds on a box whose columns' control values w (column, vertex, coordinate) are
// within delta of the exact ones.
CertifiedRatio box_ratio(const double (*w)[8][3], double delta, double enough = 1) {
  const Layout& lay = layout();
  const double a = largest_entry(w);
  const double err = entry_error(a, delta);
  if (!(err < kMax) || !(a > 0)) return {};
  // The control values of M's entries m00, m11, m22, m01, m02, m12, by slot.
  alignas(64) double m[6][kSlots];
  for (int x = 0; x < 3; ++x) diagonal_entry(w[x], x, lay, m[x]);
  for (int e = 0; e < 3; ++e) cross_entry(w, e, lay, m[3 + e]);
  // The corners are slots 0-7 (vertex q at slot q), as control_matrix_ratio wants them.
  return control_matrix_ratio(m, kSlots, 8, w, err, delta, enough);
}

// A box of the reference cube: J's columns' control values on it (for the corners' Rayleigh
// quotients), their error bound, M's control values by slot (Layout: the corners first; the
// spare slots repeat slot 8, the first other point), their error bound, the certified lower
// bound of R at each of its corners, and its lower bound of R.
struct Box {
  double w[3][8][3];
  double delta;
  alignas(64) double m[6][kSlots];
  double err;
  double corner[8];
  double lower;
  int depth;  // halvings from the root; the next one is along direction depth % 3
};

// Column c's control values at the vertices: the edges along direction c (twice J's on
// [-1, 1]^3; R does not depend on W's scale), each within 2u of the largest.
double element_columns(std::span<const double> x, double (*w)[8][3]) {
  double a = 0;
  for (int c = 0; c < 3; ++c)
    for (int q = 0; q < 8; ++q) {
      const int from = q & ~(1 << c), to = q | (1 << c);
      for (int k = 0; k < 3; ++k) {
        const double e = x[static_cast<std::size_t>(3 * kNode[to] + k)] - x[static_cast<std::size_t>(3 * kNode[from] + k)];
        w[c][q][k] = e;
        a = std::max(a, std::abs(e));
      }
    }
  return next_up(2 * kUnit * a * kSlack);
}

// The two halves of `box` along direction d (de Casteljau at 1/2: each column is linear
// along d). Column d is constant along d and stays; the others' new vertex values are
// midpoints, each within u|value| of the exact midpoint of the computed ones, which are
// within delta of the exact ones (a smallest subnormal added for underflow).
void halve(const Box& box, int d, Box& low, Box& high) {
  double a = 0;
  for (int c = 0; c < 3; ++c)
    for (int q = 0; q < 8; ++q) {
      const int q0 = q & ~(1 << d), q1 = q | (1 << d);
      for (int k = 0; k < 3; ++k) {
        const double v0 = box.w[c][q0][k], v1 = box.w[c][q1][k];
        const double mid = c == d ? v0 : 0.5 * (v0 + v1);
        a = std::max(a, std::abs(mid));
        low.w[c][q][k] = (q & (1 << d)) != 0 ? mid : v0;
        high.w[c][q][k] = (q & (1 << d)) != 0 ? v1 : mid;
      }
    }
  low.delta = high.delta = next_up((box.delta + kUnit * a) * kSlack + std::numeric_limits<double>::denorm_min());
  low.depth = high.depth = box.depth + 1;
}

// The metrics at 4 corners qs of a box (M's control values there, which are its values,
// each entry within box.err), in lanes: each one's certified lower bound of R into
// ratio[i], and with `upper` set, the upper bound of R from Rayleigh quotients of W there
// folded into *upper. false where a metric is not certified positive definite.
// Four lanes on every target: the 4 corners fill them (with 8-lane AVX-512 registers, a loop
// over 4 / kNativeLanes parts ran no part at all and left `ratio` unwritten).
bool corner_ratios(const Box& box, const int* qs, double* ratio, double* upper) {
  constexpr int kW = 4;
  if (!(box.err < kMax)) return false;
  Lanes<kW> m[6], wv[3][3];
  for (int l = 0; l < kW; ++l) {
    const int q = qs[l];
    for (int e = 0; e < 6; ++e) m[e][l] = box.m[e][q];
    for (int j = 0; j < 3; ++j)
      for (int c = 0; c < 3; ++c) wv[j][c][l] = box.w[j][q][c];
  }
  const ExtremeEigen<kW> eig = extreme_eigen<kW>(m, broadcast_lanes<kW>(box.err));
  if (mask_bits<kW>(eig.ok & (eig.lo > 0)) != (1u << kW) - 1) return false;
  const Lanes<kW> r = down<kW>(eig.lo / eig.hi);
  for (int l = 0; l < kW; ++l) ratio[l] = r[l];
  if (upper == nullptr) return true;
  Mask<kW> vectors_ok;
  const Lanes<kW> u = ratio_upper<kW>(wv, m, eig.lo, eig.hi, broadcast_lanes<kW>(box.delta), vectors_ok);
  for (int l = 0; l < kW; ++l) *upper = std::min(*upper, u[l]);
  return true;
}

// The spare slots of m repeat slot 8.
void fill_spare_slots(double (*m)[kSlots]) {
  for (int e = 0; e < 6; ++e)
    for (int t = kPoints; t < kSlots; ++t) m[e][t] = m[e][8];
}

// M's control values on the whole element, as box_ratio computes them.
void root_metric(Box& box) {
  const Layout& lay = layout();
  for (int x = 0; x < 3; ++x) diagonal_entry(box.w[x], x, lay, box.m[x]);
  for (int e = 0; e < 3; ++e) cross_entry(box.w, e, lay, box.m[3 + e]);
  fill_spare_slots(box.m);
  box.err = entry_error(largest_entry(box.w), box.delta);
}

// M's control values on the two halves of `box` along d, by de Casteljau at 1/2 along d
// (M has degree 2 there: (a, b, c) -> (a, (a + b)/2, q) and (q, (b + c)/2, c), q the mean
// of the two middle values). The map is a convex combination, so the parent's error bound
// carries over; the averages round twice (the halvings are exact), within 2u of the
// largest |value| (a smallest subnormal added for underflow).
void halve_metric(const Box& box, int d, Box& low, Box& high) {
  constexpr int kStride[3] = {1, 3, 9};
  const auto& slot = layout().slot;
  const int stride = kStride[d], s1 = kStride[(d + 1) % 3], s2 = kStride[(d + 2) % 3];
  double largest = 0;
  for (int line = 0; line < 9; ++line) {  // the line along d from each point with index 0
    const int p = s1 * (line % 3) + s2 * (line / 3);
    const auto t0 = static_cast<std::size_t>(slot[static_cast<std::size_t>(p)]);
    const auto t1 = static_cast<std::size_t>(slot[static_cast<std::size_t>(p + stride)]);
    const auto t2 = static_cast<std::size_t>(slot[static_cast<std::size_t>(p + 2 * stride)]);
    for (int e = 0; e < 6; ++e) {
      const double a = box.m[e][t0], b = box.m[e][t1], c = box.m[e][t2];
      const double ab = 0.5 * (a + b), bc = 0.5 * (b + c), mid = 0.5 * (ab + bc);
      largest = std::max({largest, std::abs(a), std::abs(b), std::abs(c)});
      low.m[e][t0] = a;
      low.m[e][t1] = ab;
      low.m[e][t2] = mid;
      high.m[e][t0] = mid;
      high.m[e][t1] = bc;
      high.m[e][t2] = c;
    }
  }
  fill_spare_slots(low.m);
  fill_spare_slots(high.m);
  low.err = high.err =
      next_up((box.err + 2 * kUnit * largest) * kSlack + std::numeric_limits<double>::denorm_min());
}

// The lower bound of R on a box whose corners' ratios are known: the least of those and of
// its other 19 control matrices' (control_matrix_ratio's blocks 1-3: the cheap test at
// min(lower so far, enough) first, an enclosure where it fails; 0 where a matrix is not
// certified positive definite).
double box_lower(const Box& box, double enough) {
  constexpr int kW = kNativeLanes, kParts = 8 / kW;
  constexpr unsigned kAll = (1u << kW) - 1;
  double lower = *std::min_element(box.corner, box.corner + 8);
  for (int block = 1; block < kSlots / 8; ++block) {
    Lanes<kW> mb[kParts][6];
    for (int p = 0; p < kParts; ++p)
      for (int e = 0; e < 6; ++e) mb[p][e] = load_lanes<kW>(&box.m[e][8 * block + kW * p]);
    const double floor = std::min(lower, enough);
    if (floor > 0 && floor < 1) {
      bool all = true;
      for (int p = 0; p < kParts && all; ++p) all = mask_bits<kW>(ratio_at_least<kW>(mb[p], box.err, floor)) == kAll;
      if (all) {
        lower = floor;
        continue;
      }
    }
    for (int p = 0; p < kParts; ++p) {
      const ExtremeEigen<kW> eig = extreme_eigen<kW>(mb[p], broadcast_lanes<kW>(box.err));
      if (mask_bits<kW>(eig.ok & (eig.lo > 0)) != kAll) return 0;
      lower = fold_min(down<kW>(eig.lo / eig.hi), lower);
    }
  }
  return std::clamp(lower, 0.0, 1.0);
}

}  // namespace

CertifiedRatio trilinear_hex_ratio(std::span<const double> x) {
  QV_ASSERT(x.size() == 24, x.size() << " coordinates for a first-order hexahedron");
  double w[3][8][3];
  const double delta = element_columns(x, w);
  return box_ratio(w, delta);
}

RefinedRatio refine_trilinear_hex_ratio(std::span<const double> x, CertifiedRatio root, double abs_tol,
                                        int max_halvings) {
  QV_ASSERT(x.size() == 24, x.size() << " coordinates for a first-order hexahedron");
  QV_ASSERT(root.ok, "refinement from an uncertified root");
  const auto settled = [&](double lower, double upper) { return sqrt_up(upper) - sqrt_down(lower) <= abs_tol; };
  // A lower bound above (sqrt(upper) - 0.9 abs_tol)^2 settles the element.
  const auto enough = [&](double upper) {
    const double m = sqrt_rn(upper) - 0.9 * abs_tol;
    return m <= 0 ? 0.0 : m * m;
  };
  // Boxes in a pool (a halved box's slot goes to its first half), a min-heap of their
  // lower bounds and slots.
  thread_local std::vector<Box> pool;
  thread_local std::vector<std::pair<double, int>> heap;
  const auto later = [](const std::pair<double, int>& p, const std::pair<double, int>& q) { return p > q; };
  pool.resize(1);
  Box& whole = pool[0];
  whole.delta = element_columns(x, whole.w);
  whole.lower = root.lower;
  whole.depth = 0;
  root_metric(whole);
  // The root's corner ratios (trilinear_hex_ratio took its upper bound from them already).
  {
    constexpr int kLow[4] = {0, 1, 2, 3}, kHigh[4] = {4, 5, 6, 7};
    if (!corner_ratios(whole, kLow, whole.corner, nullptr) || !corner_ratios(whole, kHigh, whole.corner + 4, nullptr))
      return {};
  }
  heap.assign(1, {root.lower, 0});
  RefinedRatio out;
  out.ratio = root;
  while (!settled(heap.front().first, out.ratio.upper)) {
    if (out.halvings >= max_halvings) break;
    std::pop_heap(heap.begin(), heap.end(), later);
    const int slot = heap.back().second;
    heap.pop_back();
    const Box top = pool[static_cast<std::size_t>(slot)];
    pool.emplace_back();
    Box& low = pool[static_cast<std::size_t>(slot)];
    Box& high = pool.back();
    const int d = top.depth % 3;
    halve(top, d, low, high);
    halve_metric(top, d, low, high);
    ++out.halvings;
    // Each half keeps 4 of its parent's corners; the other 4, on the plane between them,
    // are the same for both (low's with bit d set, high's with it clear): enclosed once.
    int plane[4], n = 0;
    for (int q = 0; q < 8; ++q)
      if ((q & (1 << d)) != 0) plane[n++] = q;
    double mid[4];
    if (!corner_ratios(low, plane, mid, &out.ratio.upper)) return {};
    for (int i = 0; i < 4; ++i) {
      const int q1 = plane[i], q0 = q1 & ~(1 << d);
      low.corner[q0] = top.corner[q0];
      low.corner[q1] = mid[i];
      high.corner[q0] = mid[i];
      high.corner[q1] = top.corner[q1];
    }
    const double target = enough(out.ratio.upper);
    for (Box* half : {&low, &high}) {
      // The parent's bound holds on its halves too.
      half->lower = std::max(box_lower(*half, target), top.lower);
      heap.emplace_back(half->lower, static_cast<int>(half - pool.data()));
      std::push_heap(heap.begin(), heap.end(), later);
    }
  }
  out.ratio.lower = heap.front().first;
  out.settled = settled(out.ratio.lower, out.ratio.upper);
  return out;
}

}  // namespace quadval
