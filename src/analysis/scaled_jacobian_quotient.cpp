// The quotient stage of the scaled-Jacobian bounds (see scaled_jacobian_quotient.hpp).
#include "analysis/scaled_jacobian_quotient.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>

#include "analysis/jacobian_samples.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/ratio_scan.hpp"
#include "analysis/slot_pool.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "bezier/bernstein_product.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kUnit = 0x1p-53;
constexpr double kSqrt3 = 1.7320508075688772;  // a hair below sqrt(3): the 1 + 1e-12 of its use covers it
double down(double x) { return next_down(x); }
double up(double x) { return next_up(x); }
constexpr double kReachable = 2;
// The paired bound's gap shrinks quadratically: a root within 4 tolerances is refined.
// sj of the valid elements, one thread, best of 5, within 2, 4, 10, 30 tolerances or any:
// warped_tetrahedron_o3 15.5 (at 4) against 17-22 ms (10 and above), mixed_h0.6_o2 7.4
// against 7.2-8.6, warped_pyramid_o2 about 35 ms at any.
constexpr double kPairedReachable = 4;

std::uint64_t key_of(const std::vector<FactorDegree>& deg) {
  std::uint64_t key = deg.size();
  for (const FactorDegree& f : deg) key = key * 4096 + static_cast<std::uint64_t>(f.dim * 1024 + f.degree);
  return key;
}

// Index of the coefficient at corner m (0..dim) of one simplex factor of degree n: the
// multi-index with n at m, in simplex_multi_indices order (0, n, then the last of the first
// layer, then the last); degree 0 has the one coefficient.
int factor_corner(int dim, int n, int m) {
  if (m == 0) return 0;
  if (m == 1) return n;
  const int triangle = (n + 1) * (n + 2) / 2;
  if (m == 2) return triangle - 1;
  return dim == 3 ? triangle * (n + 3) / 3 - 1 : 0;
}

// The coefficients that are values at the domain's corners (every tuple of factor corners),
// in one fixed corner order for any degrees, so that entry i of two spaces is the same
// point. Tensor layout i_0 + s_0 (i_1 + s_1 i_2), factor 0 fastest. A subdomain keeps its
// corners at these slots (bernstein_bisection.hpp), so they hold at every depth.
std::vector<int> corner_indices(const std::vector<FactorDegree>& deg) {
  std::vector<int> out{0};
  int stride = 1;
  for (const FactorDegree& f : deg) {
    std::vector<int> next;
    for (int m = 0; m <= f.dim; ++m)
      for (int i : out) next.push_back(i + stride * factor_corner(f.dim, f.degree, m));
    out.swap(next);
    stride *= static_cast<int>(simplex_multi_indices(f.dim, f.degree).size());
  }
  return out;
}

// Per degree vector, its corner indices and its bisection, built once per thread (a few
// spaces per type: a linear search; a deque keeps references valid as it grows).
struct SpaceTools {
  std::uint64_t key;
  std::vector<int> corners;
  std::unique_ptr<BernsteinBisection> bisection;
};
const SpaceTools& tools_of(const std::vector<FactorDegree>& deg) {
  thread_local std::deque<SpaceTools> cache;
  const std::uint64_t key = key_of(deg);
  for (const SpaceTools& t : cache)
    if (t.key == key) return t;
  return cache.emplace_back(SpaceTools{key, corner_indices(deg), std::make_unique<BernsteinBisection>(deg)});
}

// Distinct frame columns of a space at most (a tetrahedron's 6 edges; the bits of an
// unusable-column mask).
constexpr std::size_t kMaxDistinct = 12;

// One frame column: the columns it sums, with weights +-1.
struct FrameColumn {
  std::array<int, 3> column{};
  std::array<double, 3> weight{};
  int terms = 0;
};

struct Leaf {
  double lower;
  int slot;
  long id;  // creation order: a deterministic tie-break
};

// What a Quotient needs of its space, the same for every element of it: the leaf layout,
// the frames, and the frame columns that differ other than in sign (a hexahedron's 8
// corner frames use 3, a tetrahedron's 4 use its 6 edges), whose squared norms each leaf
// computes once.
struct QuotientLayout {
  const SpaceTools* j_tools = nullptr;
  std::array<const SpaceTools*, 3> col_tools{};
  std::array<std::size_t, 4> offset{};  // of J (0) and of column c (c + 1) in a leaf
  std::array<std::size_t, 3> size{};    // coefficients of column c, per coordinate
  std::size_t stride = 0;
  std::vector<FrameColumn> distinct;              // frame columns, first weight positive
  std::vector<std::array<std::size_t, 3>> frames;  // per frame: its columns in `distinct`
  // Per frame, for the paired bounds (3D and 2D, when the columns' product lies in J's
  // space): the tables of (v_1 v_2) and, in 3D, of (v_1 v_2) v_3, and the relative rounding
  // bound of that product (BernsteinProduct::rounding, triple_product_rounding); empty
  // otherwise.
  struct TripleProduct {
    const BernsteinProduct* first = nullptr;
    const BernsteinProduct* second = nullptr;
    double rounding = 0;
  };
  std::vector<TripleProduct> triple;
  // Whether every frame's product uses the same tables (tetrahedra, prisms, pyramids,
  // triangles): then four frames are multiplied per walk over the pairs (frame_products).
  bool shared_tables = false;
};

// What a layout depends on of an input: its degrees and sizes.
struct InputShape {
  const std::vector<FactorDegree>* j_degrees = nullptr;
  std::size_t j_size = 0;
  std::array<const std::vector<FactorDegree>*, 3> col_degrees{};
  std::array<std::size_t, 3> col_size{};
};
InputShape shape_of(const QuotientInput& in) {
  return {in.j_degrees, in.j.size(), in.col_degrees, {in.col[0][0].size(), in.col[1][0].size(), in.col[2][0].size()}};
}
InputShape shape_of(const QuotientLanes& in) {
  return {in.j_degrees, in.j.size(), {in.col_degrees[0], in.col_degrees[1], nullptr},
          {in.col[0][0].size(), in.col[1][0].size(), 0}};
}

