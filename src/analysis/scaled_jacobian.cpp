// Certified bounds on the minimum of the scaled Jacobian (scaled_jacobian.hpp): Bézier
// coefficients of the columns of J_p in their own degrees (an exact linear map of the
// nodes, rounded once), N and D_k by Bernstein products (Paper V Prop. 4) with a priori
// error bounds, then the rational-function bound of Paper V §3.1 refined by best-first
// subdivision.
#include "quadval/scaled_jacobian.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "analysis/bilinear_quad_quality.hpp"
#include "analysis/jacobian_samples.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/linear_jacobian.hpp"
#include "analysis/linear_pyramid_sj.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/ratio_scan.hpp"
#include "analysis/scaled_jacobian_probe.hpp"
#include "analysis/scaled_jacobian_quotient.hpp"
#include "analysis/scalar_or_lanes.hpp"
#include "analysis/scaled_jacobian_space.hpp"
#include "analysis/slot_pool.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/straight_sided.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "analysis/trilinear_hex_sj.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "bezier/bernstein_product.hpp"
#include "quadval/error.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;
constexpr double kInf = std::numeric_limits<double>::infinity();
using namespace scalar_or_lanes;  // up, down and root of doubles and of lanes
// Splits of J and the columns before the products, where the paired bound does not apply
// (lines, and the tests' switch; the quotient stage refines only a root within twice the
// tolerance). Measured on the shared curved meshes at --tol 1e-2:
// 16 splits of any root made linear hexahedra 10x and quadratic quadrangles 5x slower (the
// gap of a distorted element closes only linearly); 4 near the tolerance gain a little
// (warped_pyramid_o2: 163 elements settled by one split). A root within 4 tolerances
// instead of 2 (sj on one thread, fastest of 7): warped_pyramid_o2 98 -> 91 ms, whose full
// bounds work in (6r + 1)^3 coefficients, but tets_h0.8_o2 12 -> 15 ms, and the quadrangles
// of quad_h0.4_o2 and mixed_h0.6_o2 5-15% slower. No quotient stage at all for quadrangles
// and hexahedra: hex_box 10% faster, but mixed_h0.6_o2 20% and warped_hexahedron_o2 25%
// slower.
constexpr int kQuotientSplits = 4;
// Splits of the paired first stage of valid 3D and planar 2D elements (single bisections,
// `levels` of them one split; scaled_jacobian_quotient.cpp, paired_bound). sj of the valid
// elements, one thread, a per-element harness, best of 5, unpaired stage -> 4, 8, 16
// splits: warped_pyramid_o2 71 -> 35 ms at any (its 1,290 all settled by 8, none by the
// products of (6r + 1)^3 coefficients), mixed_h0.6_o2 9.9 -> 7.4 ms, warped_tetrahedron_o3
// 17.2 -> 15.5 ms, warped_prism_o2 2.4 -> 2.1 ms, the others within noise. In 2D (with the
// signed stage), CLI sj on 2 threads, medians of 9: tri_h0.4_o4 1.08 -> 0.90 ms,
// quad_h0.4_o2 0.71 -> 0.67 ms.
constexpr int kPairedSplits = 8;
// Splits of the signed first stage of 3D and planar 2D elements where J <= 0 was found
// (scaled_jacobian_quotient.hpp). Invalid elements' sj, one thread, a per-element harness,
// full path alone -> 2, 4, 8, 16 splits first (one run each, noisy): warped_hexahedron_o2
// 13.4 -> 5.3, 6.7, 6.5, 7.1 ms (all 156 settled by 2); warped_prism_o2 29.9 -> 23.8, 19.2,
// 21.0, 18.4 ms (all 280 by 8; best of 7: 17.8 -> 11.5 ms at 8); hex_box's 295 within
// noise. Tetrahedra (four frames per leaf) gained once its ratios were scanned without a
// division each (ratio_scan.hpp): warped_tetrahedron_o3's 660, best of 5, three runs
// each, 94-96 -> 82-87 ms. Re-measured on an AVX2 machine (whole mesh, each element best of
// 3) with 0, 2, 4, 6, 8, 12, 16 splits: warped_tetrahedron_o3 124, 107, 92, 92, 89-91, 95,
// 96 ms; warped_prism_o2 26, 17, 11.4 ms, then 8.9 ms from 6 on. The 128 (of 672) inverted
// tetrahedra that 8 splits leave unsettled take 57-74 of those ms (17-22 in this stage):
// more splits settle some of them, at more than the full path costs them.
constexpr int kSignedSplits = 8;
// Where the signed stage's root bound is at the Hadamard floor -s, tetrahedra go to the full
// bounds at once: 8 splits settled 27 of the 133 such inverted elements of
// warped_tetrahedron_o3 and none stuck there after 3 splits, and the full bounds settle them
// for less than the splits cost. Each inverted element best of 3, one thread, two runs:
// warped_tetrahedron_o3 56.6 -> 45.4 ms, tets_h0.8_o2 0.27 -> 0.23 ms, mixed_h0.6_o2's
// tetrahedra 14.0 -> 13.6 ms. Planar triangles at the floor go to the probe at once
// (below) instead: tri_h0.4_o4's 60 inverted ones, each best of 30, 372 -> 276 us in all;
// 22 of them change, 18 faster (its two hardest, whose minimum lies 0.019 above the floor,
// 54 -> 28 and 61 -> 37 us), 4 slower (3-5 -> 8-9 us), all tighter. Not for the others:
// warped_pyramid_o2 0.63 -> 1.7 ms, mixed_h0.6_o2's hexahedra 0.25 -> 0.93 ms (its
// pyramids 14.1 -> 13.2 ms), quad_h0.4_o2's 28 inverted quadrangles 166 -> 226 us (a
// quadrangle's probe costs more than the one split that settles most of them).
bool signed_floor_root_ends(const ElementType& type) {
  return type.family == ElementFamily::tetrahedron || type.family == ElementFamily::triangle;
}
// Where the inverted elements' time goes (one thread, each element best of 3). Of
// warped_tetrahedron_o3's 660, the signed stage settles 505 (14 ms); the other 155 take
// 29 ms in the full bounds, 14 ms of it in the 17 that need 64 to 222 halvings. The slowest
// (222, traced) holds a fold point, where a frame column vanishes: on the subdomains split
// around it D_k is not proven positive, so only the Hadamard bound -s |v_b x v_c| /
// (|v_b| |v_c|) applies there, and it nears sj's infimum (that quantity at the fold point)
// only as those subdomains shrink. Likewise 4 quadratic tetrahedra and 2 pyramids of
// mixed_h0.6_o2 (143-2,642 halvings) take 22 of its 23 ms. Tried and not kept:
// - The final upper bound given from the start: 8% fewer halvings on warped_tetrahedron_o3's
//   elements that need 8 or more, none fewer on 15 of the 17 slowest (the lower bound
//   decides there), so a better upper bound can gain at most that.
// - Compensating the positive side of a subdomain across the fold: r^2 D_k - N + m J with
//   nonnegative coefficients also gives sj_k >= -s r (where J < 0 the added term is
//   negative), with m >= 0 chosen to minimise r (the envelope of the lines
//   (N_i - m J_i) / D_k,i): warped_tetrahedron_o3 3,195 -> 3,127 subdivisions, 18% slower.
// - The local search of scaled_jacobian_probe.hpp for the upper bound, at the full bounds'
//   start: 3,195 -> 2,957 subdivisions, 7% slower; only after 32 halvings: 3,086, the
//   same time.

// A computed quantity: |computed| <= m and |computed - exact| <= e (Higham's model, one
// rounding of at most u per operation; the final bounds are enlarged by 1% to cover the
// rounding of these bound computations themselves).
struct Eb {
  double m = 0, e = 0;
};

struct Leaf {
  double lower;
  int slot;
  long id;  // creation order: a deterministic tie-break
};

struct Scratch {
  std::vector<double> values, child_err;
  std::vector<double> pool, pool_err;
  std::vector<BisectionState> states, child_states;  // states[slot]: the leaf's bisection state
  std::vector<int> free_slots;
  std::vector<Leaf> heap;
};

