// Certified bounds of the quality measure mu (thesis, Paper V): validity first (the
// Jacobian engine), the closed form of mu_constant.hpp when W is constant, then
// best-first adaptive subdivision of the control values of W, each subdomain bounded by
// mu_metric.cpp (lower) and by its corner values (upper).
#include "quadval/mu_bounds.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <functional>
#include <vector>

#include "analysis/bilinear_quad_quality.hpp"
#include "analysis/lane_vector.hpp"
#include "analysis/linear_prism_mu.hpp"
#include "analysis/linear_pyramid_mu.hpp"
#include "analysis/mu_constant.hpp"
#include "analysis/mu_control_bound.hpp"
#include "analysis/mu_metric.hpp"
#include "analysis/mu_space.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/slot_pool.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/straight_sided.hpp"
#include "analysis/straight_simplex_mu.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "analysis/trilinear_hex_mu.hpp"
#include "bezier/bernstein_bisection.hpp"
#include "bezier/bernstein_product.hpp"
#include "quadval/error.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {
namespace {

struct Subdomain {
  double lower;  // certified lower bound of min R on it
  double err;    // |control values of W - exact| <= err
  double m_err;  // the same for M's, when the pool holds them
  int slot;      // its control values in the pool
  BisectionState state;
  bool operator>(const Subdomain& o) const {
    return lower != o.lower ? lower > o.lower : slot > o.slot;
  }
};

thread_local int control_mode = 2;

// Subdivisions after which the degree-12n certificate may take over from the control bound
// (see mu_bounds_given).
constexpr int kCertificateAfter = 24;

struct MuScratch {
  MuMetric metric;
  std::vector<double> pool;
  std::vector<int> free_slots;
  std::vector<std::array<double, 9>> corners;  // W at the corners bounded in this split
  std::vector<double> children;                // the children of the subdomain refined
  std::vector<Subdomain> heap;
};

// W's control values of the whole element (layout of MuMetric::lower_bound) and their
// error bound: X_c = D_c (x - x_0) within gamma_{N+4} Gamma_c R (D entries 2u, differences
// u, products and an N-term sum), then W_j = sum_c Jinv_cj X_c (Jinv entries 3u, a
// dim-term sum): in all within gamma_{N+dim+9} sum_c |Jinv_cj| Gamma_c R.
double element_w(const MuSpace& space, std::span<const double> x, double* w) {
  const int dim = space.dim();
  const int n = space.num_nodes();
  const auto ws = static_cast<std::size_t>(space.w_size());
  const auto& jinv = space.ideal_inverse();
  thread_local std::vector<double> dx;  // x_i - x_0
  dx.resize(3 * static_cast<std::size_t>(n));
  double range = 0;
  bool flat_z = true;  // a planar element in z = const
  for (std::size_t i = 0; i < dx.size(); i += 3) {
    for (std::size_t c = 0; c < 3; ++c) {
      dx[i + c] = x[i + c] - x[c];
      range = std::max(range, std::abs(dx[i + c]));
    }
    flat_z = flat_z && dx[i + 2] == 0;
  }
  // X_c's control values (coordinate a of row k at a * ws + k), then W_j = sum_c Jinv_cj X_c.
  thread_local std::vector<double> xc;
  xc.resize(3 * 3 * ws);
  const bool finite = range < std::numeric_limits<double>::infinity();
  for (int c = 0; c < dim; ++c)
    space.derivative_nonzeros(c).times_points(dx.data(), flat_z, finite, xc.data() + static_cast<std::size_t>(c) * 3 * ws);
  for (int j = 0; j < dim; ++j)
    for (std::size_t a = 0; a < 3; ++a) {
      double* out = w + (static_cast<std::size_t>(j) * 3 + a) * ws;
      for (std::size_t k = 0; k < ws; ++k) {
        double v = 0;
        for (int c = 0; c < dim; ++c)
          v += jinv[static_cast<std::size_t>(c * 3 + j)] * xc[(static_cast<std::size_t>(c) * 3 + a) * ws + k];
        out[k] = v;
      }
    }
  double worst = 0;
  for (int j = 0; j < dim; ++j) {
    double s = 0;
    for (int c = 0; c < dim; ++c) s += std::abs(jinv[static_cast<std::size_t>(c * 3 + j)]) * space.derivative_row_sum(c);
    worst = std::max(worst, s);
  }
  return rounding_gamma(n + dim + 9) * worst * range * (1 + 1e-12);
}

bool handled_family(ElementFamily f) {
  switch (f) {
    case ElementFamily::line:
    case ElementFamily::triangle:
    case ElementFamily::quadrangle:
    case ElementFamily::tetrahedron:
    case ElementFamily::prism:
    case ElementFamily::hexahedron:
    case ElementFamily::pyramid: return true;
    default: return false;
  }
}

// mu's bounds from R's, or nothing when their gap exceeds tol.
std::optional<QualityBounds> mu_from_ratio(double r_lower, double r_upper, double tol) {
  QualityBounds out;
  out.lower = sqrt_down(r_lower);
  out.upper = sqrt_up(r_upper);
  out.tolerance_met = out.upper - out.lower <= tol;
  if (!out.tolerance_met) return std::nullopt;
  return out;
}

// A straight-sided simplex (tetrahedron; triangle in a plane z = const; straight_sided.hpp):
// its columns are the edges a_c = x_c - x_0 within beta_c everywhere, so W = J_p Jinv lies
// entrywise within delta = max_j sum_c |Jinv_cj| (beta_c + 8u max|a_c|) (the edges' and the
// products' roundings, with a margin) of W_0 = [a] Jinv computed, which mu_constant.hpp
// bounds in closed form, without W's control values. W_0 is written to every control value
// of `w` (the layout those functions read). Nothing when not such a simplex, or when the
// bounds are wider than tol.
std::optional<QualityBounds> straight_simplex_mu(const MuSpace& space, std::span<const double> x, double* w,
                                                 double tol, const KnownMargin* known) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kUnit = 0x1p-53;
  const ElementType& type = space.type();
  const bool simplex = type.family == ElementFamily::tetrahedron ||
                       (type.family == ElementFamily::triangle && in_a_z_plane(x));
  if (!simplex) return std::nullopt;
  std::array<double, 3> beta{0, 0, 0};
  if (type.order > 1 && !(straight_margin_of(type, x.data(), known, beta) < kInf)) return std::nullopt;
  const auto dim = static_cast<std::size_t>(type.dim);
  {
    // The closed form in lanes (straight_simplex_mu.hpp), the element in both: the same
    // bounds as the check's chunks; where it fails, the general closed form below.
    Lanes<2> edges[9] = {}, margins[3] = {};
    for (std::size_t c = 0; c < dim; ++c) {
      margins[c] = broadcast_lanes<2>(beta[c]);
      for (std::size_t j = 0; j < 3; ++j) edges[3 * c + j] = broadcast_lanes<2>(x[3 * (c + 1) + j] - x[j]);
    }
    const StraightSimplexRatio<2> r = dim == 3 ? straight_tet_ratio<2>(edges, margins, space.ideal_inverse())
                                               : straight_triangle_ratio<2>(edges, margins, space.ideal_inverse());
    if ((r.ok & 1u) != 0) return mu_from_ratio(r.lower[0], r.upper[0], tol);
  }
  double a[3][3] = {}, a_max[3] = {0, 0, 0};
  for (std::size_t c = 0; c < dim; ++c)
    for (std::size_t j = 0; j < 3; ++j) {
      a[c][j] = x[3 * (c + 1) + j] - x[j];
      a_max[c] = std::max(a_max[c], std::abs(a[c][j]));
    }
  const auto& jinv = space.ideal_inverse();
  const auto ws = static_cast<std::size_t>(space.w_size());
  double delta = 0;
  for (std::size_t j = 0; j < dim; ++j) {
    double d = 0;
    for (std::size_t c = 0; c < dim; ++c) d += std::abs(jinv[c * 3 + j]) * (beta[c] + 8 * kUnit * a_max[c]);
    delta = std::max(delta, d);
    for (std::size_t k = 0; k < 3; ++k) {
      double v = 0;
      for (std::size_t c = 0; c < dim; ++c) v += jinv[c * 3 + j] * a[c][k];
      std::fill_n(w + (j * 3 + k) * ws, ws, v);
    }
  }
  delta = next_up(delta * (1 + 1e-12));
  if (!(delta < kInf)) return std::nullopt;
  const RatioBounds ratio = constant_ratio_bounds(space, w, delta);
  return mu_from_ratio(ratio.lower, ratio.upper, tol);
}