QuotientLayout make_layout(const ScaledJacobianSpace& space, const InputShape& in) {
  QuotientLayout q;
  const auto dim = static_cast<std::size_t>(space.dim());
  QV_ASSERT(dim >= 1 && dim <= 3, "dimension " << dim);
  q.j_tools = &tools_of(*in.j_degrees);
  std::size_t at = in.j_size;
  for (std::size_t c = 0; c < dim; ++c) {
    q.col_tools[c] = &tools_of(*in.col_degrees[c]);
    q.offset[c + 1] = at;
    q.size[c] = in.col_size[c];
    at += 3 * q.size[c];
    QV_ASSERT(q.col_tools[c]->corners.size() == q.j_tools->corners.size(), "corner counts differ");
  }
  q.stride = at;
  for (const Frame& fr : space.frames()) {
    std::array<std::size_t, 3> slots{};
    for (std::size_t j = 0; j < dim; ++j) {
      FrameColumn f;
      for (std::size_t c = 0; c < dim; ++c)
        if (fr[j][c] != 0) {
          f.column[static_cast<std::size_t>(f.terms)] = static_cast<int>(c);
          f.weight[static_cast<std::size_t>(f.terms++)] = fr[j][c];
        }
      QV_ASSERT(f.terms > 0, "empty frame column");
      for (int t = 0; t < f.terms; ++t)
        QV_ASSERT(q.size[static_cast<std::size_t>(f.column[static_cast<std::size_t>(t)])] ==
                      q.size[static_cast<std::size_t>(f.column[0])],
                  "a frame sums columns of different spaces");
      // -v has the norm of v, and its computed coordinates are exactly those of v negated.
      if (f.weight[0] < 0)
        for (double& w : f.weight) w = -w;
      const auto same = [&](const FrameColumn& g) {
        return g.terms == f.terms && g.column == f.column && g.weight == f.weight;
      };
      const auto it = std::find_if(q.distinct.begin(), q.distinct.end(), same);
      slots[j] = static_cast<std::size_t>(it - q.distinct.begin());
      if (it == q.distinct.end()) q.distinct.push_back(f);
      QV_ASSERT(q.distinct.size() <= kMaxDistinct, q.distinct.size() << " frame columns");
    }
    q.frames.push_back(slots);
  }
  // The tables of the products of a frame's columns (two in 2D, three in 3D), where the
  // columns' degrees add up to J's.
  if (dim >= 2) {
    const std::vector<FactorDegree>& j = *in.j_degrees;
    std::vector<FactorDegree> sum(j.size());
    bool same = true;
    for (std::size_t f = 0; f < j.size() && same; ++f) {
      sum[f] = {j[f].dim, 0};
      for (std::size_t c = 0; c < dim; ++c) {
        const std::vector<FactorDegree>& d = *in.col_degrees[c];
        same = same && d.size() == j.size() && d[f].dim == j[f].dim;
        if (same) sum[f].degree += d[f].degree;
      }
      same = same && sum[f].degree == j[f].degree;
    }
    if (same)
      for (const auto& fr : q.frames) {
        const auto& d0 = *in.col_degrees[static_cast<std::size_t>(q.distinct[fr[0]].column[0])];
        const auto& d1 = *in.col_degrees[static_cast<std::size_t>(q.distinct[fr[1]].column[0])];
        QuotientLayout::TripleProduct t;
        t.first = &bernstein_product(d0, d1);
        t.rounding = t.first->rounding(1);
        if (dim == 3) {
          const auto& d2 = *in.col_degrees[static_cast<std::size_t>(q.distinct[fr[2]].column[0])];
          t.second = &bernstein_product(product_degrees(d0, d1), d2);
          t.rounding = triple_product_rounding(*t.first, *t.second);
        }
        q.triple.push_back(t);
      }
  }
  q.shared_tables = q.triple.size() > 1 && std::all_of(q.triple.begin(), q.triple.end(), [&](const auto& t) {
                      return t.first == q.triple[0].first && t.second == q.triple[0].second;
                    });
  return q;
}

// The layout of a space, built once per thread.
const QuotientLayout& layout_of(const ScaledJacobianSpace& space, const InputShape& in) {
  thread_local std::vector<std::pair<const ScaledJacobianSpace*, std::unique_ptr<QuotientLayout>>> cache;
  for (const auto& [key, layout] : cache)
    if (key == &space) return *layout;
  cache.emplace_back(&space, std::make_unique<QuotientLayout>(make_layout(space, in)));
  return *cache.back().second;
}

// The steps of directional_columns and paired_bound on one frame column's or one frame's
// scalars, shared by Quotient (T = double) and PairedRoots (T = Lanes<4>, one element per
// lane): the same operations lane by lane (the lanes' one-ulp steps and square roots are
// next_up, next_down and sqrt's bits, symmetric3_lanes.hpp), so the same bits. Their error
// analysis is at directional_columns and paired_bound.
using Lanes4 = Lanes<4>;
using Mask4 = lanes3::Mask<4>;
Lanes4 up(Lanes4 x) { return lanes3::up<4>(x); }
Lanes4 down(Lanes4 x) { return lanes3::down<4>(x); }
double root(double x) { return sqrt_rn(x); }
Lanes4 root(Lanes4 x) { return lanes3::root<4>(x); }
// c ? a : b, lane by lane for Lanes4.
template <class C, class T>
T where(C c, T a, T b) {
  return c ? a : b;
}
template <class T>
T constant(double v) {
  return T{} + v;
}

// Bound on |computed - exact| of each coordinate of frame column f: its columns' errors
// (err[c + 1]) and the rounding of the sum (gamma_6 of the columns' magnitudes).
template <class T>
T frame_column_error(const FrameColumn& f, const std::array<T, 4>& err, const std::array<T, 3>& col_magnitude) {
  constexpr double gamma = rounding_gamma(6);
  T e{};
  for (int t = 0; t < f.terms; ++t) {
    const auto c = static_cast<std::size_t>(f.column[static_cast<std::size_t>(t)]);
    e += err[c + 1] + gamma * col_magnitude[c];
  }
  return e;
}
// Bound on how far a control point's norm moves with its coordinates' errors e.
template <class T>
T norm_spread(T e) {
  return up(kSqrt3 * (1 + 1e-12) * up(e * (1 + 1e-12)));
}
// A corner's norm from the sum of its squared coordinates: below (the paired bound's
// corners, J > 0 there) and above (the signed bound's, J < 0).
template <class T>
T corner_norm_below(T sum, T spread) {
  return vmax(constant<T>(0), down(down(root(sum) * (1 - 1e-12)) - spread));
}
double corner_norm_above(double sum, double spread) { return up(up(sqrt_rn(sum) * (1 + 1e-12)) + spread); }
// At least every computed |V_i|, from the largest |V_i|^2.
template <class T>
T largest_norm(T big_square) {
  return up(root(big_square) * (1 + 1e-12));
}
// Bound on the errors of the dot products V_i . d, the V_i's coordinates within ev and
// their magnitudes at most mag.
template <class T>
T along_error(T ev, T mag) {
  return up(up(kSqrt3 * up(ev + 4 * kUnit * mag)) * (1 + 1e-12));
}
// The shift Q = R / (2 m) of paired_bound's |v| <= a + Q, from the largest |p_i|^2 and
// |V_i| (vn) and the least a_i; -1 where m is not proven positive or R is not finite.
template <class T>
T paired_shift(T ev, T vn, T perp_square, T a_min, T along_err) {
  // R from the largest |p_i| and |V_i| (r grows with both).
  const T ev3 = up(kSqrt3 * ev);
  const T pn = up(up(up(root(perp_square) * (1 + 1e-12)) + up(16 * kUnit * vn)) + ev3);
  const T ve = up(vn + ev3);
  const T r_max = up(up(pn * pn) + up(4e-15 * up(ve * ve)));
  const T m = down(a_min - along_err);
  return where((m > 0) & (r_max < kInf), up(r_max / down(2 * m)), constant<T>(-1));
}
// The shifted coefficients' error: a's, plus one rounding of the sum.
template <class T>
T shifted_along_error(T along_err, T shifted_big) {
  return up(along_err + up(2 * kUnit * shifted_big));
}
// Bound on the errors of a frame's product's coefficients from its factors' magnitudes m
// and errors e (a third factor 1, error 0, in 2D) and the products' relative rounding.
template <class T>
T product_error(const std::array<T, 3>& m, const std::array<T, 3>& e, double rounding) {
  const T mm = m[0] * m[1] * m[2];
  const T propagated = e[0] * (m[1] + e[1]) * (m[2] + e[2]) + m[0] * e[1] * (m[2] + e[2]) + m[0] * m[1] * e[2];
  return up((propagated + rounding * mm) * (1 + 1e-10));
}
// quotient_below (ratio_scan.hpp) lane by lane.
using quadval::quotient_below;
Lanes4 quotient_below(Lanes4 q) {
  constexpr double u = 0x1p-53;
  return down(down(q * where(q < 0, constant<Lanes4>(1 + 4 * u), constant<Lanes4>(1 - 4 * u))) -
              std::numeric_limits<double>::denorm_min());
}
// paired_bound's bound of one frame: J's least coefficient over the largest norms' product,
// raised, where `scanned`, by the least quotient `least` of a scan of J_i - e over U_i +
// e_U (least_den its least denominator) where that certifies one: a positive least
// quotient means every numerator is positive (rounding keeps signs).
template <class T, class M>
T paired_frame_lower(T j_lo, T norm_product, double s_lo, M scanned, T least, T least_den) {
  const T frame_lower = where(j_lo > 0, down(s_lo * down(j_lo / norm_product)), constant<T>(0));
  return where(scanned & (least_den > 0) & (least > 0) & (least < kInf),
               vmax(frame_lower, down(s_lo * quotient_below(least))), frame_lower);
}
// `upper` lowered to s J / prod |v_kj| at a corner of the leaf, with J at most j + e and
// the norms' product at least norm_product (paired_bound).
template <class T>
T paired_corner_upper(T j, T e, T norm_product, double s_hi, T upper) {
  const T j_hi = up(j + e);
  return where((j_hi > 0) & (norm_product > 0), vmin(upper, up(s_hi * up(j_hi / norm_product))), upper);
}