// The vectors one leaf holds, contiguous: J (only where J > 0 is not proven on the
// element), N, then per frame still open its D_k, followed by H_k and G_k when it has a
// Hadamard pair. A frame whose bound on a leaf is already within the tolerance of the
// upper bound is closed there (its bound kept aside: the leaf's bound is the least of its
// frames', so this changes no split) and its vectors are no longer halved below it. A split
// leaf holds on average 1.9 of the 3 frames of warped_prism_o2, 1.6 of the 4 of
// warped_tetrahedron_o3; sj time, fastest of 11 runs, 32 -> 26 ms and 174 -> 124 ms.
struct LeafFrames {
  static constexpr std::size_t kMax = 4;  // corner frames of a tetrahedron or pyramid
  std::size_t count = 0;
  std::array<std::uint8_t, kMax> width{};  // vectors of group t: 1 (D_k), or 3 with H_k, G_k
  std::size_t nvec = 0;                    // vectors in all
};

// Bounds the quantities of one subdomain (or one point) need, from the vectors of a leaf
// (LeafFrames) of `size` coefficients each at v[q * size], their error bounds err[q].
class Bounder {
 public:
  /// valid: J > 0 is proven on the whole element (jacobian_bounds), so every subdomain
  /// takes the positive branch without its own coefficient test, and leaves hold no J.
  /// signed_volume: |V_k| = |J| (3D, planar 2D, 1D), so that sj = s J / sqrt(D_k); not
  /// for surface elements in 3D.
  Bounder(const ScaledJacobianSpace& space, std::size_t size, bool valid, bool signed_volume)
      : space_(space), size_(size), valid_(valid), signed_volume_(signed_volume), n_(valid ? 0 : 1) {}

  /// Index of the first vector of the first group in a leaf.
  std::size_t first_group() const { return n_ + 1; }

  // Certified lower bound of sj on the subdomain (see scaled_jacobian.hpp): the least of
  // the bounds of its frames, each written to frame_lower[t].
  double lower(const double* v, const double* err, const LeafFrames& lf, double* frame_lower) const {
    const double* n = v + n_ * size_;
    bool positive = true;
    for (std::size_t i = 0; i < size_ && positive && !valid_; ++i) positive = down(v[i] - err[0]) > 0;
    double out = kInf;
    std::size_t q = first_group();
    if (positive) {
      // Per frame, r = min_i (N_i - e) / (D_k,i + e_k) without directed roundings
      // (ratio_scan.hpp), as in max_ratio; only a positive r is used, and then every
      // N_i - e > 0. Where the relaxation fails (some D_k,i not proven positive), J > 0
      // still gives sj > 0.
      for (std::size_t t = 0; t < lf.count; q += lf.width[t], ++t) {
        const double ed = err[q];
        const RatioScan scan = scan_ratios<true>(n, -err[n_], v + q * size_, ed, -ed, size_);
        if (!(scan.least_den > 0)) {
          frame_lower[t] = 0;
        } else {
          double r = scan.extreme;
          r = r > 0 ? quotient_below(r) : 0;
          frame_lower[t] = down(space_.s_lo() * down(sqrt_rn(std::max(0.0, r))));
        }
        out = std::min(out, frame_lower[t]);
      }
      return out;
    }
    // J not proven positive: per frame, the best of the bounds below; sj is their minimum.
    const double j_lo = down(least(v) - err[0]);
    for (std::size_t t = 0; t < lf.count; q += lf.width[t], ++t) {
      const double* d = v + q * size_;
      const double ed = err[q];
      // sj_k >= -s sqrt(max_i N_i / D_k,i), all D_k,i > 0 (relaxation), and >= -s.
      double ratio = std::min(1.0, max_ratio(n, err[n_], d, ed));
      // Hadamard with column a divided out: |V_k| <= |v_a| |v_b x v_c|, so
      // sj_k >= -s |v_b x v_c| / (|v_b| |v_c|) = -s sqrt(H_k / G_k) wherever v_a != 0
      // (and sj = 0 where it vanishes): sharp around a point of a fold where v_a = 0.
      if (lf.width[t] == 3) ratio = std::min(ratio, max_ratio(d + size_, err[q + 1], d + 2 * size_, err[q + 2]));
      double best = -up(space_.s_hi() * up(sqrt_rn(ratio)));
      // Where sj_k = s J / sqrt(D_k): sj_k >= 0 where J >= 0, and where J < 0, J >= J_lo
      // (the least coefficient of J, convex hull) and sqrt(D_k) >= sqrt(D_k,lo), so
      // sj_k >= s J_lo / sqrt(D_k,lo). Unlike the bound from N = J^2, it does not count
      // the |sj| of the part where J > 0: on a subdomain across the fold, where the
      // positive part dominates max N / D_k, it is the sharper one
      // (warped_prism_o2_N6_a0.25: 6274 -> 848 subdivisions, at most 15 instead of 414
      // per element).
      if (signed_volume_) {
        if (j_lo >= 0) {
          best = 0;
        } else {
          const double d_lo = down(least(d) - ed);
          if (d_lo > 0) best = std::max(best, -up(space_.s_hi() * up(-j_lo / down(sqrt_rn(d_lo)))));
        }
      }
      frame_lower[t] = best;
      out = std::min(out, best);
    }
    return out;
  }

  // The value lower() takes where neither J > 0 nor a bound on N / D_k is proven.
  double floor() const { return -up(space_.s_hi() * up(sqrt_rn(1.0))); }

  // True when no subdomain inside this one can ever get a lower bound above floor():
  // (1) at one of its vertices J <= 0 is certified, so every subdomain holding that vertex
  // fails the sign test (J > 0 is not proven there), and (2) for some frame k every
  // computed coefficient of D_k (and of G_k, if it has a Hadamard pair) is at most its
  // error bound: bisection never raises the largest coefficient nor lowers the error
  // bound (bernstein_bisection.hpp), so D_k (G_k) is never proven positive inside either,
  // and that frame stays at the floor. This is what happens around a point where two
  // columns of a frame vanish inside a fold (or one, without a Hadamard pair): there sj has
  // no limit, and the subdivision only zooms in on that point.
  bool stuck_at_floor(const double* v, const double* err, const LeafFrames& lf,
                      std::span<const int> vertices) const {
    if (valid_) return false;
    bool nonpositive_vertex = false;
    for (int i : vertices) nonpositive_vertex = nonpositive_vertex || up(v[i] + err[0]) <= 0;
    if (!nonpositive_vertex) return false;
    const auto vanishes = [&](std::size_t q) { return *std::max_element(v + q * size_, v + (q + 1) * size_) <= err[q]; };
    std::size_t q = first_group();
    for (std::size_t t = 0; t < lf.count; q += lf.width[t], ++t)
      if (vanishes(q) && (lf.width[t] == 1 || vanishes(q + 2))) return true;
    return false;
  }

  // Certified upper bound of sj at the point where the vectors' entry i are values (the
  // leaf's open frames only: sj is at most each frame's value).
  double point_upper(const double* v, const double* err, const LeafFrames& lf, std::size_t i) const {
    const double nv = v[n_ * size_ + i];
    std::size_t q = first_group();
    if (valid_ || down(v[i] - err[0]) > 0 || !(up(v[i] + err[0]) < 0)) {
      // J > 0 (or unknown: then sj <= 0 or sj = s min_k sqrt(N/D_k)).
      double val = space_.s_hi();
      for (std::size_t t = 0; t < lf.count; q += lf.width[t], ++t) {
        const double d_lo = down(v[q * size_ + i] - err[q]);
        if (!(d_lo > 0)) continue;
        const double r = up(std::max(0.0, up(nv + err[n_])) / d_lo);
        val = std::min(val, up(space_.s_hi() * up(sqrt_rn(r))));
      }
      return val;
    }
    // J < 0: sj = -s max_k sqrt(N / D_k) <= -s sqrt(N / D_k) for every k.
    double val = 0;
    for (std::size_t t = 0; t < lf.count; q += lf.width[t], ++t) {
      const double d_hi = up(v[q * size_ + i] + err[q]);
      const double r = down(std::max(0.0, down(nv - err[n_])) / d_hi);
      val = std::min(val, -down(space_.s_lo() * down(sqrt_rn(r))));
    }
    return val;
  }

 private:
  // The least of the size_ values at x (vectorised: lane_vector.hpp says why by hand).
  double least(const double* x) const { return least_value(x, size_); }