// First-order hexahedra, pyramids and prisms: R's bounds from their control matrices at
// the root, in lanes (trilinear_hex_mu.hpp, linear_pyramid_mu.hpp, linear_prism_mu.hpp);
// nothing for other types.
std::optional<CertifiedRatio> first_order_ratio(const MuSpace& space, std::span<const double> nodes) {
  const ElementType& type = space.type();
  const auto& jinv = space.ideal_inverse();
  if (type.family == ElementFamily::hexahedron && type.num_nodes == 8) return trilinear_hex_ratio(nodes);
  if (type.family == ElementFamily::pyramid && type.num_nodes == 5) return linear_pyramid_ratio(nodes, jinv);
  if (type.family == ElementFamily::prism && type.num_nodes == 6) return linear_prism_ratio(nodes, jinv);
  return std::nullopt;
}

// A first-order hexahedron the root did not settle, refined in its own kernel
// (refine_trilinear_hex_ratio) for as many subdivisions (3 halvings each, as the general
// path counts them) as the general path refines before its certificate takes over;
// nothing where that does not settle it.
std::optional<QualityBounds> refined_hex_mu(std::span<const double> nodes, const CertifiedRatio& root,
                                            const QualityOptions& options) {
  const RefinedRatio refined = refine_trilinear_hex_ratio(
      nodes, root, options.abs_tol, 3 * std::min(kCertificateAfter, options.max_subdivisions));
  if (!refined.settled) return std::nullopt;
  auto mu = mu_from_ratio(refined.ratio.lower, refined.ratio.upper, options.abs_tol);
  if (mu) mu->subdivisions = (refined.halvings + 2) / 3;
  return mu;
}

}  // namespace