// Working arrays of Quotient, kept per thread from element to element (as members they
// were allocated and freed for every element).
struct QuotientScratch {
  std::vector<double> sumsq, part, scratch, big, spread, products, along_err, corner_norm, corner_norm_lo, norm_big;
  std::vector<double> lane_a, lane_b, lane_c, lane_ab, lane_h;  // frame_products' interleaved factors
  std::vector<std::vector<double>> along_of;  // signed bound: per distinct frame column
  std::vector<std::size_t> first, col0;
  std::vector<BisectionState> column_states;
};

// The leaves' data: per leaf J then the columns' coordinates, contiguous; per leaf the
// error bounds of J and of each column, and its bisection state.
class Quotient {
 public:
  Quotient(const ScaledJacobianSpace& space, const QuotientInput& in, QuotientScratch& ws)
      : space_(space), in_(in), layout_(layout_of(space, shape_of(in))), ws_(ws) {
    dim_ = static_cast<std::size_t>(space.dim());
    QV_ASSERT(layout_.offset[1] == in.j.size() && layout_.size[0] == in.col[0][0].size(),
              "the layout of another input");
  }

  std::size_t stride() const { return layout_.stride; }

  // The root leaf, into `leaf` (stride() doubles) and its errors.
  void root(double* leaf, std::array<double, 4>& err) const {
    std::copy(in_.j.begin(), in_.j.end(), leaf);
    err[0] = in_.j_error;
    for (std::size_t c = 0; c < dim_; ++c) {
      for (std::size_t x = 0; x < 3; ++x)
        std::copy(in_.col[c][x].begin(), in_.col[c][x].end(), leaf + layout_.offset[c + 1] + x * layout_.size[c]);
      err[c + 1] = in_.col_error[c];
    }
  }

  // Coordinate x of frame column f at control point i of the leaf (its columns of n
  // coefficients per coordinate).
  double frame_coordinate(const double* leaf, const FrameColumn& f, std::size_t n, std::size_t x,
                          std::size_t i) const {
    double v = 0;
    for (int t = 0; t < f.terms; ++t) {
      const auto c = static_cast<std::size_t>(f.column[static_cast<std::size_t>(t)]);
      v += f.weight[static_cast<std::size_t>(t)] * leaf[layout_.offset[c + 1] + x * n + i];
    }
    return v;
  }
  // Bound on |computed - exact| of each coordinate of frame column f: its columns' errors
  // and the rounding of the sum.
  double frame_error(const FrameColumn& f, const std::array<double, 4>& err) const {
    return frame_column_error(f, err, in_.col_magnitude);
  }

  // A certified lower bound of sj on the leaf, each frame's into frame_lower[k]; `upper`
  // is lowered to sj at one of its corners (the one the squares estimate smallest, per
  // frame), certified there.
  double bound(const double* leaf, const std::array<double, 4>& err, double& upper, FrameBounds& frame_lower) const {
    const std::size_t sj = in_.j.size();
    const double j_lo = down(*std::min_element(leaf, leaf + sj) - err[0]);
    const std::vector<int>& j_corners = layout_.j_tools->corners;
    const std::size_t corners = j_corners.size();
    // Each distinct frame column: the squared norms of its control points, their largest,
    // and the spread of its norms from the columns' errors.
    const std::size_t nd = layout_.distinct.size();
    ws_.sumsq.clear();
    ws_.first.resize(nd);
    ws_.col0.resize(nd);
    ws_.big.resize(nd);
    ws_.spread.resize(nd);
    for (std::size_t d = 0; d < nd; ++d) {
      const FrameColumn& f = layout_.distinct[d];
      ws_.spread[d] = norm_spread(frame_error(f, err));
      ws_.col0[d] = static_cast<std::size_t>(f.column[0]);
      const std::size_t n = layout_.size[ws_.col0[d]];
      ws_.first[d] = ws_.sumsq.size();
      double big = 0;
      for (std::size_t i = 0; i < n; ++i) {
        double sum = 0;
        for (std::size_t x = 0; x < 3; ++x) {
          const double v = frame_coordinate(leaf, f, n, x, i);
          sum += v * v;
        }
        ws_.sumsq.push_back(sum);
        big = std::max(big, sum);
      }
      ws_.big[d] = big;
    }
    double lower = kInf;
    for (std::size_t k = 0; k < layout_.frames.size(); ++k) {
      const auto& fr = layout_.frames[k];
      double norm_product = 1;
      for (std::size_t j = 0; j < dim_; ++j)
        norm_product = up(norm_product * up(up(sqrt_rn(ws_.big[fr[j]]) * (1 + 1e-12)) + ws_.spread[fr[j]]));
      // J > 0 on the element: sj > 0 everywhere, the bound where J_lo is not positive.
      frame_lower[k] = j_lo > 0 ? down(space_.s_lo() * down(j_lo / norm_product)) : 0.0;
      lower = std::min(lower, frame_lower[k]);
      // The corner of least sj estimated from the squares (any corner gives a true upper
      // bound; the estimate only picks a sharp one), then certified there.
      const auto square_at = [&](std::size_t j, std::size_t m) {
        const std::size_t d = fr[j];
        return ws_.sumsq[ws_.first[d] + static_cast<std::size_t>(layout_.col_tools[ws_.col0[d]]->corners[m])];
      };
      std::size_t best = corners;
      double best_square = kInf;
      for (std::size_t m = 0; m < corners; ++m) {
        double denominator = 1;
        for (std::size_t j = 0; j < dim_; ++j) denominator *= square_at(j, m);
        const double jm = leaf[j_corners[m]];
        if (denominator > 0 && jm > 0 && jm * jm / denominator < best_square) {
          best_square = jm * jm / denominator;
          best = m;
        }
      }
      if (best == corners) continue;
      double denominator = 1;
      for (std::size_t j = 0; j < dim_; ++j) {
        const double norm_lo = down(down(sqrt_rn(square_at(j, best)) * (1 - 1e-12)) - ws_.spread[fr[j]]);
        denominator = norm_lo > 0 ? down(denominator * norm_lo) : 0;
      }
      if (!(denominator > 0)) continue;  // a column may vanish there: no value from this corner
      const double j_hi = up(leaf[j_corners[best]] + err[0]);
      upper = std::min(upper, up(space_.s_hi() * up(j_hi / denominator)));
    }
    return lower;
  }