  // An upper bound of max_i (num_i + num_err) / (den_i - den_err), at least 0, or 1 (no
  // bound) unless every den_i - den_err is positive. Without directed roundings
  // (ratio_scan.hpp): a difference of doubles keeps its sign exactly, and each of the sum, the
  // difference and the quotient rounds once (relative u each; an underflowing quotient
  // loses at most denorm_min), so (1 + 4u) times the computed maximum, rounded up, plus
  // denorm_min covers the exact one.
  double max_ratio(const double* num, double num_err, const double* den, double den_err) const {
    const RatioScan scan = scan_ratios<false>(num, num_err, den, -den_err, -den_err, size_);
    if (!(scan.least_den > 0)) return 1;
    const double r = 0 < scan.extreme ? scan.extreme : 0.0;
    return up(up(r * (1 + 4 * kUnit)) + std::numeric_limits<double>::denorm_min());
  }

  const ScaledJacobianSpace& space_;
  std::size_t size_;
  bool valid_;
  bool signed_volume_;
  std::size_t n_;  // index of N in a leaf (J, when held, is 0)
};

// A coefficient vector with its bounds: |entries| <= m (computed), |entry - exact| <= e.
// Kept in thread-local scratch and overwritten in place (no allocation once warm).
struct Poly {
  std::vector<FactorDegree> deg;
  std::vector<double> c;
  Eb b;
};

void refresh_magnitude(Poly& p) { p.b.m = largest_magnitude(p.c.data(), p.c.size()); }

struct ProductTerm {
  const Poly* f;
  const Poly* g;
  double scale;
};

// The shared table of (f, g), looked up once per thread and degree pair (no lock, no
// allocation per product). The key packs each factor's dimension and degree of both
// operands, 10 bits each (at most 3 factors, degrees below 256): a linear search over the
// few pairs in use (against a std::map keyed by 12 ints: hex_box sj, one thread, fastest
// of 15, 27.6 -> 27.0 ms).
const BernsteinProduct& product_table(const Poly& f, const Poly& g) {
  thread_local std::vector<std::pair<std::uint64_t, const BernsteinProduct*>> tables;
  QV_ASSERT(f.deg.size() <= 3 && f.deg.size() == g.deg.size(), f.deg.size() << " factors");
  std::uint64_t key = f.deg.size();
  for (const Poly* p : {&f, &g})
    for (const FactorDegree& fd : p->deg) {
      QV_ASSERT(fd.degree >= 0 && fd.degree < 256 && fd.dim >= 0 && fd.dim < 4, "factor " << fd.dim << ", " << fd.degree);
      key = key << 10 | static_cast<std::uint64_t>(fd.dim) << 8 | static_cast<std::uint64_t>(fd.degree);
    }
  for (const auto& [k, table] : tables)
    if (k == key) return *table;
  tables.emplace_back(key, &bernstein_product(f.deg, g.deg));
  return *tables.back().second;
}

// h = sum_t scale_t f_t g_t (Paper V Prop. 4), all pairs (f_t, g_t) of the same two
// spaces; error: propagated input errors plus bernstein_product's rounding bound.
// @pre h is none of the inputs
void product_sum(std::initializer_list<ProductTerm> terms, Poly& h) {
  const ProductTerm& first = *terms.begin();
  const BernsteinProduct& table = product_table(*first.f, *first.g);
  h.deg.resize(first.f->deg.size());
  for (std::size_t i = 0; i < h.deg.size(); ++i)
    h.deg[i] = {first.f->deg[i].dim, first.f->deg[i].degree + first.g->deg[i].degree};
  h.c.assign(static_cast<std::size_t>(table.h_size()), 0.0);
  double magnitude = 0, propagated = 0;
  bool zero_everywhere = true;
  std::array<BernsteinProduct::Term, 8> batch{};
  QV_ASSERT(terms.size() <= batch.size(), terms.size() << " terms");
  std::size_t k = 0;
  for (const ProductTerm& t : terms) {
    const Poly& f = *t.f;
    const Poly& g = *t.g;
    QV_ASSERT(&f != &h && &g != &h, "product into its own input");
    batch[k++] = {t.scale, f.c.data(), g.c.data()};
    const double sc = std::abs(t.scale);
    magnitude += sc * f.b.m * g.b.m;
    zero_everywhere = zero_everywhere && (f.b.m == 0 || g.b.m == 0);
    propagated += sc * (f.b.m * g.b.e + (g.b.m + g.b.e) * f.b.e);
  }
  // Every term with a factor that is zero everywhere (a planar element's z coordinates in
  // the cross products): h stays +0, as the kernel would leave it; the error bound is kept.
  if (!zero_everywhere) table.multiply_add_sum(std::span<const BernsteinProduct::Term>(batch.data(), k), h.c.data());
  refresh_magnitude(h);
  h.b.e = propagated + table.rounding(static_cast<int>(k)) * magnitude;
}

// p = sum_t w_t q_t (same space, t < n), w_t in {-1, 1} or |w_t| <= 1 (a reference
// direction).
void linear_sum(const Poly* const* q, const double* w, std::size_t n, Poly& p) {
  p.deg = q[0]->deg;
  p.c.assign(q[0]->c.size(), 0.0);
  double e = 0, m = 0;
  for (std::size_t t = 0; t < n; ++t) {
    QV_ASSERT(q[t]->c.size() == p.c.size(), "spaces differ");
    for (std::size_t i = 0; i < p.c.size(); ++i) p.c[i] += w[t] * q[t]->c[i];
    e += std::abs(w[t]) * q[t]->b.e;
    m += std::abs(w[t]) * q[t]->b.m;
  }
  refresh_magnitude(p);
  // Each product w q rounds once (exact for w = +-1) and each of the n - 1 sums once.
  p.b.e = e + rounding_gamma(2 * static_cast<int>(n)) * m;
}

using Columns = std::array<std::array<Poly, 3>, 3>;  // [column c][coordinate]

// Frame column j of frame fr (the components of v_j = sum_c fr[j][c] c_c) into vj.
void frame_column(const Frame& fr, std::size_t j, std::size_t dim, const Columns& col, std::array<Poly, 3>& vj) {
  for (std::size_t x = 0; x < 3; ++x) {
    const Poly* q[3];
    double wt[3];
    std::size_t terms = 0;
    for (std::size_t c = 0; c < dim; ++c)
      if (fr[j][c] != 0) {
        q[terms] = &col[c][x];
        wt[terms++] = fr[j][c];
      }
    linear_sum(q, wt, terms, vj[x]);
  }
}

// The polynomials of one element, reused from element to element.
struct Polys {
  Columns col;
  std::array<Poly, 3> w;  // a cross product of two columns
  Poly jac, n, jsq, one, prod, tmp;
  // The distinct frame columns up to sign (a tetrahedron's 4 corner frames have 12
  // columns but 6 edges, a prism's 3 have 9 but 4), each with its squared norm: D_k, H_k
  // and G_k use only the squares and |v_b x v_c|^2, which a sign leaves unchanged.
  std::vector<std::array<int, 3>> distinct;  // weights, first nonzero positive
  std::vector<std::array<Poly, 3>> distinct_col;
  std::vector<Poly> distinct_sq;
  std::vector<Poly> dk, hadamard;  // per frame: D_k; H_k, G_k
};

// Index in polys.distinct of frame column j of fr, computed on first use.
std::size_t distinct_column(const Frame& fr, std::size_t j, std::size_t dim, Polys& polys) {
  std::array<int, 3> w = fr[j];
  const auto first = std::find_if(w.begin(), w.end(), [](int x) { return x != 0; });
  if (first != w.end() && *first < 0)
    for (int& x : w) x = -x;
  const auto it = std::find(polys.distinct.begin(), polys.distinct.end(), w);
  const auto d = static_cast<std::size_t>(it - polys.distinct.begin());
  if (it != polys.distinct.end()) return d;
  polys.distinct.push_back(w);
  if (polys.distinct_col.size() <= d) polys.distinct_col.resize(d + 1);
  if (polys.distinct_sq.size() <= d) polys.distinct_sq.resize(d + 1);
  std::array<Poly, 3>& v = polys.distinct_col[d];
  frame_column(Frame{w, {}, {}}, 0, dim, polys.col, v);
  product_sum({{&v[0], &v[0], 1.0}, {&v[1], &v[1], 1.0}, {&v[2], &v[2], 1.0}}, polys.distinct_sq[d]);
  return d;
}