void mu_use_control_bound(int mode) noexcept { control_mode = mode; }

unsigned straight_simplex_mu_lanes(const ElementType& type, const Lanes<kNativeLanes>* edges,
                                   const Lanes<kNativeLanes>* margins, double tol, QualityBounds* out) {
  if (!mu_constant_path_enabled()) return 0;
  const std::array<double, 9>& jinv = mu_space(type).ideal_inverse();
  const StraightSimplexRatio<kNativeLanes> r = type.family == ElementFamily::tetrahedron
                                                   ? straight_tet_ratio<kNativeLanes>(edges, margins, jinv)
                                                   : straight_triangle_ratio<kNativeLanes>(edges, margins, jinv);
  unsigned done = 0;
  for (int l = 0; l < kNativeLanes; ++l)
    if ((r.ok >> l) & 1u)
      if (const auto mu = mu_from_ratio(r.lower[l], r.upper[l], tol)) {
        out[l] = *mu;
        done |= 1u << l;
      }
  return done;
}

unsigned linear_pyramid_mu_lanes(const ElementType& type, const Lanes<kNativeLanes>* x, double tol,
                                 QualityBounds* out) {
  if (!mu_constant_path_enabled()) return 0;
  const StraightSimplexRatio<kNativeLanes> r = linear_pyramid_constant_ratio(x, mu_space(type).ideal_inverse());
  unsigned done = 0;
  for (int l = 0; l < kNativeLanes; ++l)
    if (((r.ok >> l) & 1u) != 0 && r.lower[l] <= r.upper[l])
      if (const auto mu = mu_from_ratio(r.lower[l], r.upper[l], tol)) {
        out[l] = *mu;
        done |= 1u << l;
      }
  return done;
}

bool mu_supported(const ElementType& type) noexcept {
  return handled_family(type.family) && type.has_lagrange_basis && type.order >= 1 &&
         type.order <= mu_max_order(type.family) && jacobian_bounds_supported(type);
}