  // On an element not proven valid (3D, planar 2D): a certified lower bound of sj on the leaf from J's
  // coefficients, their signs included; `upper` is lowered to sj at the leaf's corners where
  // J < 0 there. Per frame k, L_k = prod_j (v_kj . d_kj), d_kj a unit vector along the mean
  // of v_kj's control points: |v . d| <= |v|, so where L_k's coefficients are positive (their
  // errors included), 0 < L_k <= prod_j |v_kj| on the leaf, and where J < 0,
  //   sj_k = s J / prod_j |v_kj| >= s J / L_k >= s min_i J_i / L_k,i
  // (a ratio of Bernstein polynomials with positive denominator coefficients lies between
  // its coefficients' ratios); where J >= 0, sj_k >= 0. So sj >= s min(0, min_k min_i J_i /
  // L_k,i), and sj >= -s everywhere (Hadamard). Unlike J_lo over the norms' bounds, which
  // come from different points, each ratio pairs J and L_k at the same coefficient, and L_k
  // misses prod |v_kj| only by the cosines of the columns' spread on the leaf: the gap
  // shrinks quadratically with the leaf, in the degree of J rather than 2n.
  double signed_bound(const double* leaf, const std::array<double, 4>& err, double& upper,
                      FrameBounds& frame_lower_out) const {
    const std::size_t sj = in_.j.size();
    const std::vector<int>& j_corners = layout_.j_tools->corners;
    const double s_hi = space_.s_hi(), s_lo = space_.s_lo();
    const std::size_t corners = j_corners.size();
    // J >= 0 on the whole leaf (every coefficient, its error included): sj >= 0 there, and
    // no corner has J < 0 to bound sj from above; the columns are not needed.
    if (down(*std::min_element(leaf, leaf + sj) - err[0]) >= 0) {
      frame_lower_out.fill(0.0);
      return 0.0;
    }
    const std::uint32_t unusable = directional_columns(leaf, err, false);
    frame_products(unusable);
    double lower = kInf;
    for (std::size_t k = 0; k < layout_.frames.size(); ++k) {
      const auto& fr = layout_.frames[k];
      double frame_lower = -s_hi;  // Hadamard
      if (usable(k, unusable)) {
        // min(0, min_i (J_i - e) / (L_i - e_L)) without directed roundings (ratio_scan.hpp):
        // each quotient within three roundings of the exact one; rounding keeps signs.
        const double el = frame_product_error(k);
        const RatioScan scan = scan_ratios<true>(leaf, -err[0], ws_.products.data() + k * sj, -el, -el, sj);
        if (scan.least_den > 0) {
          const double least = std::min(scan.extreme, 0.0);
          const double bound = least < 0 ? quotient_below(least) : 0.0;
          frame_lower = std::max(frame_lower, down(s_hi * bound));
        }
      }
      frame_lower_out[k] = frame_lower;
      lower = std::min(lower, frame_lower);
      // Upper bounds at the leaf's corners where J < 0 is certain: s J / prod |v_kj| with
      // J at most J + e (negative) and the norms at most their computed values plus spread.
      for (std::size_t mi = 0; mi < corners; ++mi) {
        const double j_hi = up(leaf[j_corners[mi]] + err[0]);
        if (!(j_hi < 0)) continue;
        double norm_product = 1;
        for (std::size_t j = 0; j < dim_; ++j) norm_product = up(norm_product * ws_.corner_norm[fr[j] * corners + mi]);
        upper = std::min(upper, up(s_lo * up(j_hi / norm_product)));
      }
    }
    return lower;
  }

  // On an element where J > 0 is proven (3D, planar 2D): the same pairing with an upper bound of the
  // norms. With a = v . d (d as above) and r = |v|^2 - a^2 = v^T (I - d d^T) v, a convex
  // function of v as |d| <= 1: on the leaf a >= m = min_i a_i and r <= R = max_i r(V_i)
  // (V_i the control points; v is their convex combination), so where m > 0,
  //   |v|^2 = a^2 + r <= a^2 + 2 a Q <= (a + Q)^2,  Q = R / (2 m),
  // and |v| <= a + Q, a polynomial of the column's degree (Q adds to every coefficient).
  // With U_k = prod_j (a_kj + Q_kj), in J's space like L_k,
  //   sj_k = s J / prod_j |v_kj| >= s J / U_k >= s min_i J_i / U_k,i.
  // Q is of the order of the columns' spread squared, so the gap shrinks quadratically with
  // the leaf, as the signed bound's, where J_lo over the largest norms (bound, also taken
  // here) shrinks linearly. `upper` is lowered to sj at the leaf's corners.
  // Errors: R covers the computed V_i's errors and the roundings of the projection
  // (directional_columns); the shifted coefficients a_i + Q carry a's error plus one
  // rounding of the sum; U_k's as L_k's.
  double paired_bound(const double* leaf, const std::array<double, 4>& err, double& upper,
                      FrameBounds& frame_lower_out) const {
    const std::size_t sj = in_.j.size();
    const std::vector<int>& j_corners = layout_.j_tools->corners;
    const double s_hi = space_.s_hi(), s_lo = space_.s_lo();
    const std::size_t corners = j_corners.size();
    const std::uint32_t unusable = directional_columns(leaf, err, true);
    frame_products(unusable);
    const double j_lo = down(*std::min_element(leaf, leaf + sj) - err[0]);
    double lower = kInf;
    for (std::size_t k = 0; k < layout_.frames.size(); ++k) {
      const auto& fr = layout_.frames[k];
      double norm_product = 1;
      for (std::size_t j = 0; j < dim_; ++j) norm_product = up(norm_product * ws_.norm_big[fr[j]]);
      // min_i (J_i - e) / (U_i + e_U) without directed roundings (ratio_scan.hpp): each
      // quotient within three roundings of the exact one.
      RatioScan scan{};
      if (usable(k, unusable)) {
        const double el = frame_product_error(k);
        scan = scan_ratios<true>(leaf, -err[0], ws_.products.data() + k * sj, el, el, sj);
      }
      const double frame_lower = paired_frame_lower(j_lo, norm_product, s_lo, usable(k, unusable), scan.extreme, scan.least_den);
      frame_lower_out[k] = frame_lower;
      lower = std::min(lower, frame_lower);
      // Upper bounds at the leaf's corners: s J / prod |v_kj| with J at most J + e and the
      // norms at least their computed values minus spread.
      for (std::size_t mi = 0; mi < corners; ++mi) {
        double norm_product = 1;
        for (std::size_t j = 0; j < dim_; ++j) norm_product = down(norm_product * ws_.corner_norm_lo[fr[j] * corners + mi]);
        upper = paired_corner_upper(leaf[j_corners[mi]], err[0], norm_product, s_hi, upper);
      }
    }
    return lower;
  }

  // Frame column f's first nx coordinates (the others are zero) at the leaf's n control
  // points, into part[x * n + i]; their sums per coordinate into mean, and mag raised to
  // their largest magnitude. The same operations as frame_coordinate, a coordinate at a
  // time, so that the compiler vectorises the sums of columns.
  void frame_column(const double* leaf, const FrameColumn& f, std::size_t n, std::size_t nx, double* part,
                    std::array<double, 3>& mean, double& mag) const {
    const auto source = [&](int t, std::size_t x) {
      return leaf + layout_.offset[static_cast<std::size_t>(f.column[static_cast<std::size_t>(t)]) + 1] + x * n;
    };
    const double w0 = f.weight[0], w1 = f.weight[1], w2 = f.weight[2];
    for (std::size_t x = 0; x < nx; ++x) {
      double* out = part + x * n;
      const double* s0 = source(0, x);
      if (f.terms == 1) {
        for (std::size_t i = 0; i < n; ++i) out[i] = 0.0 + w0 * s0[i];
      } else if (f.terms == 2) {
        const double* s1 = source(1, x);
        for (std::size_t i = 0; i < n; ++i) out[i] = (0.0 + w0 * s0[i]) + w1 * s1[i];
      } else {
        const double *s1 = source(1, x), *s2 = source(2, x);
        for (std::size_t i = 0; i < n; ++i) out[i] = ((0.0 + w0 * s0[i]) + w1 * s1[i]) + w2 * s2[i];
      }
      for (std::size_t i = 0; i < n; ++i) {
        mean[x] += out[i];
        mag = std::max(mag, std::abs(out[i]));
      }
    }
  }
  // directional_columns' pass over ws_.part (NX coordinates) with the unit vector d: the
  // dot products a_i into along, their largest magnitude, the largest |V_i|^2 and, when
  // shifted, the least a_i and the largest squared distance of V_i from the line along d.
  template <std::size_t NX>
  void project_along(std::size_t n, const std::array<double, 3>& d, bool shifted, double* along, double& big,
                  double& big_square, double& perp_square, double& a_min) const {
    const double* v = ws_.part.data();
    for (std::size_t i = 0; i < n; ++i) {
      double a = v[i] * d[0];
      double v2 = v[i] * v[i];
      for (std::size_t x = 1; x < NX; ++x) {
        a += v[x * n + i] * d[x];
        v2 += v[x * n + i] * v[x * n + i];
      }
      along[i] = a;
      big = std::max(big, std::abs(a));
      big_square = std::max(big_square, v2);
      if (!shifted) continue;
      a_min = std::min(a_min, a);
      double p2 = 0;
      for (std::size_t x = 0; x < NX; ++x) {
        const double p = v[x * n + i] - a * d[x];
        p2 = x == 0 ? p * p : p2 + p * p;
      }
      perp_square = std::max(perp_square, p2);
    }
  }