// The quotient stage's view of an element's J and columns (scaled_jacobian_quotient.hpp).
QuotientInput quotient_input(const Polys& polys, std::size_t dim) {
  QuotientInput in;
  in.j = polys.jac.c;
  in.j_degrees = &polys.jac.deg;
  in.j_error = polys.jac.b.e;
  for (std::size_t c = 0; c < dim; ++c) {
    in.col_degrees[c] = &polys.col[c][0].deg;
    for (std::size_t x = 0; x < 3; ++x) {
      in.col[c][x] = polys.col[c][x].c;
      in.col_error[c] = std::max(in.col_error[c], polys.col[c][x].b.e);
      in.col_magnitude[c] = std::max(in.col_magnitude[c], polys.col[c][x].b.m);
    }
  }
  bool flat = true;
  for (std::size_t c = 0; c < dim; ++c) flat = flat && polys.col[c][2].b.m == 0;
  if (flat) in.coordinates = 2;
  return in;
}

// Steps 1 and 2a of scaled_jacobian_bounds_given for one element: its columns and J, into
// polys (values: scratch for the node differences).
void columns_and_jacobian(const ScaledJacobianSpace& space, std::span<const double> nodes, bool planar,
                          Polys& polys, std::vector<double>& values) {
  const ElementType& type = space.type();
  const auto udim = static_cast<std::size_t>(type.dim);
  const int dim = type.dim;
  const auto nn = static_cast<std::size_t>(type.num_nodes);
  // 1. Bézier coefficients of the columns of J_p in their own degrees: an exact linear
  //    map of x_i - x_0 (the maps' rows sum to zero: the translation is exact in the
  //    definition); error (4u entries + u differences + gamma_N sums) * row sum * R,
  //    counted as 6u + gamma_N.
  double range = 0;
  bool flat_z = true;  // an element in a plane z = const: every column's z coefficients +0
  values.resize(nn * 3);
  for (std::size_t i = 0; i < nn; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      values[i * 3 + j] = nodes[3 * i + j] - nodes[j];
      range = std::max(range, std::abs(values[i * 3 + j]));
    }
    flat_z = flat_z && values[i * 3 + 2] == 0;
  }
  auto& col = polys.col;
  for (std::size_t c = 0; c < udim; ++c) {
    const SparseRows& m = space.column_nonzeros(static_cast<int>(c));
    const auto rows = static_cast<std::size_t>(space.column_size(static_cast<int>(c)));
    const double e = (6 * kUnit + rounding_gamma(type.num_nodes)) * space.column_row_sum(static_cast<int>(c)) * range * 1.01;
    for (std::size_t j = 0; j < 3; ++j) {
      Poly& p = col[c][j];
      p.deg = space.column_degrees(static_cast<int>(c));
      p.c.resize(rows);
      p.b.e = e;
    }
    thread_local std::vector<double> values_by_coordinate;  // coordinate j of row r at j * rows + r
    values_by_coordinate.resize(3 * rows);
    m.times_points(values.data(), flat_z, range < kInf, values_by_coordinate.data());
    for (std::size_t j = 0; j < 3; ++j)
      std::copy_n(values_by_coordinate.begin() + static_cast<std::ptrdiff_t>(j * rows), rows, col[c][j].c.begin());
    for (std::size_t j = 0; j < 3; ++j) refresh_magnitude(col[c][j]);
  }

  // 2a. J by Bernstein products (w = the cross product of the first two columns in 2D, of
  //     the last two in 3D).
  const auto ref = reference_direction(type, nodes.data(), planar);
  Poly& jac = polys.jac;
  auto& w = polys.w;
  if (dim == 3) {
    for (std::size_t x = 0; x < 3; ++x) {  // w = c_1 x c_2
      const std::size_t y = (x + 1) % 3, z = (x + 2) % 3;
      product_sum({{&col[1][y], &col[2][z], 1.0}, {&col[1][z], &col[2][y], -1.0}}, w[x]);
    }
    product_sum({{&col[0][0], &w[0], 1.0}, {&col[0][1], &w[1], 1.0}, {&col[0][2], &w[2], 1.0}}, jac);
  } else if (dim == 2) {
    for (std::size_t x = 0; x < 3; ++x) {  // w = c_0 x c_1
      const std::size_t y = (x + 1) % 3, z = (x + 2) % 3;
      product_sum({{&col[0][y], &col[1][z], 1.0}, {&col[0][z], &col[1][y], -1.0}}, w[x]);
    }
    const Poly* q[3] = {&w[0], &w[1], &w[2]};
    linear_sum(q, ref.data(), 3, jac);
  } else {
    const Poly* q[3] = {&col[0][0], &col[0][1], &col[0][2]};
    linear_sum(q, ref.data(), 3, jac);
  }
}

thread_local bool use_straight_path = true;

// The frame columns of a simplex that differ other than in sign, as weights of the edges
// (first nonzero weight positive), and per frame k its column j's index among them.
struct SimplexFrameColumns {
  std::size_t count = 0;
  std::array<std::array<int, 3>, 6> weight{};
  std::array<std::array<std::size_t, 3>, 4> of{};
};

SimplexFrameColumns make_simplex_frame_columns(const ScaledJacobianSpace& space) {
  SimplexFrameColumns fc;
  const auto dim = static_cast<std::size_t>(space.dim());
  QV_ASSERT(space.frames().size() <= fc.of.size(), space.frames().size() << " frames");
  for (std::size_t k = 0; k < space.frames().size(); ++k)
    for (std::size_t j = 0; j < dim; ++j) {
      std::array<int, 3> w = space.frames()[k][j];
      const int first = *std::find_if(w.begin(), w.end(), [](int x) { return x != 0; });
      if (first < 0)
        for (int& x : w) x = -x;
      std::size_t d = 0;
      while (d < fc.count && fc.weight[d] != w) ++d;
      if (d == fc.count) {
        QV_ASSERT(fc.count < fc.weight.size(), "more than 6 frame columns");
        fc.weight[fc.count++] = w;
      }
      fc.of[k][j] = d;
    }
  return fc;
}

// Built once per simplex family (tetrahedra, planar triangles).
const SimplexFrameColumns& simplex_frame_columns(const ScaledJacobianSpace& space) {
  if (space.type().family == ElementFamily::tetrahedron) {
    static const SimplexFrameColumns tet = make_simplex_frame_columns(space);
    return tet;
  }
  static const SimplexFrameColumns triangle = make_simplex_frame_columns(space);
  return triangle;
}

template <class T>
struct StraightSj {
  T lower{}, upper{};
  decltype(T{} < T{}) ok{};  ///< where these bounds hold and meet the tolerance
};