QualityBounds mu_bounds(const ElementType& type, std::span<const double> nodes,
                        const QualityOptions& options, bool planar) {
  QV_ASSERT(mu_supported(type), "mu bounds do not handle " << type.name);
  QV_ASSERT(nodes.size() == static_cast<std::size_t>(3 * type.num_nodes),
            nodes.size() << " coordinates for " << type.name);
  QV_ASSERT(options.abs_tol > 0, "abs_tol " << options.abs_tol);
  thread_local BoundsWorkspace workspace;
  BoundsOptions validity;
  validity.goal = BoundsGoal::validity;
  return mu_bounds_given(type, nodes, options, planar,
                         jacobian_bounds(type, nodes, validity, workspace, planar).validity);
}

QualityBounds mu_bounds_given(const ElementType& type, std::span<const double> nodes,
                              const QualityOptions& options, bool /*planar: settled by validity*/,
                              Validity validity, const KnownMargin* known) {
  QV_ASSERT(mu_supported(type), "mu bounds do not handle " << type.name);
  QV_ASSERT(nodes.size() == static_cast<std::size_t>(3 * type.num_nodes),
            nodes.size() << " coordinates for " << type.name);
  QV_ASSERT(options.abs_tol > 0, "abs_tol " << options.abs_tol);
  thread_local MuScratch scratch;
  QualityBounds out;
  if (validity == Validity::invalid) {
    out.tolerance_met = true;  // mu = 0 exactly
    return out;
  }
  if (type.family == ElementFamily::line) {
    // One singular value: mu_pw = 1 wherever J > 0.
    out.upper = 1;
    out.lower = validity == Validity::valid ? 1.0 : 0.0;
    out.tolerance_met = out.upper - out.lower <= options.abs_tol;
    return out;
  }

  const MuSpace& space = mu_space(type);
  const BezierBasis& basis = space.w_basis();
  const auto block = static_cast<std::size_t>(space.dim() * 3 * space.w_size());
  auto& pool = scratch.pool;
  auto& free_slots = scratch.free_slots;
  free_slots.clear();
  pool.resize(block);
  if (validity == Validity::valid && mu_constant_path_enabled()) {
    if (const auto straight = straight_simplex_mu(space, nodes, pool.data(), options.abs_tol, known)) return *straight;
    if (const auto bilinear = bilinear_quad_mu_bounds(type, nodes, options.abs_tol, known)) return *bilinear;
    if (const auto ratio = first_order_ratio(space, nodes); ratio && ratio->ok) {
      if (const auto mu = mu_from_ratio(ratio->lower, ratio->upper, options.abs_tol)) return *mu;
      if (type.family == ElementFamily::hexahedron)
        if (const auto mu = refined_hex_mu(nodes, *ratio, options)) return *mu;
    }
  }
  const double err0 = element_w(space, nodes, pool.data());
  // Constant W (straight-sided simplices, parallelograms, parallelepipeds): W's control
  // values agree to 1e-9 relative. Then one corner's upper bound serves for all (they
  // differ by no more than that; the others cost an eigen solve each, a quarter of mu's
  // time on tets_h0.8_o2), and the closed form of mu_constant.hpp settles the element
  // without products when the gap is met, its upper bound included.
  double delta = 0;
  bool constant = false;
  if (mu_constant_path_enabled()) {
    const double wmax = largest_magnitude(pool.data(), block);
    delta = constant_w_radius(space, pool.data(), err0, 1e-9 * wmax);
    constant = delta <= 1e-9 * wmax;
  }
  const int corner = basis.vertex_indices()[0];
  if (validity != Validity::valid) {
    out.upper = sqrt_up(constant ? corner_ratio_upper_at(space, pool.data(), err0, corner)
                                 : corner_ratio_upper(space, pool.data(), err0));
    out.tolerance_met = out.upper <= options.abs_tol;
    return out;
  }
  double r_upper = 1;
  if (constant) {
    const RatioBounds ratio = constant_ratio_bounds(space, pool.data(), delta);
    out.lower = sqrt_down(ratio.lower);
    r_upper = ratio.upper;
    out.upper = sqrt_up(r_upper);
    if (out.upper - out.lower <= options.abs_tol) {
      out.tolerance_met = true;
      return out;
    }
  } else {
    r_upper = corner_ratio_upper(space, pool.data(), err0);
  }

  const auto tol_r = [&] {
    // mu = sqrt(R): a bracket of width abs_tol * mu / 2 in R is about abs_tol / 4 in mu.
    return 0.5 * options.abs_tol * std::max(sqrt_rn(std::max(r_upper, 0.0)), options.abs_tol);
  };
  // A lower bound of R above (sqrt(R upper) - 0.9 abs_tol)^2 meets the tolerance.
  const auto r_target = [&] {
    const double m = sqrt_rn(std::max(r_upper, 0.0)) - 0.9 * options.abs_tol;
    return m <= 0 ? 0.0 : m * m;
  };
  // Per subdomain: the control-matrix bound (mu_control_bound.hpp), which converges like
  // the certificate (quadratically) at a small fraction of its cost (mu_bench: BM_MuMode);
  // the degree-12n certificate only for elements that kCertificateAfter splits have not
  // settled (near-degenerate ones, where the enclosures of the control matrices lose
  // relative accuracy), and only where the control bound falls short.
  // Types above mu_certificate_max_order have no certificate (mu_space.hpp): the control
  // bound alone, whatever mode was asked for.
  const int mode = space.has_certificate() ? control_mode : 1;
  // Tetrahedra: twice as many, as a bisection of a tetrahedron closes the control bound's
  // gap more slowly (tets_h0.8_o2's element 2186: settled by the control bound at 34
  // subdivisions, 210 us, and with the certificate from 24 at 27, 220 us, whose tables
  // then cost 1 ms to build in each process).
  const int certificate_after =
      type.family == ElementFamily::tetrahedron ? 2 * kCertificateAfter : kCertificateAfter;
  // With the control bound each subdomain's slot also holds M's control values, halved
  // with W's (the same bisection sequence: M's space has W's factors at twice the
  // degree), so that a child's control bound needs no product.
  const bool track_metric = mode != 0;
  const BernsteinBisection& bisection = space.bisection(1);
  const BernsteinBisection* m_bisection = track_metric ? &space.bisection(2) : nullptr;
  const int vectors = space.dim() * 3;
  const int m_vectors = metric_vectors(space.dim());
  QV_ASSERT(!track_metric || m_bisection->size() == space.size(2), "M's space");
  const auto w_block = block;
  const auto slot_size = w_block + (track_metric ? static_cast<std::size_t>(m_vectors * space.size(2)) : 0);
  reserve_slots(pool, slot_size);
  long steps = 0;  // bisections so far
  const auto subdomain_lower = [&](const double* w, double err, double m_err, double r_lo, double r_hi) {
    double lo = r_lo;
    if (mode != 0) {
      // A subdomain's control matrices are certified only down to what settles the
      // element (most by the cheap test alone); the root's fully, so that an element
      // settled there gets the tightest bound.
      const double enough = steps > 0 ? r_target() : 1.0;
      lo = std::max(lo, track_metric
                            ? control_lower_bound_of_metric(space.dim(), w + w_block, m_err, space.size(2), enough)
                            : scratch.metric.control_lower_bound(space, w, err, enough));
      if (mode == 1 || out.subdivisions < certificate_after || lo >= r_target() ||
          !(std::min(r_hi, 1.0) - lo > tol_r()))
        return lo;
    }
    return scratch.metric.lower_bound(space, w, err, lo, r_hi, r_target(), tol_r());
  };
  // Refinement: the subdomain with the least bound is halved by one bisection of W's
  // space (BernsteinBisection::halve, `levels` halvings counting as one subdivision).
  // Measured against the 8 midpoint children of BezierBasis, --tol 1e-2, one thread
  // (medians of 5): hex_box 0.23 -> 0.17 s, warped_prism 28 -> 22 ms, warped_pyramid_o2
  // 74 -> 64 ms, the 2D meshes within noise. Tetrahedra kept the midpoint children until
  // their subdomains' control matrices were certified only down to r_target (Maubach's
  // children close the gap more slowly: tets_h0.8_o2 then took 42 -> 71 ms); since, mu on
  // 2 threads, medians of 11 alternating CLI runs (two runs): warped_tetrahedron_o3
  // 8.1-8.4 -> 5.0-5.5 ms, mixed_h0.6_o2 within noise, tets_h0.8_o2 3.89 -> 3.65 ms once
  // the certificate waits longer for tetrahedra (above).
  const long levels = bisection.levels();
  // A min-heap of subdomains by lower bound, in reused storage (std::priority_queue's own
  // push_heap / pop_heap steps, so the same order).
  std::vector<Subdomain>& heap = scratch.heap;
  heap.clear();
  const auto push = [&](const Subdomain& d) {
    heap.push_back(d);
    std::push_heap(heap.begin(), heap.end(), std::greater<>());
  };
  double m_err0 = 0;
  if (track_metric) {
    pool.resize(slot_size);
    m_err0 = scratch.metric.metric(space, pool.data(), err0, pool.data() + w_block);
  }
  push({subdomain_lower(pool.data(), err0, m_err0, 0, r_upper), err0, m_err0, 0, bisection.root_state()});
  int next_slot = 1;
  scratch.children.resize(2 * slot_size);
  while (true) {
    const Subdomain top = heap.front();
    out.lower = sqrt_down(top.lower);
    out.upper = sqrt_up(r_upper);
    if (out.upper - out.lower <= options.abs_tol) {
      out.tolerance_met = true;
      break;
    }
    if (steps >= static_cast<long>(options.max_subdivisions) * levels) break;
    std::pop_heap(heap.begin(), heap.end(), std::greater<>());
    heap.pop_back();
    ++steps;
    out.subdivisions = static_cast<int>((steps + levels - 1) / levels);
    const auto par = static_cast<std::size_t>(top.slot) * slot_size;
    const double wmax = largest_magnitude(pool.data() + par, block);
    // Averages never exceed their inputs: the parent's error plus the step's rounding.
    const double child_err =
        (top.err + bisection.halving_rounding_relative() * wmax + bisection.halving_rounding_absolute()) * (1 + 1e-12);
    // The parent's corners are in r_upper already, bounded with a smaller error bound.
    scratch.corners.clear();
    remember_corners(space, pool.data() + par, scratch.corners);
    BisectionState states[2];
    double child_m_err = 0;
    double* first = scratch.children.data();
    double* second = first + slot_size;
    bisection.halve(pool.data() + par, static_cast<std::size_t>(vectors), top.state, first, second, states);
    if (track_metric) {
      const double* m = pool.data() + par + w_block;
      const auto m_size = slot_size - w_block;
      child_m_err = (top.m_err + m_bisection->halving_rounding_relative() * largest_magnitude(m, m_size) +
                     m_bisection->halving_rounding_absolute()) *
                    (1 + 1e-12);
      BisectionState unused[2];
      m_bisection->halve(m, static_cast<std::size_t>(m_vectors), top.state, first + w_block, second + w_block, unused);
    }
    free_slots.push_back(top.slot);
    for (std::size_t q = 0; q < 2; ++q) {
      int slot;
      if (!free_slots.empty()) {
        slot = free_slots.back();
        free_slots.pop_back();
      } else {
        slot = next_slot++;
        pool.resize(static_cast<std::size_t>(next_slot) * slot_size);
      }
      const auto child = static_cast<std::size_t>(slot) * slot_size;
      std::copy(scratch.children.begin() + static_cast<std::ptrdiff_t>(q * slot_size),
                scratch.children.begin() + static_cast<std::ptrdiff_t>((q + 1) * slot_size),
                pool.begin() + static_cast<std::ptrdiff_t>(child));
      const double corner = corner_ratio_upper(space, pool.data() + child, child_err, &scratch.corners, r_upper);
      r_upper = std::min(r_upper, corner);
      const double lo = subdomain_lower(pool.data() + child, child_err, child_m_err, top.lower, std::min(corner, r_upper));
      push({lo, child_err, child_m_err, slot, states[q]});
    }
  }
  return out;
}