  // Per distinct frame column dc of the leaf: ws_.along_of[dc] = its control points' dot
  // products with the unit vector d along their mean, ws_.big[dc] >= their magnitudes,
  // ws_.along_err[dc] >= their errors, and bounds of |v| at the leaf's corners (above:
  // corner_norm, for signed_bound; below: corner_norm_lo, with `shifted`) and on the whole
  // leaf (norm_big). With `shifted` (paired_bound), along_of holds a_i + Q instead, its
  // error and magnitude with it.
  // Errors: a frame column's coordinates are within e (frame_error), so v . d (|d| <= 1) is
  // within sqrt(3) e plus the dot product's rounding (gamma_3 sum |v_x d_x| <= 4u sqrt(3)
  // max|v_x|). For R: the projection p = V - (V . d) d is computed within 16u |V| (the dot
  // product, its product with d and the difference: about 11u |V| in all), I - d d^T moves
  // V's error sqrt(3) e by no more (its norm is at most 1), and r(V) = |p|^2 + (V . d)^2 (1 -
  // |d|^2) with 1 - |d|^2 <= 4e-15 for the d below.
  // @return bit dc set where column dc is unusable (its mean vanishes; shifted: also a's
  // coefficients not proven positive)
  std::uint32_t directional_columns(const double* leaf, const std::array<double, 4>& err, bool shifted) const {
    const std::vector<int>& j_corners = layout_.j_tools->corners;
    const std::size_t nd = layout_.distinct.size();
    const std::size_t corners = j_corners.size();
    ws_.big.resize(nd);
    ws_.norm_big.resize(nd);
    ws_.along_err.resize(nd);
    ws_.corner_norm.resize(nd * corners);
    ws_.corner_norm_lo.resize(nd * corners);
    if (ws_.along_of.size() < nd) ws_.along_of.resize(nd);
    std::uint32_t unusable = 0;
    const std::size_t nx = in_.coordinates;
    for (std::size_t dc = 0; dc < nd; ++dc) {
      const FrameColumn& f = layout_.distinct[dc];
      const auto c0 = static_cast<std::size_t>(f.column[0]);
      const std::size_t n = layout_.size[c0];
      const double ev = frame_error(f, err);
      double mag = 0;
      ws_.part.resize(3 * n);
      std::array<double, 3> mean{0, 0, 0};
      frame_column(leaf, f, n, nx, ws_.part.data(), mean, mag);
      const double spread = norm_spread(ev);
      // Corner norms: from above for the signed bound's corners (J < 0 there), from below
      // for the paired bound's (J > 0).
      for (std::size_t mi = 0; mi < corners; ++mi) {
        const auto at = static_cast<std::size_t>(layout_.col_tools[c0]->corners[mi]);
        double sum = 0;
        for (std::size_t x = 0; x < nx; ++x) sum += ws_.part[x * n + at] * ws_.part[x * n + at];
        if (shifted)
          ws_.corner_norm_lo[dc * corners + mi] = corner_norm_below(sum, spread);
        else
          ws_.corner_norm[dc * corners + mi] = corner_norm_above(sum, spread);
      }
      const double len = sqrt_rn(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
      if (!(len > 0) || !(len < kInf)) {
        unusable |= 1u << dc;
        ws_.norm_big[dc] = kInf;
        continue;
      }
      std::array<double, 3> d{};
      for (std::size_t x = 0; x < 3; ++x) d[x] = mean[x] / len * (1 - 1e-15);  // |d| <= 1
      std::vector<double>& along = ws_.along_of[dc];
      along.resize(n);
      double big = 0, big_square = 0, perp_square = 0, a_min = kInf;
      if (nx == 2)
        project_along<2>(n, d, shifted, along.data(), big, big_square, perp_square, a_min);
      else
        project_along<3>(n, d, shifted, along.data(), big, big_square, perp_square, a_min);
      const double vn = largest_norm(big_square);
      ws_.big[dc] = big;
      ws_.norm_big[dc] = up(vn + spread);
      ws_.along_err[dc] = along_error(ev, mag);
      if (!shifted) continue;
      const double q = paired_shift(ev, vn, perp_square, a_min, ws_.along_err[dc]);
      if (q < 0) {
        unusable |= 1u << dc;
        continue;
      }
      double shifted_big = 0;
      for (double& a : along) {
        a += q;
        shifted_big = std::max(shifted_big, std::abs(a));
      }
      ws_.big[dc] = shifted_big;
      ws_.along_err[dc] = shifted_along_error(ws_.along_err[dc], shifted_big);
    }
    return unusable;
  }

  // ws_.products[k * J's size ...]: the product of frame k's along_of vectors (dim of
  // them), in J's space, for every usable frame k (the others' are left as they were).
  void frame_products(std::uint32_t unusable) const {
    const std::size_t nf = layout_.frames.size(), sj = in_.j.size();
    ws_.products.resize(nf * sj);
    std::size_t k = 0;
    if (layout_.shared_tables)
      for (; k < nf && four_frame_products(k, unusable); k += 4) {
      }
    for (; k < nf; ++k)
      if (usable(k, unusable)) frame_product(k, ws_.products.data() + k * sj);
  }

  // Frames k0 .. k0 + 3 (those there are) in the four lanes of one walk over the shared
  // tables' pairs: each lane does exactly what frame_product does (BernsteinProduct::
  // multiply4; the bounds are the same bits), and unused lanes multiply zeros. One frame
  // at a time, the products took 26-40% of the scaled Jacobian's time on the warped
  // meshes; four at a time, sj on one thread (BM_CheckSharedQuality, medians of 5):
  // warped_tetrahedron_o3 101.6 -> 82.0 ms, warped_prism_o2 10.5 -> 8.5 ms.
  // false when the first product has no entry kernel (nothing is computed then).
  bool four_frame_products(std::size_t k0, std::uint32_t unusable) const {
    const QuotientLayout::TripleProduct& tp = layout_.triple[0];
    const std::size_t nf = std::min<std::size_t>(4, layout_.frames.size() - k0), sj = in_.j.size();
    const auto fill = [&](std::vector<double>& lanes, std::size_t j, std::size_t n) {
      lanes.assign(4 * n, 0.0);
      for (std::size_t l = 0; l < nf; ++l) {
        if (!usable(k0 + l, unusable)) continue;
        const std::vector<double>& v = ws_.along_of[layout_.frames[k0 + l][j]];
        for (std::size_t i = 0; i < n; ++i) lanes[4 * i + l] = v[i];
      }
    };
    fill(ws_.lane_a, 0, static_cast<std::size_t>(tp.first->f_size()));
    fill(ws_.lane_b, 1, static_cast<std::size_t>(tp.first->g_size()));
    std::vector<double>& out = dim_ == 2 ? ws_.lane_h : ws_.lane_ab;
    out.resize(4 * static_cast<std::size_t>(tp.first->h_size()));
    if (!tp.first->multiply4(ws_.lane_a.data(), ws_.lane_b.data(), out.data())) return false;
    if (dim_ == 3) {
      fill(ws_.lane_c, 2, static_cast<std::size_t>(tp.second->g_size()));
      ws_.lane_h.resize(4 * sj);
      if (!tp.second->multiply4(ws_.lane_ab.data(), ws_.lane_c.data(), ws_.lane_h.data())) {
        // A large second product (pyramids of order 2 and up): one frame at a time, from
        // the lanes' first products (the bits frame_product has). Recomputing those too
        // took 13% of warped_pyramid_o2's sj: 41 -> 33 ms (one thread, per element, 3 runs).
        const auto nh = static_cast<std::size_t>(tp.first->h_size());
        ws_.scratch.resize(nh);
        for (std::size_t l = 0; l < nf; ++l) {
          if (!usable(k0 + l, unusable)) continue;
          for (std::size_t i = 0; i < nh; ++i) ws_.scratch[i] = ws_.lane_ab[4 * i + l];
          tp.second->multiply(ws_.scratch.data(), ws_.along_of[layout_.frames[k0 + l][2]].data(),
                              ws_.products.data() + (k0 + l) * sj);
        }
        return true;
      }
    }
    for (std::size_t l = 0; l < nf; ++l) {
      if (!usable(k0 + l, unusable)) continue;
      double* h = ws_.products.data() + (k0 + l) * sj;
      for (std::size_t i = 0; i < sj; ++i) h[i] = ws_.lane_h[4 * i + l];
    }
    return true;
  }

  // h = the product of frame k's along_of vectors (dim of them), in J's space.
  void frame_product(std::size_t k, double* h) const {
    const auto& fr = layout_.frames[k];
    const QuotientLayout::TripleProduct& tp = layout_.triple[k];
    if (dim_ == 2) {
      tp.first->multiply(ws_.along_of[fr[0]].data(), ws_.along_of[fr[1]].data(), h);
    } else {
      ws_.scratch.resize(static_cast<std::size_t>(tp.first->h_size()));
      tp.first->multiply(ws_.along_of[fr[0]].data(), ws_.along_of[fr[1]].data(), ws_.scratch.data());
      tp.second->multiply(ws_.scratch.data(), ws_.along_of[fr[2]].data(), h);
    }
  }

  // Bound on the errors of frame k's product's coefficients: the factors' propagated
  // errors plus the products' rounding (BernsteinProduct::rounding,
  // triple_product_rounding in 3D).
  double frame_product_error(std::size_t k) const {
    const auto& fr = layout_.frames[k];
    const std::array<double, 3> m{ws_.big[fr[0]], ws_.big[fr[1]], dim_ == 3 ? ws_.big[fr[2]] : 1.0};
    const std::array<double, 3> e{ws_.along_err[fr[0]], ws_.along_err[fr[1]], dim_ == 3 ? ws_.along_err[fr[2]] : 0.0};
    // 2D: m_2 = 1 and e_2 = 0 make these the bounds of the two-factor product.
    return product_error(m, e, layout_.triple[k].rounding);
  }

  // Whether frame k's columns are all usable (directional_columns' bits).
  bool usable(std::size_t k, std::uint32_t unusable) const {
    for (std::size_t j = 0; j < dim_; ++j)
      if (unusable & (1u << layout_.frames[k][j])) return false;
    return true;
  }

  // Splits the leaf into the 2^dim children (child-major, stride() each) with their states
  // and errors (the same for all children).
  void split(const double* leaf, const std::array<double, 4>& err, const BisectionState& state,
             std::vector<double>& children, std::vector<BisectionState>& states,
             std::array<double, 4>& child_err) const {
    const BernsteinBisection& jb = *layout_.j_tools->bisection;
    const auto nc = static_cast<std::size_t>(jb.num_children());
    children.resize(nc * layout_.stride);
    states.resize(nc);
    const auto child_error = [](const BernsteinBisection& b, double e, const double* v, std::size_t n) {
      return up((e + b.rounding_relative() * largest_magnitude(v, n) + b.rounding_absolute()) * (1 + 1e-12));
    };
    const std::size_t sj = in_.j.size();
    ws_.part.resize(nc * layout_.stride);  // any one part's children: layout_.stride >= J's and 3 x a column's size
    jb.split(leaf, 1, state, ws_.part.data(), states.data(), ws_.scratch);
    for (std::size_t q = 0; q < nc; ++q) std::copy_n(ws_.part.data() + q * sj, sj, children.data() + q * layout_.stride);
    child_err[0] = child_error(jb, err[0], leaf, sj);
    for (std::size_t c = 0; c < dim_; ++c) {
      const BernsteinBisection& cb = *layout_.col_tools[c]->bisection;
      const std::size_t block = 3 * layout_.size[c];
      const double* parent = leaf + layout_.offset[c + 1];
      ws_.column_states.resize(nc);
      cb.split(parent, 3, state, ws_.part.data(), ws_.column_states.data(), ws_.scratch);
      for (std::size_t q = 0; q < nc; ++q)
        std::copy_n(ws_.part.data() + q * block, block, children.data() + q * layout_.stride + layout_.offset[c + 1]);
      child_err[c + 1] = child_error(cb, err[c + 1], parent, block);
    }
  }

  // One bisection of the leaf (BernsteinBisection::halve): the 2 children (stride() each,
  // child-major), their states and errors.
  void halve(const double* leaf, const std::array<double, 4>& err, const BisectionState& state,
             std::vector<double>& children, std::vector<BisectionState>& states,
             std::array<double, 4>& child_err) const {
    const BernsteinBisection& jb = *layout_.j_tools->bisection;
    children.resize(2 * layout_.stride);
    states.resize(2);
    const auto child_error = [](const BernsteinBisection& b, double e, const double* v, std::size_t n) {
      return up((e + b.halving_rounding_relative() * largest_magnitude(v, n) + b.halving_rounding_absolute()) *
                (1 + 1e-12));
    };
    const std::size_t sj = in_.j.size();
    double* first = children.data();
    double* second = children.data() + layout_.stride;
    jb.halve(leaf, 1, state, first, second, states.data());
    child_err[0] = child_error(jb, err[0], leaf, sj);
    for (std::size_t c = 0; c < dim_; ++c) {
      const BernsteinBisection& cb = *layout_.col_tools[c]->bisection;
      const std::size_t at = layout_.offset[c + 1];
      ws_.column_states.resize(2);
      cb.halve(leaf + at, 3, state, first + at, second + at, ws_.column_states.data());
      child_err[c + 1] = child_error(cb, err[c + 1], leaf + at, 3 * layout_.size[c]);
    }
  }

  int levels() const { return layout_.j_tools->bisection->levels(); }

  BisectionState root_state() const { return layout_.j_tools->bisection->root_state(); }

 private:
  const ScaledJacobianSpace& space_;
  const QuotientInput& in_;
  const QuotientLayout& layout_;
  std::size_t dim_ = 0;
  QuotientScratch& ws_;
};

// Which bound the leaves get: Quotient::bound (split into 2^dim children), signed_bound or
// paired_bound (single bisections); signs_unless_floor: signed_bound, not refined where the
// root's bound is at the Hadamard floor.
enum class Pairing { none, signs, signs_unless_floor, positive };

QualityBounds refine(const ScaledJacobianSpace& space, const QuotientInput& in, double tol, int max_splits,
                     Pairing pairing, QualityBounds out, FrameBounds* frame_lower);

}  // namespace