// A valid straight-sided simplex (planar triangle, tetrahedron; order 1, or higher with a
// finite straight_sided.hpp margin): its columns are the edges a_c = x_c - x_0 up to beta_c
// (0 at order 1) and J is J_1 (within err) up to the margin m, so on the whole element each
// frame's s J / prod_j |v_j| lies between s (J_1 - m) / prod (|v~_j| + e_j) and
// s (J_1 + m) / prod (|v~_j| - e_j), v~_j the frame's columns computed from the edges and
// e_j the sum of beta_c over its columns plus 4u of their 1-norms (the edges' and sums'
// roundings); the norms' own few ulps are covered by 1 +- 1e-12, J_1's rounding by
// linear_jacobian's err. The minimum over the frames of each bound bounds min sj. Not ok
// where the bounds are wider than tol (or a step below fails).
// T = double for one element, LaneBlock for one element per lane: the same operations, so
// the same bits (straight_simplex_sj_lanes).
template <class T>
StraightSj<T> straight_simplex_sj(const ScaledJacobianSpace& space, const std::array<std::array<T, 3>, 3>& a,
                                  const std::array<T, 3>& beta, T m, T j1, T err, double tol) {
  StraightSj<T> out;
  const T j_lo = down(down(j1 - err) - m), j_hi = up(up(j1 + err) + m);
  out.ok = (j_lo > 0) & (j_hi < kInf);
  const auto dim = static_cast<std::size_t>(space.dim());
  std::array<T, 3> a_norm1{};  // the edges' 1-norms
  for (std::size_t c = 0; c < dim; ++c)
    for (std::size_t j = 0; j < 3; ++j) a_norm1[c] += vabs(a[c][j]);
  // In plain arithmetic: every quantity below is nonnegative and its norms lie in
  // [2^-300, 2^300] (else the general path), so nothing underflows or overflows, and each
  // operation adds a relative error of at most u (the differences norm - e too, as e is at
  // most half the norm). Fewer than 40 roundings reach a frame's quotient, so widening the
  // least quotients by kSlack (about 9e4 u) covers them all; directed roundings at every
  // step cost twice as much on straight tetrahedra.
  constexpr double kSlack = 1e-11, kSmall = 0x1p-300, kLarge = 0x1p300;
  // Each distinct frame column's norm and error once (a tetrahedron's 4 corner frames use
  // its 6 edges, a triangle's 3 frames its 3; -v has exactly the norm of v).
  const SimplexFrameColumns& fc = simplex_frame_columns(space);
  std::array<T, 6> col_norm{}, col_err{};
  for (std::size_t d = 0; d < fc.count; ++d) {
    T v[3] = {}, e{};
    for (std::size_t c = 0; c < dim; ++c) {
      const int w = fc.weight[d][c];
      if (w == 0) continue;
      for (std::size_t k = 0; k < 3; ++k) v[k] += w * a[c][k];
      e += beta[c] + 4 * kUnit * a_norm1[c];
    }
    const T norm = root(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    out.ok = out.ok & (norm >= kSmall) & (norm <= kLarge) & (e <= 0.5 * norm);
    col_norm[d] = norm;
    col_err[d] = e;
  }
  T lower = T{} + kInf, upper = T{} + kInf;
  for (std::size_t k = 0; k < space.frames().size(); ++k) {
    T den_hi = T{} + 1, den_lo = T{} + 1;
    for (std::size_t j = 0; j < dim; ++j) {
      const std::size_t d = fc.of[k][j];
      den_hi *= col_norm[d] + col_err[d];
      den_lo *= col_norm[d] - col_err[d];
    }
    lower = vmin(lower, j_lo / den_hi);
    upper = vmin(upper, j_hi / den_lo);
  }
  out.lower = down(space.s_lo() * lower * (1 - kSlack));
  out.upper = up(space.s_hi() * upper * (1 + kSlack));
  out.ok = out.ok & (up(out.upper - out.lower) <= tol);
  return out;
}

// straight_simplex_sj of one element from its nodes; nothing when it is not such a
// simplex or the bounds are wider than tol.
std::optional<QualityBounds> straight_simplex_bounds(const ScaledJacobianSpace& space, std::span<const double> x,
                                                     bool planar, double tol, const KnownMargin* known) {
  const ElementType& type = space.type();
  const bool triangle = type.family == ElementFamily::triangle && planar && in_a_z_plane(x);
  if (!use_straight_path || !(triangle || type.family == ElementFamily::tetrahedron)) return std::nullopt;
  std::array<double, 3> beta{0, 0, 0};
  double m = 0;
  if (type.order > 1) {
    m = straight_margin_of(type, x.data(), known, beta);
    if (!(m < kInf)) return std::nullopt;
  }
  const LinearKind kind = triangle ? LinearKind::triangle : LinearKind::tetrahedron;
  double j1 = 0;
  const double err = linear_jacobian_coefficients(kind, x.data(), &j1);
  std::array<std::array<double, 3>, 3> a{};  // the edges
  for (std::size_t c = 0; c < static_cast<std::size_t>(type.dim); ++c)
    for (std::size_t j = 0; j < 3; ++j) a[c][j] = x[3 * (c + 1) + j] - x[j];
  const StraightSj<double> sj = straight_simplex_sj(space, a, beta, m, j1, err, tol);
  if (!sj.ok) return std::nullopt;
  return QualityBounds{sj.lower, sj.upper, 0, true};
}

}  // namespace

void scaled_jacobian_use_straight_path(bool on) noexcept { use_straight_path = on; }
bool scaled_jacobian_straight_path_enabled() noexcept { return use_straight_path; }

unsigned straight_simplex_sj_lanes(const ElementType& type, const LaneBlock* edges, const LaneBlock* beta,
                                   LaneBlock margin, double tol, QualityBounds* out) {
  const bool triangle = type.family == ElementFamily::triangle;
  if (!use_straight_path || !(triangle || type.family == ElementFamily::tetrahedron)) return 0;
  LaneBlock j1;
  const LaneBlock err =
      linear_simplex_jacobian_lanes(triangle ? LinearKind::triangle : LinearKind::tetrahedron, edges, j1);
  std::array<std::array<LaneBlock, 3>, 3> a{};
  for (std::size_t c = 0; c < static_cast<std::size_t>(type.dim); ++c)
    for (std::size_t j = 0; j < 3; ++j) a[c][j] = edges[3 * c + j];
  // A first-order element's margins are 0, as the element alone takes them.
  const StraightSj<LaneBlock> sj =
      straight_simplex_sj(scaled_jacobian_space(type), a, {beta[0], beta[1], beta[2]}, margin, j1, err, tol);
  const unsigned done = lanes3::mask_bits<kNativeLanes>(sj.ok & (margin < kInf));
  for (int l = 0; l < kNativeLanes; ++l)
    if ((done >> l) & 1u) out[l] = QualityBounds{sj.lower[l], sj.upper[l], 0, true};
  return done;
}

QualityBounds scaled_jacobian_bounds(const ElementType& type, std::span<const double> nodes,
                                     const QualityOptions& options, bool planar) {
  QV_ASSERT(scaled_jacobian_supported(type), "no scaled Jacobian for " << type.name);
  // The sign of J on the whole element, settled by the Jacobian engine (certified, with
  // its exact fallback).
  thread_local BoundsWorkspace jacobian_ws;
  BoundsOptions validity;
  validity.goal = BoundsGoal::validity;
  validity.max_subdivisions = options.max_subdivisions;
  const Validity v = jacobian_bounds(type, nodes, validity, jacobian_ws, planar).validity;
  return scaled_jacobian_bounds_given(type, nodes, options, planar, v);
}

namespace {

// J and the frame columns of one element from its nodes, for the stages on their own
// below (tests): the spans point into this thread's storage, valid until its next call.
QuotientInput element_input(const ScaledJacobianSpace& space, std::span<const double> nodes, bool planar) {
  thread_local Polys polys;
  thread_local std::vector<double> values;
  columns_and_jacobian(space, nodes, planar, polys, values);
  return quotient_input(polys, static_cast<std::size_t>(space.dim()));
}

}  // namespace

QualityBounds scaled_jacobian_quotient_stage(const ElementType& type, std::span<const double> nodes, bool planar,
                                             double tol, int max_splits) {
  QV_ASSERT(scaled_jacobian_supported(type) && nodes.size() == static_cast<std::size_t>(type.num_nodes) * 3,
            "quotient stage of " << type.name);
  const ScaledJacobianSpace& space = scaled_jacobian_space(type);
  if (type.dim == 2 && !planar) return {-kInf, space.s_hi(), 0, false};
  return quotient_bounds(space, element_input(space, nodes, planar), tol, max_splits, max_splits);
}

QualityBounds scaled_jacobian_signed_stage(const ElementType& type, std::span<const double> nodes, double tol,
                                           int max_splits, bool floor_root_ends) {
  QV_ASSERT(scaled_jacobian_supported(type) && type.dim >= 2 && nodes.size() == static_cast<std::size_t>(type.num_nodes) * 3,
            "signed stage of " << type.name);
  const ScaledJacobianSpace& space = scaled_jacobian_space(type);
  return signed_quotient_bounds(space, element_input(space, nodes, /*planar=*/type.dim == 2), tol, max_splits, 0.0,
                                nullptr, floor_root_ends);
}

SjProbe scaled_jacobian_probe(const ElementType& type, std::span<const double> nodes, double enough) {
  QV_ASSERT(scaled_jacobian_supported(type) && type.dim >= 2 && nodes.size() == static_cast<std::size_t>(type.num_nodes) * 3,
            "probe of " << type.name);
  const ScaledJacobianSpace& space = scaled_jacobian_space(type);
  return probe_scaled_jacobian(space, element_input(space, nodes, /*planar=*/type.dim == 2), enough);
}