namespace {

// mu_bounds_given's steps from element_w to its root's tolerance test, for four valid
// planar elements in planes z = const whose closed forms did not apply, element l in lane
// l of every vector: the same operations lane by lane (SparseRows::rows_times_planar_lanes,
// BernsteinProduct::gram_sums2x4, the enclosures of mu_control_bound.hpp), so the same
// bits. W's z coordinates are +0 there (not stored). Returns bit l where lane l's root meets
// the tolerance and the scalar path takes the same branches (W not constant, every
// corner's closed form at least 1e-2), out[l] then exactly mu_bounds_given's result.
unsigned planar_mu_roots(const MuSpace& space, const std::array<std::span<const double>, 4>& nodes, double tol,
                         std::array<QualityBounds, 4>& out) {
  using V = Lanes<4>;
  const auto up = [](V x) { return lanes3::up<4>(x); };
  const int n = space.num_nodes();
  const auto nn = static_cast<std::size_t>(n);
  const auto ws = static_cast<std::size_t>(space.w_size());
  const auto& jinv = space.ideal_inverse();
  thread_local std::vector<V> d, xc, w, m;
  // element_w: x_i - x_0, their range, X_c's control values, W_j = sum_c Jinv_cj X_c.
  d.resize(2 * nn);
  V range{};
  if (!planar_differences(nodes, nn, d.data(), range)) return 0;
  xc.resize(4 * ws);  // (c, a) at (2 c + a) ws
  for (int c = 0; c < 2; ++c) space.derivative_nonzeros(c).rows_times_planar_lanes(d.data(), xc.data() + 2 * c * ws);
  w.resize(4 * ws);  // (j, a) at (2 j + a) ws
  for (std::size_t j = 0; j < 2; ++j)
    for (std::size_t a = 0; a < 2; ++a)
      for (std::size_t k = 0; k < ws; ++k)
        w[(2 * j + a) * ws + k] = (V{} + jinv[j] * xc[a * ws + k]) + jinv[3 + j] * xc[(2 + a) * ws + k];
  double worst = 0;
  for (int j = 0; j < 2; ++j) {
    double s = 0;
    for (int c = 0; c < 2; ++c) s += std::abs(jinv[static_cast<std::size_t>(c * 3 + j)]) * space.derivative_row_sum(c);
    worst = std::max(worst, s);
  }
  const V err0 = rounding_gamma(n + 2 + 9) * worst * range * (1 + 1e-12);
  // Constant W (constant_w_radius): that lane takes mu_constant.hpp's closed form instead.
  V wmax{}, dev{};
  for (std::size_t r = 0; r < 4; ++r) {
    const V* p = w.data() + r * ws;
    for (std::size_t k = 0; k < ws; ++k) wmax = vmax(wmax, vabs(p[k]));
    for (std::size_t k = 1; k < ws; ++k) dev = vmax(dev, vabs(p[k] - p[0]));
  }
  const V stop = 1e-9 * wmax;
  unsigned open = 15u & ~lanes3::mask_bits<4>((dev <= stop) & (up(err0 + up(dev)) <= stop));
  // corner_ratio_upper: the least closed-form bound over the corners (its skipped corners
  // are certified at least its bound, so the least is the same); a lane where one is below
  // 1e-2 would take Rayleigh quotients too.
  V r_upper = V{} + 1;
  for (const int k : space.w_basis().vertex_indices()) {
    const auto at = static_cast<std::size_t>(k);
    static constexpr int kPairs2[3][2] = {{0, 0}, {1, 1}, {0, 1}};
    V cm[3], cerr{};
    for (std::size_t e = 0; e < 3; ++e) {
      V sum{}, mag{}, prop{};
      for (std::size_t c = 0; c < 3; ++c) {
        const auto i = static_cast<std::size_t>(kPairs2[e][0]), j = static_cast<std::size_t>(kPairs2[e][1]);
        const V a = c < 2 ? w[(2 * i + c) * ws + at] : V{}, b = c < 2 ? w[(2 * j + c) * ws + at] : V{};
        sum += a * b;
        mag += vabs(a * b);
        prop += (vabs(a) + vabs(b) + err0) * err0;
      }
      cm[e] = sum;
      cerr = vmax(cerr, (prop + rounding_gamma(4) * mag) * (1 + 1e-12));
    }
    const V closed = enclosure_ratio_upper2_lanes<4>(cm, cerr);
    open &= ~lanes3::mask_bits<4>(closed < 1e-2);
    r_upper = vmin(r_upper, closed);
  }
  if (open == 0) return 0;
  // MuMetric::metric: M's control values by gram_sums, its error bound.
  const BernsteinProduct& p11 = space.prod(1, 1);
  const auto size = static_cast<std::size_t>(space.size(2));
  m.assign(3 * size, V{});
  const double* columns[4];
  V mag[6];
  for (std::size_t j = 0; j < 2; ++j)
    for (std::size_t x = 0; x < 3; ++x) {
      mag[3 * j + x] = V{};
      if (x == 2) continue;
      const V* p = w.data() + (2 * j + x) * ws;
      columns[2 * j + x] = reinterpret_cast<const double*>(p);
      for (std::size_t k = 0; k < ws; ++k) mag[3 * j + x] = vmax(mag[3 * j + x], vabs(p[k]));
    }
  double* h[3] = {reinterpret_cast<double*>(m.data()), reinterpret_cast<double*>(m.data() + size),
                  reinterpret_cast<double*>(m.data() + 2 * size)};
  if (!p11.gram_sums2x4(columns, h)) return 0;
  V m_err{};
  for (const auto& [a, b] : BernsteinProduct::kGramEntries2) {
    V prop{}, scale_fg{};
    for (std::size_t x = 0; x < 3; ++x) {
      const V fm = mag[3 * static_cast<std::size_t>(a) + x], gm = mag[3 * static_cast<std::size_t>(b) + x];
      prop += fm * err0 + err0 * gm + err0 * err0;
      scale_fg += fm * gm;
    }
    m_err = vmax(m_err, (prop + p11.rounding(3) * scale_fg) * (1 + 1e-12));
  }
  // control_ratio_lower<2>: the least enclosure over M's control matrices.
  const V e = vmax(vmax(vmax(V{}, m_err), m_err), m_err);
  V control = V{} + 1;
  for (std::size_t k = 0; k < size; ++k) {
    const V mk[3] = {m[k], m[size + k], m[2 * size + k]};
    control = vmin(control, enclosure_ratio_lower2_lanes<4>(mk, e));
  }
  const V lo = vmax(V{}, control);
  unsigned settled = 0;
  for (std::size_t l = 0; l < 4; ++l) {
    if (!((open >> l) & 1u)) continue;
    const double lower = sqrt_down(lo[l]), upper = sqrt_up(r_upper[l]);
    if (!(upper - lower <= tol)) continue;
    out[l] = {lower, upper, 0, true};
    settled |= 1u << l;
  }
  return settled;
}

}  // namespace