namespace {
thread_local bool use_paired_stage = true;
}  // namespace

void scaled_jacobian_use_paired_stage(bool on) noexcept { use_paired_stage = on; }

QualityBounds quotient_bounds(const ScaledJacobianSpace& space, const QuotientInput& in, double tol,
                              int max_splits, int max_paired_splits, FrameBounds* frame_lower) {
  QualityBounds out;
  out.lower = -kInf;
  out.upper = space.s_hi();
  if (frame_lower) frame_lower->fill(-kInf);
  if (!(down(*std::min_element(in.j.begin(), in.j.end()) - in.j_error) > 0)) return out;
  if (use_paired_stage && !layout_of(space, shape_of(in)).triple.empty())
    return refine(space, in, tol, max_paired_splits, Pairing::positive, out, frame_lower);
  return refine(space, in, tol, max_splits, Pairing::none, out, frame_lower);
}

QualityBounds signed_quotient_bounds(const ScaledJacobianSpace& space, const QuotientInput& in, double tol,
                                     int max_splits, double upper, FrameBounds* frame_lower, bool floor_root_ends) {
  QualityBounds out;
  out.lower = -kInf;
  out.upper = std::min(upper, 0.0);  // J <= 0 at a point, where sj <= 0
  if (frame_lower) frame_lower->fill(-kInf);
  if (layout_of(space, shape_of(in)).triple.empty()) return out;  // L_k outside J's space (2D)
  return refine(space, in, tol, max_splits, floor_root_ends ? Pairing::signs_unless_floor : Pairing::signs, out,
                frame_lower);
}