// columns_and_jacobian of four valid planar elements in planes z = const, element l in lane
// l of every vector, for paired_quotient_roots: the same operations lane by lane, so the
// same bits as each element's own QuotientInput (SparseRows::rows_times_planar_lanes,
// BernsteinProduct::multiply_add_sum2x4; in z = const, J = c_0 x c_1 . (0, 0, 1) is the
// cross product's z term, whose x and y terms are products of zeros). false where that does
// not apply (an element off a plane z = const, a coordinate or bound not finite, a product
// without the entry kernel): then the elements' own calls.
struct PlanarLanes {
  using V = Lanes<4>;
  std::vector<V> d, jac;
  std::array<std::vector<V>, 2> col;  // column c: its x coefficients, then its y
  std::vector<FactorDegree> j_degrees;
};

bool planar_lanes_input(const ScaledJacobianSpace& space, const std::array<std::span<const double>, 4>& nodes,
                        PlanarLanes& ws, QuotientLanes& in) {
  using V = PlanarLanes::V;
  const ElementType& type = space.type();
  const auto nn = static_cast<std::size_t>(type.num_nodes);
  // 1. The node differences x_i - x_0 and their range, as columns_and_jacobian takes them.
  ws.d.resize(2 * nn);
  V range{};
  if (!planar_differences(nodes, nn, ws.d.data(), range)) return false;
  // 2. The columns' coefficients, error bounds and magnitudes (z: zeros, magnitude 0).
  std::array<V, 2> err, mag_x, mag_y;
  for (std::size_t c = 0; c < 2; ++c) {
    const auto rows = static_cast<std::size_t>(space.column_size(static_cast<int>(c)));
    const double factor = (6 * kUnit + rounding_gamma(type.num_nodes)) * space.column_row_sum(static_cast<int>(c));
    err[c] = factor * range * 1.01;
    ws.col[c].resize(2 * rows);
    space.column_nonzeros(static_cast<int>(c)).rows_times_planar_lanes(ws.d.data(), ws.col[c].data());
    mag_x[c] = mag_y[c] = V{};
    for (std::size_t r = 0; r < rows; ++r) {
      mag_x[c] = vmax(mag_x[c], vabs(ws.col[c][r]));
      mag_y[c] = vmax(mag_y[c], vabs(ws.col[c][rows + r]));
    }
    in.col[c][0] = std::span<const V>(ws.col[c].data(), rows);
    in.col[c][1] = std::span<const V>(ws.col[c].data() + rows, rows);
    in.col_degrees[c] = &space.column_degrees(static_cast<int>(c));
    in.col_error[c] = vmax(vmax(vmax(V{}, err[c]), err[c]), err[c]);
    in.col_magnitude[c] = vmax(vmax(vmax(V{}, mag_x[c]), mag_y[c]), V{});
  }
  // 3. J = 0 + c_0,x c_1,y - c_0,y c_1,x (product_sum, then linear_sum with (0, 0, 1)).
  const BernsteinProduct& table = bernstein_product(space.column_degrees(0), space.column_degrees(1));
  ws.jac.assign(static_cast<std::size_t>(table.h_size()), V{});
  const auto lanes = [](const std::vector<V>& v, std::size_t at) { return reinterpret_cast<const double*>(v.data() + at); };
  const std::size_t r0 = in.col[0][0].size(), r1 = in.col[1][0].size();
  // product_sum leaves J +0 where every term has a factor zero everywhere: not in lanes.
  const auto zero_everywhere = ((mag_x[0] == 0) | (mag_y[1] == 0)) & ((mag_y[0] == 0) | (mag_x[1] == 0));
  for (std::size_t l = 0; l < 4; ++l)
    if (zero_everywhere[l] != 0) return false;
  if (!table.multiply_add_sum2x4(1.0, lanes(ws.col[0], 0), lanes(ws.col[1], r1), -1.0, lanes(ws.col[0], r0),
                                 lanes(ws.col[1], 0), reinterpret_cast<double*>(ws.jac.data())))
    return false;
  V w_mag{};
  for (V& c : ws.jac) {
    w_mag = vmax(w_mag, vabs(c));
    c = V{} + c;
  }
  // product_sum's error bounds of the cross product's three terms (factors' magnitudes and
  // errors; z: 0 and the columns' error), then linear_sum's with weights 0, 0, 1.
  const double rounding = table.rounding(2);
  const auto cross_error = [&](V fm0, V gm0, V fm1, V gm1) {
    const V magnitude = (V{} + 1.0 * fm0 * gm0) + 1.0 * fm1 * gm1;
    const V propagated = (V{} + 1.0 * (fm0 * err[1] + (gm0 + err[1]) * err[0])) + 1.0 * (fm1 * err[1] + (gm1 + err[1]) * err[0]);
    return propagated + rounding * magnitude;
  };
  const V e0 = cross_error(mag_y[0], V{}, V{}, mag_y[1]);  // c_0,y c_1,z - c_0,z c_1,y
  const V e1 = cross_error(V{}, mag_x[1], mag_x[0], V{});  // c_0,z c_1,x - c_0,x c_1,z
  const V e2 = cross_error(mag_x[0], mag_y[1], mag_y[0], mag_x[1]);
  const V e = ((V{} + 0.0 * e0) + 0.0 * e1) + 1.0 * e2;
  const V m = ((V{} + 0.0 * V{}) + 0.0 * V{}) + 1.0 * w_mag;
  in.j_error = e + rounding_gamma(6) * m;
  for (std::size_t l = 0; l < 4; ++l)
    if (!(in.j_error[l] < kInf) || !(in.col_magnitude[0][l] < kInf) || !(in.col_magnitude[1][l] < kInf)) return false;
  const auto h = table.h_degrees();
  ws.j_degrees.assign(h.begin(), h.end());
  in.j = ws.jac;
  in.j_degrees = &ws.j_degrees;
  return true;
}

unsigned scaled_jacobian_valid_planar4(const ElementType& type, const std::array<std::span<const double>, 4>& nodes,
                                       const QualityOptions& options, const std::array<const KnownMargin*, 4>& known,
                                       std::array<QualityBounds, 4>& out) {
  QV_ASSERT(scaled_jacobian_supported(type) && type.dim == 2, "four planar elements of " << type.name);
  const ScaledJacobianSpace& space = scaled_jacobian_space(type);
  unsigned done = 0;
  for (std::size_t l = 0; l < 4; ++l) {
    QV_ASSERT(nodes[l].size() == static_cast<std::size_t>(type.num_nodes) * 3, "nodes " << nodes[l].size());
    // scaled_jacobian_bounds_given's steps before its first stage.
    if (const auto straight = straight_simplex_bounds(space, nodes[l], true, options.abs_tol, known[l])) {
      out[l] = *straight;
      done |= 1u << l;
    } else if (use_straight_path) {
      if (const auto bilinear = bilinear_quad_sj_bounds(type, nodes[l], options.abs_tol, known[l])) {
        out[l] = *bilinear;
        done |= 1u << l;
      }
    }
  }
  if (done == 15) return done;
  thread_local PlanarLanes ws;
  QuotientLanes in;
  if (!planar_lanes_input(space, nodes, ws, in)) return done;
  std::array<QualityBounds, 4> roots;
  const unsigned settled = paired_quotient_roots(space, in, options.abs_tol, roots) & ~done & 15u;
  for (std::size_t l = 0; l < 4; ++l)
    if ((settled >> l) & 1u) out[l] = roots[l];
  return done | settled;
}