unsigned mu_valid_planar4(const ElementType& type, const std::array<std::span<const double>, 4>& nodes,
                          const QualityOptions& options, const std::array<const KnownMargin*, 4>& known,
                          std::array<QualityBounds, 4>& out) {
  QV_ASSERT(mu_supported(type) && type.dim == 2, "four planar elements of " << type.name);
  if (!mu_constant_path_enabled()) return 0;
  const MuSpace& space = mu_space(type);
  if (space.has_certificate() && control_mode == 0) return 0;
  thread_local std::vector<double> pool;
  pool.resize(static_cast<std::size_t>(space.dim() * 3 * space.w_size()));
  unsigned done = 0;
  for (std::size_t l = 0; l < 4; ++l) {
    // mu_bounds_given's closed forms first, as it takes them.
    if (const auto straight = straight_simplex_mu(space, nodes[l], pool.data(), options.abs_tol, known[l])) {
      out[l] = *straight;
      done |= 1u << l;
    } else if (const auto bilinear = bilinear_quad_mu_bounds(type, nodes[l], options.abs_tol, known[l])) {
      out[l] = *bilinear;
      done |= 1u << l;
    }
  }
  if (done == 15) return done;
  std::array<QualityBounds, 4> roots;
  const unsigned settled = planar_mu_roots(space, nodes, options.abs_tol, roots) & ~done;
  for (std::size_t l = 0; l < 4; ++l)
    if ((settled >> l) & 1u) out[l] = roots[l];
  return done | settled;
}

}  // namespace quadval