namespace {

// Best-first refinement of the leaves' bounds (see Pairing), from `out` holding the bounds
// known before.
QualityBounds refine(const ScaledJacobianSpace& space, const QuotientInput& in, double tol, int max_splits,
                     Pairing pairing, QualityBounds out, FrameBounds* frame_lower) {
  thread_local QuotientScratch scratch;
  const Quotient q(space, in, scratch);
  const std::size_t stride = q.stride();
  thread_local std::vector<double> pool, children;
  thread_local std::vector<std::array<double, 4>> pool_err;
  thread_local std::vector<FrameBounds> pool_frames;  // per slot: its leaf's frame bounds
  thread_local std::vector<BisectionState> states, child_states;
  thread_local std::vector<int> free_slots;
  thread_local std::vector<Leaf> heap;
  reserve_slots(pool, stride);
  pool.resize(stride);
  pool_err.assign(1, {});
  pool_frames.resize(1);
  states.assign(1, q.root_state());
  free_slots.clear();
  heap.clear();
  q.root(pool.data(), pool_err[0]);

  double settled = kInf;  // least lower bound of the leaves dropped as good enough
  FrameBounds settled_frames;  // the same per frame
  settled_frames.fill(kInf);
  long next_id = 0;
  const bool with_signs = pairing == Pairing::signs || pairing == Pairing::signs_unless_floor;
  const auto cmp = [](const Leaf& a, const Leaf& b) { return a.lower != b.lower ? a.lower > b.lower : a.id > b.id; };
  const auto push = [&](int slot) {
    const auto s = static_cast<std::size_t>(slot);
    const double* leaf = pool.data() + s * stride;
    FrameBounds& frames = pool_frames[s];
    frames.fill(kInf);
    const double lo = with_signs ? q.signed_bound(leaf, pool_err[s], out.upper, frames)
                      : pairing == Pairing::positive ? q.paired_bound(leaf, pool_err[s], out.upper, frames)
                                                     : q.bound(leaf, pool_err[s], out.upper, frames);
    if (up(out.upper - lo) <= tol) {
      settled = std::min(settled, lo);  // stays good enough: upper only decreases
      for (std::size_t k = 0; k < frames.size(); ++k) settled_frames[k] = std::min(settled_frames[k], frames[k]);
      free_slots.push_back(slot);
      return;
    }
    heap.push_back({lo, slot, next_id++});
    std::push_heap(heap.begin(), heap.end(), cmp);
  };
  push(0);
  // The gap shrinks about linearly with the subdomain: a root far from the tolerance would
  // need more splits than the products of the full bounds cost (scaled_jacobian.cpp,
  // kQuotientSplits), so only a root within kReachable tolerances is refined.
  if (pairing == Pairing::none && !heap.empty() && up(out.upper - heap.front().lower) > kReachable * tol)
    max_splits = 0;
  if (pairing == Pairing::positive && !heap.empty() && up(out.upper - heap.front().lower) > kPairedReachable * tol)
    max_splits = 0;
  if (pairing == Pairing::signs_unless_floor && !heap.empty() && heap.front().lower <= -space.s_hi())
    max_splits = 0;
  thread_local std::vector<double> parent;
  parent.resize(stride);
  std::array<double, 4> child_err{};
  // The paired bounds refine by single bisections (as the full bounds do), `levels` of
  // them counting as one split.
  const bool halving = pairing != Pairing::none;
  const long levels = halving ? q.levels() : 1;
  long steps = 0;
  while (!heap.empty()) {
    const Leaf top = heap.front();
    if (up(out.upper - std::min(top.lower, settled)) <= tol || steps >= max_splits * levels) break;
    std::pop_heap(heap.begin(), heap.end(), cmp);
    heap.pop_back();
    ++steps;
    const auto ts = static_cast<std::size_t>(top.slot);
    std::copy_n(pool.data() + ts * stride, stride, parent.data());  // its slot is reused below
    const std::array<double, 4> parent_err = pool_err[ts];
    const BisectionState parent_state = states[ts];
    free_slots.push_back(top.slot);
    if (halving)
      q.halve(parent.data(), parent_err, parent_state, children, child_states, child_err);
    else
      q.split(parent.data(), parent_err, parent_state, children, child_states, child_err);
    for (std::size_t c = 0; c < child_states.size(); ++c) {
      int slot;
      if (!free_slots.empty()) {
        slot = free_slots.back();
        free_slots.pop_back();
      } else {
        slot = static_cast<int>(pool_err.size());
        pool.resize(pool.size() + stride);
        pool_err.emplace_back();
        pool_frames.emplace_back();
        states.emplace_back();
      }
      const auto s = static_cast<std::size_t>(slot);
      std::copy_n(children.data() + c * stride, stride, pool.data() + s * stride);
      pool_err[s] = child_err;
      states[s] = child_states[c];
      push(slot);
    }
  }
  out.subdivisions = static_cast<int>((steps + levels - 1) / levels);
  double lower = settled;
  for (const Leaf& l : heap) {
    lower = std::min(lower, l.lower);
    for (std::size_t k = 0; k < settled_frames.size(); ++k)
      settled_frames[k] = std::min(settled_frames[k], pool_frames[static_cast<std::size_t>(l.slot)][k]);
  }
  out.lower = lower;
  out.tolerance_met = up(out.upper - out.lower) <= tol;
  if (frame_lower) *frame_lower = settled_frames;
  return out;
}

// The root of refine's paired stage for four elements at once, element l in lane l of every
// vector: the steps of directional_columns (shifted) and paired_bound, each lane with the
// operations the scalar path does on that element (the helpers above, and the same loops
// over the coefficients in lanes), so the same bits. Where a lane's root meets the
// tolerance, refine returns exactly those bounds, with no subdivision.
class PairedRoots {
 public:
  static constexpr std::size_t kW = 4;
  using V = Lanes4;

  // The vectors, kept per thread from call to call.
  struct Scratch {
    std::vector<V> part, products, corner_lo;
    std::vector<std::vector<V>> along;
  };

  PairedRoots(const ScaledJacobianSpace& space, const QuotientLanes& in, Scratch& ws)
      : space_(space), in_(in), layout_(layout_of(space, shape_of(in))), ws_(ws) {
    QV_ASSERT(layout_.offset[1] == in.j.size() && layout_.size[0] == in.col[0][0].size(), "the layout of another input");
  }