QualityBounds scaled_jacobian_bounds_given(const ElementType& type, std::span<const double> nodes,
                                           const QualityOptions& options, bool planar, Validity v,
                                           const KnownMargin* known) {
  QV_ASSERT(scaled_jacobian_supported(type), "no scaled Jacobian for " << type.name);
  QV_ASSERT(nodes.size() == static_cast<std::size_t>(type.num_nodes) * 3,
            "nodes " << nodes.size() << " for " << type.name);
  thread_local Scratch ws;
  const ScaledJacobianSpace& space = scaled_jacobian_space(type);
  const BernsteinBisection& b2 = space.squared();
  const auto s2 = static_cast<std::size_t>(b2.size());
  const int dim = type.dim;
  const auto udim = static_cast<std::size_t>(dim);
  const std::size_t frames = space.frames().size();

  if (v == Validity::valid) {
    if (const auto straight = straight_simplex_bounds(space, nodes, planar, options.abs_tol, known)) return *straight;
    if (use_straight_path && planar)
      if (const auto bilinear = bilinear_quad_sj_bounds(type, nodes, options.abs_tol, known)) return *bilinear;
    if (use_straight_path && type.family == ElementFamily::hexahedron && type.num_nodes == 8)
      if (const auto hex = trilinear_hex_sj_bounds(nodes, options.abs_tol)) return *hex;
    if (use_straight_path && type.family == ElementFamily::pyramid && type.num_nodes == 5)
      if (const auto pyramid = linear_pyramid_sj_bounds(space, nodes, options.abs_tol)) return *pyramid;
  }
  thread_local Polys polys;
  const bool area = dim == 2 && !planar;  // N = |c_1 x c_2|^2 rather than J^2
  columns_and_jacobian(space, nodes, planar, polys, ws.values);
  Poly& jac = polys.jac;
  Poly& n = polys.n;
  auto& w = polys.w;
  // The first stage (scaled_jacobian_quotient.hpp): on a valid element, J and the frame
  // columns alone, split a few times, settle most elements without the products of twice
  // the degree below; its bounds still count when it does not.
  QualityBounds quick{-kInf, space.s_hi(), 0, false};
  FrameBounds quick_frames;  // per frame, the first stage's lower bound over the element
  quick_frames.fill(-kInf);
  if (v == Validity::valid && !area) {
    quick = quotient_bounds(space, quotient_input(polys, udim), options.abs_tol,
                            std::min(kQuotientSplits, options.max_subdivisions),
                            std::min(kPairedSplits, options.max_subdivisions), &quick_frames);
    if (quick.tolerance_met) return quick;
  }
  // Where J <= 0 was found (3D), the signed first stage likewise: J's coefficients with
  // their signs over products of the columns along their mean directions.
  if (v == Validity::invalid && (dim == 3 || (dim == 2 && !area))) {
    const QuotientInput in = quotient_input(polys, udim);
    const int splits = std::min(kSignedSplits, options.max_subdivisions);
    quick = signed_quotient_bounds(space, in, options.abs_tol, splits, 0.0, &quick_frames,
                                   signed_floor_root_ends(type));
    if (quick.tolerance_met) return quick;
    // Not settled, in 2D with the lower bound at the floor -s (a fold: the columns at right
    // angles, the wrong way round): that bound is sharp, and only the upper bound, from the
    // subdomains' corners, needs the subdivisions; an upper bound from a local search
    // (scaled_jacobian_probe.hpp) settles it instead. quad_h0.4_o2's four most inverted
    // quadrangles: 26-30 subdivisions, 285 us -> none, 103 us. Elsewhere the lower bound
    // is what stays short (a perfect upper bound settled 538 instead of 532 of the 660
    // inverted elements of warped_tetrahedron_o3), and the search costs more than it saves.
    const bool at_floor = dim == 2 && quick.lower <= -space.s_hi();
    const double probed = at_floor ? probe_scaled_jacobian(space, in, quick.lower + 0.5 * options.abs_tol).upper : 0.0;
    if (probed < quick.upper) {
      quick = signed_quotient_bounds(space, in, options.abs_tol, splits, probed, &quick_frames,
                                     signed_floor_root_ends(type));
      if (quick.tolerance_met) return quick;
    }
  }
  if (area)
    product_sum({{&w[0], &w[0], 1.0}, {&w[1], &w[1], 1.0}, {&w[2], &w[2], 1.0}}, n);
  else
    product_sum({{&jac, &jac, 1.0}}, n);
  // J in the squared space (J * 1, 1 with all coefficients 1 in J's space), for the sign
  // tests of the subdomains; not needed when J > 0 is proven on the whole element.
  const bool valid = v == Validity::valid;
  Poly& jsq = polys.jsq;
  if (!valid) {
    Poly& one = polys.one;
    one.deg = jac.deg;
    one.c.assign(jac.c.size(), 1.0);
    one.b = {1, 0};
    product_sum({{&jac, &one, 1.0}}, jsq);
  }
  auto& dk = polys.dk;
  dk.resize(frames);
  polys.distinct.clear();
  // An element not proven valid may hold a point of a fold where a frame column vanishes;
  // there D_k = 0, and only the Hadamard bound (Bounder::lower) with that column divided
  // out stays sharp. A frame whose D_k is not proven positive at the root gets that bound
  // for its column most likely to vanish: H = |v_b x v_c|^2 and G = |v_b|^2 |v_c|^2, both
  // times 1 in the space of |v_a|^2 to reach the squared space (3D only: in 2D |V_k| =
  // |v_a| |v_b| sin, and dividing out leaves nothing below -s).
  const bool hadamard_frames = !valid && dim == 3;
  QV_ASSERT(frames <= LeafFrames::kMax, frames << " frames");
  // A frame whose first-stage bound is already within the tolerance of that stage's upper
  // bound (which only decreases) needs nothing more: it is left out of the leaves, its
  // bound kept aside (as the refinement's closed frames are).
  std::array<bool, LeafFrames::kMax> done{};
  double done_lower = kInf;
  for (std::size_t f = 0; f < frames; ++f) {
    done[f] = up(quick.upper - quick_frames[f]) <= options.abs_tol;
    if (done[f]) done_lower = std::min(done_lower, quick_frames[f]);
  }
  std::array<bool, LeafFrames::kMax> hadamard{};
  auto& had = polys.hadamard;
  had.resize(2 * frames);
  for (std::size_t f = 0; f < frames; ++f) {
    if (done[f]) continue;
    const Frame& fr = space.frames()[f];
    std::array<std::size_t, 3> d{};
    for (std::size_t j = 0; j < udim; ++j) d[j] = distinct_column(fr, j, udim, polys);
    const auto sq = [&](std::size_t j) -> const Poly& { return polys.distinct_sq[d[j]]; };
    Poly& prod = polys.prod;
    if (udim == 1) {
      prod = sq(0);
    } else {
      product_sum({{&sq(0), &sq(1), 1.0}}, prod);
      if (udim == 3) {
        product_sum({{&prod, &sq(2), 1.0}}, polys.tmp);
        std::swap(prod, polys.tmp);
      }
    }
    std::swap(dk[f], prod);
    const auto least = [](const Poly& p) { return *std::min_element(p.c.begin(), p.c.end()) - p.b.e; };
    if (!hadamard_frames || least(dk[f]) > 0) continue;
    // Column a: the least lower bound of |v_a|^2 relative to its size.
    std::size_t a = 0;
    for (std::size_t j = 1; j < 3; ++j)
      if (least(sq(j)) * std::max(sq(a).b.m, 1e-300) < least(sq(a)) * std::max(sq(j).b.m, 1e-300)) a = j;
    const std::size_t b = (a + 1) % 3, c = (a + 2) % 3;
    const auto& vb = polys.distinct_col[d[b]];
    const auto& vc = polys.distinct_col[d[c]];
    auto& cr = polys.w;
    for (std::size_t x = 0; x < 3; ++x) {  // v_b x v_c
      const std::size_t y = (x + 1) % 3, z = (x + 2) % 3;
      product_sum({{&vb[y], &vc[z], 1.0}, {&vb[z], &vc[y], -1.0}}, cr[x]);
    }
    Poly& one = polys.one;
    one.deg = sq(a).deg;
    one.c.assign(sq(a).c.size(), 1.0);
    one.b = {1, 0};
    product_sum({{&cr[0], &cr[0], 1.0}, {&cr[1], &cr[1], 1.0}, {&cr[2], &cr[2], 1.0}}, polys.tmp);
    product_sum({{&polys.tmp, &one, 1.0}}, had[2 * f]);
    product_sum({{&sq(b), &sq(c), 1.0}}, polys.tmp);
    product_sum({{&polys.tmp, &one, 1.0}}, had[2 * f + 1]);
    hadamard[f] = true;
  }

  // 3. The root, slot 0 of the leaf pool: its vectors in the order of LeafFrames.
  // At most J, N and three vectors per frame; fixed arrays, as this runs per element.
  std::array<const Poly*, 2 + 3 * LeafFrames::kMax> vectors{};
  std::size_t nvec = 0;
  if (!valid) vectors[nvec++] = &jsq;
  vectors[nvec++] = &n;
  LeafFrames root_frames;
  for (std::size_t f = 0; f < frames; ++f) {
    if (done[f]) continue;
    root_frames.width[root_frames.count++] = hadamard[f] ? 3 : 1;
    vectors[nvec++] = &dk[f];
    if (hadamard[f]) {
      vectors[nvec++] = &had[2 * f];
      vectors[nvec++] = &had[2 * f + 1];
    }
  }
  root_frames.nvec = nvec;
  const std::size_t stride = nvec * s2;
  reserve_slots(ws.pool, stride);
  ws.pool.assign(stride, 0.0);
  ws.pool_err.assign(nvec, 0.0);
  for (std::size_t q = 0; q < nvec; ++q) {
    const Poly& p = *vectors[q];
    QV_ASSERT(p.c.size() == s2 && p.deg.size() == space.squared_degrees().size(), "squared space");
    for (std::size_t f = 0; f < p.deg.size(); ++f)
      QV_ASSERT(p.deg[f].degree == space.squared_degrees()[f].degree, "squared degree");
    std::copy(p.c.begin(), p.c.end(), ws.pool.begin() + static_cast<std::ptrdiff_t>(q * s2));
    ws.pool_err[q] = next_up(p.b.e * 1.01);  // 1% covers the rounding of these bounds
  }
  ws.free_slots.clear();
  ws.heap.clear();
  ws.states.assign(1, b2.root_state());
  thread_local std::vector<LeafFrames> leaf_frames;  // per slot
  leaf_frames.assign(1, root_frames);
  // valid lets every subdomain skip its own sign test (and leaves hold no J); invalid
  // means a point with J <= 0, where sj <= 0.
  Bounder bounder(space, s2, valid, !area);
  // Invalid: a point with J <= 0, where sj <= 0; and the first stage's certified bound.
  double upper = std::min(v == Validity::invalid ? 0.0 : space.s_hi(), quick.upper);

  const double tol = options.abs_tol;
  const auto cmp = [](const Leaf& a, const Leaf& b) { return a.lower != b.lower ? a.lower > b.lower : a.id > b.id; };
  double settled = done_lower;  // smallest lower bound of the leaves and frames dropped as good enough
  long next_id = 0;
  // Adds a leaf whose coefficients are at `slot`; frees the slot when it needs no split,
  // and closes the frames that need none (LeafFrames).
  const auto push = [&](int slot) {
    const auto us = static_cast<std::size_t>(slot);
    double* v = ws.pool.data() + us * stride;
    double* e = ws.pool_err.data() + us * nvec;
    LeafFrames& lf = leaf_frames[us];
    // Upper bounds at the subdomain's vertices only: adding its centre (one dot product per
    // vector) saved 2% of the subdivisions of warped_tetrahedron_o3 and none elsewhere.
    for (int i : b2.vertex_indices()) upper = std::min(upper, bounder.point_upper(v, e, lf, static_cast<std::size_t>(i)));
    std::array<double, LeafFrames::kMax> frame_lower{};
    const double lo = bounder.lower(v, e, lf, frame_lower.data());
    if (up(upper - lo) <= tol) {
      settled = std::min(settled, lo);  // stays good enough: upper only decreases
      ws.free_slots.push_back(slot);
      return;
    }
    // Close the frames within the tolerance (never the least one), moving the open
    // groups' vectors down over theirs.
    LeafFrames open;
    std::size_t from = bounder.first_group(), to = from;
    for (std::size_t t = 0; t < lf.count; from += lf.width[t], ++t) {
      if (up(upper - frame_lower[t]) <= tol) {
        settled = std::min(settled, frame_lower[t]);
        continue;
      }
      if (to != from) {
        std::copy_n(v + from * s2, lf.width[t] * s2, v + to * s2);
        std::copy_n(e + from, lf.width[t], e + to);
      }
      to += lf.width[t];
      open.width[open.count++] = lf.width[t];
    }
    open.nvec = to;
    lf = open;
    ws.heap.push_back({lo, slot, next_id++});
    std::push_heap(ws.heap.begin(), ws.heap.end(), cmp);
  };
  push(0);

  // Refinement by single bisections (BernsteinBisection::halve): `levels` of them make one
  // subdivision of the count reported and capped by max_subdivisions. Against all 2^dim
  // children per step, at --tol 1e-2 on one thread (medians of 5): warped_tetrahedron_o3
  // 0.83 -> 0.45 s, warped_prism 0.16 -> 0.08 s, warped_hexahedron 0.15 -> 0.10 s, mixed
  // 0.36 -> 0.28 s; the straight-sided and barely curved meshes within noise.
  QualityBounds out;
  const auto levels = static_cast<long>(b2.levels());
  long halvings = 0;
  constexpr std::size_t nc = 2;
  ws.child_states.resize(nc);
  ws.child_err.resize(nvec);
  auto& child_err = ws.child_err;
  const double floor = bounder.floor();
  while (!ws.heap.empty()) {
    const Leaf top = ws.heap.front();
    if (up(upper - std::min(top.lower, settled)) <= tol) break;
    if (halvings >= static_cast<long>(options.max_subdivisions) * levels) break;
    const std::size_t parent_off = static_cast<std::size_t>(top.slot) * stride;
    // A fold around a vanishing frame column: the lower bound is at the floor and can
    // never rise (stuck_at_floor), so more subdivisions could only lower `upper`, which
    // is bounded below by sj(E) itself; stop, with tolerance_met false (unless upper is
    // already within the tolerance of the floor).
    if (top.lower <= floor &&
        bounder.stuck_at_floor(ws.pool.data() + parent_off, ws.pool_err.data() + top.slot * static_cast<std::ptrdiff_t>(nvec),
                               leaf_frames[static_cast<std::size_t>(top.slot)], b2.vertex_indices()))
      break;
    std::pop_heap(ws.heap.begin(), ws.heap.end(), cmp);
    ws.heap.pop_back();
    ++halvings;
    // The children get slots of their own, so that they are written straight from the
    // parent's; the parent's slot is freed after.
    int child_slot[nc];
    for (int& slot : child_slot) {
      if (!ws.free_slots.empty()) {
        slot = ws.free_slots.back();
        ws.free_slots.pop_back();
      } else {
        slot = static_cast<int>(ws.pool_err.size() / nvec);
        ws.pool.resize(ws.pool.size() + stride);
        ws.pool_err.resize(ws.pool_err.size() + nvec);
        ws.states.resize(ws.states.size() + 1);
        leaf_frames.resize(leaf_frames.size() + 1);
      }
    }
    const LeafFrames parent_frames = leaf_frames[static_cast<std::size_t>(top.slot)];
    const std::size_t open = parent_frames.nvec;
    const double* parent = ws.pool.data() + parent_off;
    const double* parent_err = ws.pool_err.data() + top.slot * static_cast<std::ptrdiff_t>(nvec);
    for (std::size_t v = 0; v < open; ++v)
      child_err[v] = up((parent_err[v] + b2.halving_rounding_relative() * largest_magnitude(parent + v * s2, s2) +
                         b2.halving_rounding_absolute()) * (1 + 1e-12));
    // The open vectors of both children at once (bit-identical to one at a time).
    b2.halve(parent, open, ws.states[static_cast<std::size_t>(top.slot)],
             ws.pool.data() + static_cast<std::size_t>(child_slot[0]) * stride,
             ws.pool.data() + static_cast<std::size_t>(child_slot[1]) * stride, ws.child_states.data());
    ws.free_slots.push_back(top.slot);
    for (std::size_t q = 0; q < nc; ++q) {
      const int slot = child_slot[q];
      std::copy_n(child_err.begin(), open, ws.pool_err.begin() + slot * static_cast<std::ptrdiff_t>(nvec));
      ws.states[static_cast<std::size_t>(slot)] = ws.child_states[q];
      leaf_frames[static_cast<std::size_t>(slot)] = parent_frames;
      push(slot);
    }
  }
  out.subdivisions = static_cast<int>((halvings + levels - 1) / levels);
  double lower = settled;
  for (const Leaf& l : ws.heap) lower = std::min(lower, l.lower);
  out.lower = std::max(lower, quick.lower);
  out.upper = std::min(upper, quick.upper);
  out.subdivisions += quick.subdivisions;
  out.tolerance_met = up(out.upper - out.lower) <= tol;
  return out;
}

}  // namespace quadval