  unsigned run(double tol, std::array<QualityBounds, 4>& out) {
    const std::span<const V> j = in_.j;
    const std::size_t sj = j.size();
    const std::size_t nd = layout_.distinct.size();
    const std::vector<int>& j_corners = layout_.j_tools->corners;
    const std::size_t corners = j_corners.size();
    const double s_lo = space_.s_lo(), s_hi = space_.s_hi();
    err_ = {in_.j_error, in_.col_error[0], in_.col_error[1]};
    // quotient_bounds' test: J's least coefficient positive (min_element's value: the first
    // of the least), else lower = -inf there.
    V j_min = constant<V>(kInf);
    for (const V& c : j) j_min = vmin(j_min, c);
    const V j_lo = down(j_min - in_.j_error);
    const unsigned open = lanes3::mask_bits<4>(j_lo > 0);
    if (open == 0) return 0;
    // The frame columns: directional_columns, shifted.
    std::array<Mask4, kMaxDistinct> usable_column{};
    ws_.along.resize(nd);
    ws_.corner_lo.resize(nd * corners);
    for (std::size_t dc = 0; dc < nd; ++dc) usable_column[dc] = frame_column(dc, corners);
    // The frames: paired_bound.
    V lower = constant<V>(kInf), upper = constant<V>(s_hi);
    ws_.products.resize(sj);
    for (std::size_t k = 0; k < layout_.frames.size(); ++k) {
      const auto& fr = layout_.frames[k];
      const Mask4 usable = usable_column[fr[0]] & usable_column[fr[1]];
      // min_i (J_i - e) / (U_i + e_U) as scan_ratios<true> computes it.
      V least{}, least_den{};
      if ((lanes3::mask_bits<4>(usable) & open) != 0) {
        if (!layout_.triple[k].first->multiply4(lane_data(ws_.along[fr[0]]), lane_data(ws_.along[fr[1]]),
                                                reinterpret_cast<double*>(ws_.products.data())))
          return 0;
        const V a = -err_[0];
        const V b = product_error<V>({big_[fr[0]], big_[fr[1]], constant<V>(1)},
                                     {along_err_[fr[0]], along_err_[fr[1]], V{}}, layout_.triple[k].rounding);
        least = constant<V>(kInf);
        least_den = least;
        for (std::size_t i = 0; i < sj; ++i) {
          least = vmin(least, (j[i] + a) / (ws_.products[i] + b));
          least_den = vmin(least_den, ws_.products[i] + b);
        }
      }
      const V norm_product = up(up(1 * norm_big_[fr[0]]) * norm_big_[fr[1]]);
      lower = vmin(lower, paired_frame_lower(j_lo, norm_product, s_lo, usable, least, least_den));
      for (std::size_t mi = 0; mi < corners; ++mi) {
        const V corner_product =
            down(down(1 * ws_.corner_lo[fr[0] * corners + mi]) * ws_.corner_lo[fr[1] * corners + mi]);
        upper = paired_corner_upper(j[static_cast<std::size_t>(j_corners[mi])], err_[0], corner_product, s_hi, upper);
      }
    }
    const unsigned settled = open & lanes3::mask_bits<4>(up(upper - lower) <= tol);
    for (std::size_t l = 0; l < kW; ++l)
      if ((settled >> l) & 1u) out[l] = {lower[l], upper[l], 0, true};
    return settled;
  }

 private:
  // Distinct frame column dc: its dot products with d, shifted, into ws_.along[dc], its
  // bounds into big_, norm_big_, along_err_, ws_.corner_lo; returns the lanes where it is
  // usable.
  Mask4 frame_column(std::size_t dc, std::size_t corners) {
    const FrameColumn& f = layout_.distinct[dc];
    const auto c0 = static_cast<std::size_t>(f.column[0]);
    const std::size_t n = layout_.size[c0];
    // frame_column: coordinate x of the column at control point i.
    std::vector<V>& part = ws_.part;
    part.resize(2 * n);
    std::array<V, 3> mean{};
    V mag{};
    for (std::size_t x = 0; x < 2; ++x)
      for (std::size_t i = 0; i < n; ++i) {
        V v = V{} + f.weight[0] * column(f.column[0], x)[i];
        for (int t = 1; t < f.terms; ++t)
          v = v + f.weight[static_cast<std::size_t>(t)] * column(f.column[static_cast<std::size_t>(t)], x)[i];
        part[x * n + i] = v;
        mean[x] += v;
        mag = vmax(mag, vabs(v));
      }
    const V ev = frame_column_error<V>(f, {err_[0], err_[1], err_[2], V{}}, {in_.col_magnitude[0], in_.col_magnitude[1], V{}});
    const V spread = norm_spread(ev);
    for (std::size_t mi = 0; mi < corners; ++mi) {
      const auto at = static_cast<std::size_t>(layout_.col_tools[c0]->corners[mi]);
      V sum{};
      for (std::size_t x = 0; x < 2; ++x) sum += part[x * n + at] * part[x * n + at];
      ws_.corner_lo[dc * corners + mi] = corner_norm_below(sum, spread);
    }
    const V len = root(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
    Mask4 usable = (len > 0) & (len < kInf);
    std::array<V, 2> d;
    for (std::size_t x = 0; x < 2; ++x) d[x] = where(usable, mean[x] / len * (1 - 1e-15), V{});  // |d| <= 1
    // project_along<2>, shifted.
    std::vector<V>& along = ws_.along[dc];
    along.resize(n);
    V big{}, big_square{}, perp_square{}, a_min = constant<V>(kInf);
    for (std::size_t i = 0; i < n; ++i) {
      const V v0 = part[i], v1 = part[n + i];
      const V a = v0 * d[0] + v1 * d[1];
      along[i] = a;
      big = vmax(big, vabs(a));
      big_square = vmax(big_square, v0 * v0 + v1 * v1);
      a_min = vmin(a_min, a);
      const V p0 = v0 - a * d[0], p1 = v1 - a * d[1];
      perp_square = vmax(perp_square, p0 * p0 + p1 * p1);
    }
    const V vn = largest_norm(big_square);
    norm_big_[dc] = where(usable, up(vn + spread), constant<V>(kInf));
    along_err_[dc] = along_error(ev, mag);
    const V q = paired_shift(ev, vn, perp_square, a_min, along_err_[dc]);
    usable &= q >= 0;
    V shifted_big{};
    for (V& a : along) {
      a += q;
      shifted_big = vmax(shifted_big, vabs(a));
    }
    big_[dc] = shifted_big;
    along_err_[dc] = shifted_along_error(along_err_[dc], shifted_big);
    return usable;
  }

  // A vector of lanes as multiply4's interleaved coefficients (coefficient i of lane l at
  // 4 i + l).
  static const double* lane_data(const std::vector<V>& v) { return reinterpret_cast<const double*>(v.data()); }

  // Coordinate x of column c.
  std::span<const V> column(int c, std::size_t x) const { return in_.col[static_cast<std::size_t>(c)][x]; }

  const ScaledJacobianSpace& space_;
  const QuotientLanes& in_;
  const QuotientLayout& layout_;
  Scratch& ws_;
  std::array<V, 3> err_{};  // J's, then each column's error bound
  std::array<V, kMaxDistinct> big_{}, norm_big_{}, along_err_{};
};

}  // namespace

unsigned paired_quotient_roots(const ScaledJacobianSpace& space, const QuotientLanes& in, double tol,
                               std::array<QualityBounds, 4>& out) {
  if (!use_paired_stage || space.dim() != 2) return 0;
  if (layout_of(space, shape_of(in)).triple.empty()) return 0;
  thread_local PairedRoots::Scratch scratch;
  PairedRoots roots(space, in, scratch);
  return roots.run(tol, out);
}

}  // namespace quadval
