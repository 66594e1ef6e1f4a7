// Per-subdomain bounds of R = lambda_min / lambda_max (see mu_metric.hpp for the method).
// Error model: every polynomial carries (coefficients c, err, mag = max|c|); the exact
// polynomial's control values lie within err of c. A product sum_t s_t f_t g_t has error
// sum |s| (F e_g + e_f G + e_f e_g) + rounding(k) sum |s| F G (bernstein_product.hpp),
// F = max|f|; a coefficient-wise combination sum a_i f_i with k terms has error
// sum |a_i| e_i + gamma_{k+2} sum |a_i| F_i (sum, scale products, and constants such as
// 1/3 rounded to double). Error bounds are computed in double and enlarged by 1e-12
// relative, which covers their own rounding.
#include "analysis/mu_metric.hpp"
#include "analysis/mu_w_matrix.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>

#include "analysis/lane_vector.hpp"
#include "analysis/mu_control_bound.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kSlack = 1 + 1e-12;
constexpr double kInf = std::numeric_limits<double>::infinity();

double max_abs(const std::vector<double>& v) { return largest_magnitude(v.data(), v.size()); }

// Largest rho (rounded down) with rho * D <= N certified coefficient-wise (Paper V §3.1,
// both signs of the denominator); -inf when no rho satisfies every coefficient, +inf when
// every constraint is a lower limit.
double ratio_lower_bound(const std::vector<double>& n, double en, const std::vector<double>& d,
                         double ed) {
  double lower = -kInf, upper = kInf;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const double n_lo = next_down(n[i] - en);
    for (double dv : {next_down(d[i] - ed), next_up(d[i] + ed)}) {
      if (dv > 0) {
        upper = std::min(upper, next_down(n_lo / dv));
      } else if (dv < 0) {
        lower = std::max(lower, next_up(n_lo / dv));
      } else if (n_lo < 0) {
        return -kInf;
      }
    }
  }
  return lower <= upper ? upper : -kInf;
}

thread_local bool use_filter = true;

// The error bound of a sum of `terms` products of `table` (see the top), from the sums
// prop = sum |s| (F e_g + e_f G + e_f e_g) and scale_fg = sum |s| F G.
double product_error(const BernsteinProduct& table, int terms, double prop, double scale_fg) {
  return (prop + table.rounding(terms) * scale_fg) * kSlack;
}

}  // namespace

void mu_use_filter(bool on) noexcept { use_filter = on; }

void MuMetric::product(const BernsteinProduct& table,
                       std::initializer_list<std::tuple<double, const Poly*, const Poly*>> terms,
                       Poly& out) {
  out.c.assign(static_cast<std::size_t>(table.h_size()), 0.0);
  int k = 0;
  std::array<BernsteinProduct::Term, 8> batch{};
  QV_ASSERT(terms.size() <= batch.size(), terms.size() << " terms");
  for (const auto& [s, f, g] : terms) batch[static_cast<std::size_t>(k++)] = {s, f->c.data(), g->c.data()};
  table.multiply_add_sum(std::span<const BernsteinProduct::Term>(batch.data(), static_cast<std::size_t>(k)),
                         out.c.data());
  bound_product(table, terms, out);
}

void MuMetric::bound_product(const BernsteinProduct& table,
                             std::initializer_list<std::tuple<double, const Poly*, const Poly*>> terms, Poly& out) {
  double prop = 0, scale_fg = 0;
  for (const auto& [s, f, g] : terms) {
    prop += std::abs(s) * (f->mag * g->err + f->err * g->mag + f->err * g->err);
    scale_fg += std::abs(s) * f->mag * g->mag;
  }
  out.err = product_error(table, static_cast<int>(terms.size()), prop, scale_fg);
  out.mag = max_abs(out.c);
}

void MuMetric::metric_entries(const MuSpace& space, const double* w, double err) {
  const int dim = space.dim();
  const auto ws = static_cast<std::size_t>(space.w_size());
  for (int j = 0; j < dim * 3; ++j) {
    Poly& p = w_[j];
    p.c.assign(w + static_cast<std::size_t>(j) * ws, w + static_cast<std::size_t>(j + 1) * ws);
    p.err = err;
    p.mag = max_abs(p.c);
  }
  const BernsteinProduct& p11 = space.prod(1, 1);
  // All entries in one walk over the product's pairs where it has them (gram_sums), with
  // each entry's error bound as product() gives it. mu of warped_pyramid_o2_N6_a0.15, one
  // thread, medians of 5: 18.3 -> 14.0 ms (the entries were a third of it; 6 walks before).
  {
    const auto entry = [dim](int e) {
      return dim == 3 ? BernsteinProduct::kGramEntries3[static_cast<std::size_t>(e)]
                      : BernsteinProduct::kGramEntries2[static_cast<std::size_t>(e)];
    };
    // m_ holds m00, m11, m22, m01, m02, m12 (2D: m00, m11, -, m01).
    const auto slot = [](const std::array<int, 2>& ab) { return ab[0] == ab[1] ? ab[0] : ab[0] + ab[1] + 2; };
    const int entries = dim * (dim + 1) / 2;
    const double* columns[9];
    for (int j = 0; j < dim * 3; ++j) columns[j] = w_[j].c.data();
    double* out[6];
    for (int e = 0; e < entries; ++e) {
      Poly& m = m_[slot(entry(e))];
      m.c.assign(static_cast<std::size_t>(p11.h_size()), 0.0);
      out[e] = m.c.data();
    }
    // Planar elements in a plane z = const: W's z coordinates are +0 everywhere.
    bool flat_z = true;
    for (int j = 0; j < dim; ++j) flat_z = flat_z && w_[3 * j + 2].mag == 0;
    if (p11.gram_sums(columns, dim, out, flat_z ? 2 : 3)) {
      for (int e = 0; e < entries; ++e) {
        const auto [a, b] = entry(e);
        bound_product(p11, {{1.0, &w_[3 * a], &w_[3 * b]}, {1.0, &w_[3 * a + 1], &w_[3 * b + 1]},
                            {1.0, &w_[3 * a + 2], &w_[3 * b + 2]}},
                      m_[slot(entry(e))]);
      }
      return;
    }
  }
  const auto dot = [&](int a, int b, Poly& out) {
    product(p11, {{1.0, &w_[3 * a], &w_[3 * b]}, {1.0, &w_[3 * a + 1], &w_[3 * b + 1]},
                  {1.0, &w_[3 * a + 2], &w_[3 * b + 2]}},
            out);
  };
  // m_: m00, m11, m22, m01, m02, m12 (2D: m00, m11, -, m01).
  dot(0, 0, m_[0]);
  dot(1, 1, m_[1]);
  dot(0, 1, m_[3]);
  if (dim == 3) {
    dot(2, 2, m_[2]);
    dot(0, 2, m_[4]);
    dot(1, 2, m_[5]);
  }
}

double MuMetric::control_lower_bound(const MuSpace& space, const double* w, double err, double enough) {
  metric_entries(space, w, err);
  const int size = static_cast<int>(m_[0].c.size());
  if (space.dim() == 2) {
    const double* e[3] = {m_[0].c.data(), m_[1].c.data(), m_[3].c.data()};
    const double er[3] = {m_[0].err, m_[1].err, m_[3].err};
    return control_ratio_lower<2>(e, er, size);
  }
  const double* e[6];
  double er[6];
  for (int i = 0; i < 6; ++i) e[i] = m_[i].c.data(), er[i] = m_[i].err;
  return control_ratio_lower<3>(e, er, size, enough);
}

double MuMetric::metric(const MuSpace& space, const double* w, double err, double* out) {
  const int dim = space.dim();
  const auto size = static_cast<std::size_t>(space.size(2));
  const BernsteinProduct& p11 = space.prod(1, 1);
  QV_ASSERT(static_cast<std::size_t>(p11.h_size()) == size, "M's space");
  // W's columns read where they are and M's entries written straight to `out`, in
  // kGramEntries order (m00, m11, (m22,) m01, (m02, m12)); the same sums and error bounds
  // as metric_entries and bound_product, without copying either.
  const auto ws = static_cast<std::size_t>(space.w_size());
  const double* columns[9];
  double mag[9];
  for (int j = 0; j < dim * 3; ++j) {
    columns[j] = w + static_cast<std::size_t>(j) * ws;
    mag[j] = largest_magnitude(columns[j], ws);
  }
  const int entries = metric_vectors(dim);
  double* h[6];
  for (int e = 0; e < entries; ++e) {
    h[e] = out + static_cast<std::size_t>(e) * size;
    std::fill_n(h[e], size, 0.0);
  }
  bool flat_z = true;  // planar elements in a plane z = const: W's z coordinates are +0
  for (int j = 0; j < dim; ++j) flat_z = flat_z && mag[3 * j + 2] == 0;
  if (p11.gram_sums(columns, dim, h, flat_z ? 2 : 3)) {
    double bound = 0;
    for (int e = 0; e < entries; ++e) {
      const auto [a, b] = dim == 3 ? BernsteinProduct::kGramEntries3[static_cast<std::size_t>(e)]
                                   : BernsteinProduct::kGramEntries2[static_cast<std::size_t>(e)];
      double prop = 0, scale_fg = 0;  // bound_product's sums, its scales all 1
      for (int x = 0; x < 3; ++x) {
        const double fm = mag[3 * a + x], gm = mag[3 * b + x];
        prop += fm * err + err * gm + err * err;
        scale_fg += fm * gm;
      }
      bound = std::max(bound, product_error(p11, 3, prop, scale_fg));
    }
    return bound;
  }
  metric_entries(space, w, err);
  const std::array<int, 6> order = dim == 2 ? std::array<int, 6>{0, 1, 3, 0, 0, 0} : std::array<int, 6>{0, 1, 2, 3, 4, 5};
  double e = 0;
  for (int i = 0; i < entries; ++i) {
    const Poly& p = m_[order[static_cast<std::size_t>(i)]];
    std::copy(p.c.begin(), p.c.end(), out + static_cast<std::size_t>(i) * size);
    e = std::max(e, p.err);
  }
  return e;
}

double control_lower_bound_of_metric(int dim, const double* m, double err, int size, double enough) {
  const auto at = [&](int i) { return m + static_cast<std::size_t>(i) * static_cast<std::size_t>(size); };
  if (dim == 2) {
    const double* e[3] = {at(0), at(1), at(2)};
    const double er[3] = {err, err, err};
    return control_ratio_lower<2>(e, er, size);
  }
  const double* e[6] = {at(0), at(1), at(2), at(3), at(4), at(5)};
  const double er[6] = {err, err, err, err, err, err};
  return control_ratio_lower<3>(e, er, size, enough);
}

double MuMetric::lower_bound(const MuSpace& space, const double* w, double err, double r_lo,
                             double r_hi, double r_target, double tol_r) {
  QV_ASSERT(space.has_certificate(), "no mu certificate for " << space.type().name);
  const int dim = space.dim();
  metric_entries(space, w, err);
  const BernsteinProduct& p22 = space.prod(2, 2);
  // out = sum a_i f_i coefficient-wise, with its error bound.
  const auto combine = [](std::initializer_list<std::pair<double, const Poly*>> terms, Poly& out) {
    const std::size_t n = terms.begin()->second->c.size();
    out.c.assign(n, 0.0);
    double e = 0, m = 0;
    int k = 0;
    for (const auto& [a, f] : terms) {
      for (std::size_t i = 0; i < n; ++i) out.c[i] += a * f->c[i];
      e += std::abs(a) * f->err;
      m += std::abs(a) * f->mag;
      ++k;
    }
    out.err = (e + rounding_gamma(k + 2) * m) * kSlack;
    out.mag = max_abs(out.c);
  };

  if (dim == 2) {
    combine({{0.5, &m_[0]}, {0.5, &m_[1]}}, q_);
    combine({{0.5, &m_[0]}, {-0.5, &m_[1]}}, s_);
    product(p22, {{1.0, &q_, &q_}}, q2_);
    product(p22, {{1.0, &s_, &s_}, {1.0, &m_[3], &m_[3]}}, n2_);
    // a^2 = q^2 / (s^2 + t^2) >= rho; R = (a - 1) / (a + 1) increasing in a (§4).
    const double rho = ratio_lower_bound(q2_.c, q2_.err, n2_.c, n2_.err);
    double r = 0;
    if (rho == kInf) {
      r = 1;
    } else if (rho > 1) {
      const double a = next_down(sqrt_rn(rho));
      r = std::max(0.0, next_down(next_down(a - 1) / next_up(a + 1)));
    }
    return std::max(r_lo, std::min(r, 1.0));
  }

  // 3D: q, D = M - q I, p^2 = tr D^2 / 6, e3 = det D.
  combine({{1.0 / 3, &m_[0]}, {1.0 / 3, &m_[1]}, {1.0 / 3, &m_[2]}}, q_);
  for (int i = 0; i < 3; ++i) combine({{1.0, &m_[i]}, {-1.0, &q_}}, d_[i]);
  product(p22, {{1.0 / 6, &d_[0], &d_[0]}, {1.0 / 6, &d_[1], &d_[1]}, {1.0 / 6, &d_[2], &d_[2]},
                {1.0 / 3, &m_[3], &m_[3]}, {1.0 / 3, &m_[4], &m_[4]}, {1.0 / 3, &m_[5], &m_[5]}},
          p2_);
  product(p22, {{1.0, &q_, &q_}}, q2_);
  // Cheap bound: a = q / p >= sqrt(rho); lambda = q + p y with y_max - y_min <= 2 sqrt 3
  // and y_max >= 1, so R = 1 - (y_max - y_min) / (a + y_max) >= 1 - 2 sqrt 3 / (a + 1).
  double lo = r_lo;
  {
    const double rho = ratio_lower_bound(q2_.c, q2_.err, p2_.c, p2_.err);
    if (rho == kInf) {
      lo = std::max(lo, next_down(1.0));
    } else if (rho > 1) {
      const double a = next_down(sqrt_rn(rho));
      const double cheap = next_down(1 - next_up(3.4641016151377553 / next_down(a + 1)));
      lo = std::max(lo, cheap);
    }
  }
  r_hi = std::min(r_hi, 1.0);
  if (!(r_hi - lo > tol_r) || lo >= r_target) return lo;

  const BernsteinProduct& p42 = space.prod(4, 2);
  const BernsteinProduct& p66 = space.prod(6, 6);
  const BernsteinProduct& p44 = space.prod(4, 4);
  const BernsteinProduct& p84 = space.prod(8, 4);
  // e3 = det D, q^3 and q p^2 (degree 6n): A, for the filter and the (q, p^2, e3) form.
  product(p22, {{1.0, &d_[0], &d_[1]}}, de_[0]);
  product(p22, {{1.0, &m_[3], &m_[4]}}, de_[1]);
  product(p22, {{1.0, &m_[5], &m_[5]}}, de_[2]);
  product(p22, {{1.0, &m_[4], &m_[4]}}, de_[3]);
  product(p22, {{1.0, &m_[3], &m_[3]}}, de_[4]);
  product(p42, {{1.0, &de_[0], &d_[2]}, {2.0, &de_[1], &m_[5]}, {-1.0, &de_[2], &d_[0]},
                {-1.0, &de_[3], &d_[1]}, {-1.0, &de_[4], &d_[2]}},
          e3_);
  product(p42, {{1.0, &q2_, &q_}}, q3_);
  product(space.prod(2, 4), {{1.0, &q_, &p2_}}, qp2_);
  // Degree-6n filter (soundness proof at certify_filter): the largest r it certifies is
  // a true lower bound; most subdomains stop here, before any degree-12n product.
  if (use_filter) {
    make_p_upper();
    product(p22, {{1.0, &pu_, &pu_}}, pu2_);
    product(p42, {{1.0, &pu2_, &pu_}}, pu3_);
    const double first = std::min(r_hi - 0.5 * tol_r, r_target);
    if (first > lo && first < 1) {
      if (certify_filter(first)) return first;
      double f_lo = lo, f_hi = first;
      for (int it = 0; it < 60 && f_hi - f_lo > 0.25 * tol_r; ++it) {
        const double mid = 0.5 * (f_lo + f_hi);
        (certify_filter(mid) ? f_lo : f_hi) = mid;
      }
      lo = f_lo;
      if (!(r_hi - lo > tol_r)) return lo;
    }
  }
  // Two exact forms of A and Pi_r: in (q, p^2, e3 = det D), whose terms are of the size of
  // the result near the ideal element (R near 1), and in the invariants of M
  // (I1 = tr M, I2 = sum of principal 2x2 minors, I3 = det M), whose terms are of the size
  // of the result near degeneracy (R near 0). The subdomain's upper bound picks one.
  invariant_form_ = r_hi < 0.25;
  if (!invariant_form_) {
    product(p44, {{1.0, &p2_, &p2_}}, p4_);
    product(p84, {{1.0, &p4_, &p2_}}, big_[3]);
    product(p66, {{1.0, &e3_, &e3_}}, big_[6]);
    // First try, directly as A^2 - X^2 (3 products of degree 12n instead of 7): most
    // subdomains only need to clear the target, and only those near the minimum bisect.
    const double first = std::min(r_hi - 0.5 * tol_r, r_target);
    if (first > lo && first < 1) {
      if (certify_direct(p66, first)) return first;
      r_hi = first;
    }
    product(p66, {{1.0, &q3_, &q3_}}, big_[0]);
    product(p44, {{1.0, &q2_, &p2_}}, q2p2_);
    product(p84, {{1.0, &q2p2_, &q2_}}, big_[1]);
    product(p84, {{1.0, &q2p2_, &p2_}}, big_[2]);
    product(p66, {{1.0, &q3_, &e3_}}, big_[4]);
    product(p66, {{1.0, &qp2_, &e3_}}, big_[5]);
  } else {
    Poly& i1 = q3_;   // reused buffers: I1 (2n), I2 (4n), I3 (6n), I1 I2 (6n)
    Poly& i2 = q2p2_;
    Poly& i3 = e3_;
    Poly& i1i2 = qp2_;
    combine({{1.0, &m_[0]}, {1.0, &m_[1]}, {1.0, &m_[2]}}, i1);
    product(p22, {{1.0, &m_[0], &m_[1]}, {-1.0, &m_[3], &m_[3]}, {1.0, &m_[0], &m_[2]},
                  {-1.0, &m_[4], &m_[4]}, {1.0, &m_[1], &m_[2]}, {-1.0, &m_[5], &m_[5]}},
            i2);
    // det M = m00 (m11 m22 - m12^2) - m01 (m01 m22 - m12 m02) + m02 (m01 m12 - m11 m02)
    product(p22, {{1.0, &m_[1], &m_[2]}, {-1.0, &m_[5], &m_[5]}}, de_[0]);
    product(p22, {{1.0, &m_[3], &m_[2]}, {-1.0, &m_[5], &m_[4]}}, de_[1]);
    product(p22, {{1.0, &m_[3], &m_[5]}, {-1.0, &m_[1], &m_[4]}}, de_[2]);
    product(p42, {{1.0, &de_[0], &m_[0]}, {-1.0, &de_[1], &m_[3]}, {1.0, &de_[2], &m_[4]}}, i3);
    product(space.prod(2, 4), {{1.0, &i1, &i2}}, i1i2);
    product(p66, {{1.0, &i3, &i3}}, big_[0]);
    product(p44, {{1.0, &i2, &i2}}, p4_);
    product(p84, {{1.0, &p4_, &i2}}, big_[1]);
    product(p66, {{1.0, &i1i2, &i3}}, big_[2]);
    product(p22, {{1.0, &i1, &i1}}, tmp_);
    product(p84, {{1.0, &p4_, &tmp_}}, big_[3]);
    product(p42, {{1.0, &tmp_, &i1}}, de_[3]);
    product(p66, {{1.0, &de_[3], &i3}}, big_[4]);
  }

  // One try at the target (the invariant form), then bisection below it.
  double hi = r_hi;
  if (invariant_form_) {
    const double first = std::min(r_hi - 0.5 * tol_r, r_target);
    if (first > lo && first < 1) {
      if (certify_3d(first)) return first;
      hi = first;
    }
  }
  for (int it = 0; it < 60 && hi - lo > tol_r; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid >= 1) break;
    (certify_3d(mid) ? lo : hi) = mid;
  }
  return lo;
}

void MuMetric::make_p_upper() {
  // p^2 = |V|^2 / 6 pointwise, V = (d0, d1, d2, sqrt2 m01, sqrt2 m02, sqrt2 m12) (degree 2n).
  // With V_i the exact control values of V, V(x) = sum_i B_i(x) V_i (B_i >= 0, sum 1), so
  // by the triangle inequality p(x) = |V(x)| / sqrt 6 <= sum_i B_i(x) |V_i| / sqrt 6:
  // the polynomial P with control values P_i >= |V_i| / sqrt 6 satisfies P >= p >= 0
  // (Paper V Lemma 6, here as a pointwise polynomial bound). P_i is formed from
  // |V_ki| <= |computed| + err, the sum inflated by 1e-13 (its ~12 roundings) and the
  // square root rounded up; P's control values are then exact by definition (err 0).
  const std::size_t n = d_[0].c.size();
  pu_.c.resize(n);
  const Poly* comp[6] = {&d_[0], &d_[1], &d_[2], &m_[3], &m_[4], &m_[5]};
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = 0; k < 6; ++k) {
      const double v = std::abs(comp[k]->c[i]) + comp[k]->err;
      sum += (k < 3 ? 1.0 : 2.0) * v * v;
    }
    pu_.c[i] = next_up(sqrt_rn(sum * (1 + 1e-13) / 6));
  }
  pu_.err = 0;
  pu_.mag = max_abs(pu_.c);
}

bool MuMetric::certify_filter(double r) {
  // Sufficient condition for R >= r of degree 6n. X^2 = (27/4) r^2 (r+1)^2 (4 p^6 - e3^2)
  // (mu_metric.hpp), and pointwise |e3| <= 2 p^3 (e3 = 2 p^3 cos 3theta, Paper V App. A).
  // With P >= p >= 0 (make_p_upper): a = 2 P^3 - e3 >= 0, b = 2 P^3 + e3 >= 0 and
  // 4 p^6 - e3^2 = (2p^3 - e3)(2p^3 + e3) <= a b. For any constant lambda > 0,
  // sqrt(a b) <= (lambda a + b / lambda) / 2 (AM-GM), so with k = sqrt(27) r (r+1) / 4
  //   X <= k (lambda a + b / lambda) = 2k (lambda + 1/lambda) P^3 + k (1/lambda - lambda) e3.
  // If A - (that) >= 0 everywhere then A >= X >= 0, A^2 >= X^2, Pi_r >= 0, hence R >= r
  // (exact equivalence of mu_metric.hpp). The polynomial is certified from its control
  // values (Prop. 5). The bound is pointwise exact where P = p and lambda = sqrt(b / a),
  // so lambda is taken there at the control value that binds most.
  const double s = 1 - r, t = r * r + r + 1, v = (r + 2) * (2 * r + 1);
  const double a0 = s * s * s, a1 = -3 * t * s, a2 = 0.5 * s * v;
  const double k = 1.299038105676658 * r * (r + 1);  // sqrt(27) / 4 within 1 ulp
  const std::size_t na = q3_.c.size();
  double lambda = 1, worst = kInf;
  for (std::size_t i = 0; i < na; ++i) {
    const double a = std::max(2 * pu3_.c[i] - e3_.c[i], 1e-300);
    const double b = std::max(2 * pu3_.c[i] + e3_.c[i], 1e-300);
    const double slack = a0 * q3_.c[i] + a1 * qp2_.c[i] + a2 * e3_.c[i] - 2 * k * sqrt_rn(a * b);
    if (slack < worst) worst = slack, lambda = sqrt_rn(b / a);
  }
  lambda = std::clamp(lambda, 1e-4, 1e4);
  const double c1 = 2 * k * (lambda + 1 / lambda);
  const double c2 = k * (1 / lambda - lambda);
  // Every coefficient within 1e-14 relative of its exact value, except c2 (cancellation in
  // 1/lambda - lambda): within 1e-14 k (lambda + 1/lambda) absolutely.
  const double m = std::abs(a0) * q3_.mag + std::abs(a1) * qp2_.mag + std::abs(a2) * e3_.mag +
                   c1 * pu3_.mag + std::abs(c2) * e3_.mag;
  const double err = (std::abs(a0) * (q3_.err + 1e-14 * q3_.mag) + std::abs(a1) * (qp2_.err + 1e-14 * qp2_.mag) +
                      std::abs(a2) * (e3_.err + 1e-14 * e3_.mag) + c1 * (pu3_.err + 1e-14 * pu3_.mag) +
                      std::abs(c2) * e3_.err + 1e-14 * k * (lambda + 1 / lambda) * e3_.mag +
                      rounding_gamma(8) * m) * kSlack;
  for (std::size_t i = 0; i < na; ++i)
    if (!(a0 * q3_.c[i] + a1 * qp2_.c[i] + a2 * e3_.c[i] - c1 * pu3_.c[i] - c2 * e3_.c[i] >= err))
      return false;
  return true;
}

bool MuMetric::certify_direct(const BernsteinProduct& p66, double r) {
  // A = s^3 q^3 - 3 t s q p^2 + s v e3 / 2 (6n), then Pi = A^2 - c (4 p^6 - e3^2) with
  // c = (27/4) r^2 (r+1)^2 (mu_metric.hpp).
  const double s = 1 - r, t = r * r + r + 1, v = (r + 2) * (2 * r + 1);
  const double a0 = s * s * s, a1 = -3 * t * s, a2 = 0.5 * s * v;
  const std::size_t na = q3_.c.size();
  a_.c.resize(na);
  for (std::size_t i = 0; i < na; ++i) a_.c[i] = a0 * q3_.c[i] + a1 * qp2_.c[i] + a2 * e3_.c[i];
  const double m = std::abs(a0) * q3_.mag + std::abs(a1) * qp2_.mag + std::abs(a2) * e3_.mag;
  a_.err = (std::abs(a0) * (q3_.err + 1e-14 * q3_.mag) + std::abs(a1) * (qp2_.err + 1e-14 * qp2_.mag) +
            std::abs(a2) * (e3_.err + 1e-14 * e3_.mag) + rounding_gamma(5) * m) * kSlack;
  a_.mag = max_abs(a_.c);
  for (double x : a_.c)
    if (!(x >= a_.err)) return false;
  product(p66, {{1.0, &a_, &a_}}, tmp_);
  const double c = 6.75 * r * r * (r + 1) * (r + 1);
  const Poly& p6 = big_[3];
  const Poly& e6 = big_[6];
  const double err = (tmp_.err + c * (4 * (p6.err + 1e-14 * p6.mag) + e6.err + 1e-14 * e6.mag) +
                      rounding_gamma(5) * (tmp_.mag + c * (4 * p6.mag + e6.mag))) * kSlack;
  for (std::size_t i = 0; i < tmp_.c.size(); ++i)
    if (!(tmp_.c[i] - c * (4 * p6.c[i] - e6.c[i]) >= err)) return false;
  return true;
}

bool MuMetric::certify_3d(double r) {
  // Coefficients of A and Pi_r in the chosen form (mu_metric.hpp; exact identities checked
  // by the tests against C_- = (l2 - r l1)(l3 - r l2)(l1 - r l3)). All factors are positive
  // for r in [0, 1), so each coefficient is within 1e-14 relative of its exact value.
  const double s = 1 - r, t = r * r + r + 1, v = (r + 2) * (2 * r + 1);
  const double s2 = s * s, s3 = s2 * s, s4 = s2 * s2;
  double a_coef[3], g[7];
  const Poly* a_poly[3];
  const Poly* b_poly[7];
  int na_terms, nb_terms;
  if (!invariant_form_) {
    // A = u^3 - 3 t u p^2 + s v e3 / 2, u = s q; Pi = A^2 - (27/4) r^2 (r+1)^2 (4 p^6 - e3^2).
    a_coef[0] = s3, a_coef[1] = -3 * t * s, a_coef[2] = 0.5 * s * v;
    a_poly[0] = &q3_, a_poly[1] = &qp2_, a_poly[2] = &e3_;
    na_terms = 3;
    const double gv[7] = {s3 * s3, -6 * t * s4, 9 * t * t * s2, -27 * r * r * (r + 1) * (r + 1),
                          s4 * v, -3 * s2 * v * t, t * t * t};
    std::copy(gv, gv + 7, g);
    for (int m = 0; m < 7; ++m) b_poly[m] = &big_[m];
    nb_terms = 7;
  } else {
    // A = s v I3 / 2 - r s I1 I2 / 2;
    // Pi = t^3 I3^2 + r^2 (r+1)^2 I2^3 - r t (r^2 + 4r + 1) I1 I2 I3 - r^3 I1^2 I2^2
    //      + r^2 (r+1)^2 I1^3 I3.
    a_coef[0] = 0.5 * s * v, a_coef[1] = -0.5 * r * s;
    a_poly[0] = &e3_, a_poly[1] = &qp2_;
    na_terms = 2;
    const double rr = r * r * (r + 1) * (r + 1);
    const double gv[5] = {t * t * t, rr, -r * t * (r * r + 4 * r + 1), -r * r * r, rr};
    std::copy(gv, gv + 5, g);
    for (int m = 0; m < 5; ++m) b_poly[m] = &big_[m];
    nb_terms = 5;
  }
  const auto bound = [](const double* coef, const Poly* const* polys, int k) {
    double e = 0, m = 0;
    for (int i = 0; i < k; ++i) {
      e += std::abs(coef[i]) * (polys[i]->err + 1e-14 * polys[i]->mag);
      m += std::abs(coef[i]) * polys[i]->mag;
    }
    return (e + rounding_gamma(k + 2) * m) * kSlack;
  };
  const double err_a = bound(a_coef, a_poly, na_terms);
  const std::size_t na = a_poly[0]->c.size();
  for (std::size_t i = 0; i < na; ++i) {
    double a = 0;
    for (int m = 0; m < na_terms; ++m) a += a_coef[m] * a_poly[m]->c[i];
    if (!(a >= err_a)) return false;
  }
  const double err_pi = bound(g, b_poly, nb_terms);
  const std::size_t nb = b_poly[0]->c.size();
  for (std::size_t i = 0; i < nb; ++i) {
    double x = 0;
    for (int m = 0; m < nb_terms; ++m) x += g[m] * b_poly[m]->c[i];
    if (!(x >= err_pi)) return false;
  }
  return true;
}

namespace {

// Upper bound of R at one corner: W (3 x D, fixed size: no allocation per corner), with
// the approximate eigenvectors `given` (D x D, column-major, ascending) or its own.
template <int D>
double corner_upper(const Eigen::Matrix<double, 3, D>& wm, double err, const double* given) {
  // Closed-form eigenvectors: any v gives a valid Rayleigh bound, accuracy only matters
  // for tightness (the quotient's error is quadratic in v's).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig;
  Eigen::Matrix<double, D, D> vectors;
  if (given != nullptr) {
    vectors = Eigen::Map<const Eigen::Matrix<double, D, D>>(given);
  } else {
    const Eigen::Matrix<double, D, D> m = wm.transpose() * wm;
    if (!m.allFinite()) return 1;
    eig.computeDirect(m);
    vectors = eig.eigenvectors();
  }
  if (!vectors.allFinite() || !wm.allFinite()) return 1;
  // Rayleigh quotient |W v|^2 / |v|^2, enclosed: y_c = sum_j w_cj v_j within
  // err sum|v| + gamma_4 sum |w_cj v_j| (+1e-12 relative for the bound's own rounding).
  const auto rayleigh = [&](const Eigen::Matrix<double, D, 1>& v, bool upper) {
    double y2 = 0, v2 = 0, vsum = 0;
    for (int j = 0; j < D; ++j) {
      v2 += v(j) * v(j);
      vsum += std::abs(v(j));
    }
    for (int c = 0; c < 3; ++c) {
      double y = 0, mag = 0;
      for (int j = 0; j < D; ++j) {
        y += wm(c, j) * v(j);
        mag += std::abs(wm(c, j) * v(j));
      }
      const double rad = (err * vsum + rounding_gamma(4) * mag) * kSlack;
      const double e = upper ? std::abs(y) + rad : std::max(0.0, std::abs(y) - rad);
      y2 += e * e;
    }
    // Sums of squares and the quotient: relative error <= gamma_6 each.
    const double g = rounding_gamma(6) * kSlack;
    return upper ? y2 * (1 + g) / (v2 * (1 - g)) * (1 + g) : y2 * (1 - g) / (v2 * (1 + g)) * (1 - g);
  };
  const double lmin_hi = rayleigh(vectors.col(0), true);
  const double lmax_lo = rayleigh(vectors.col(D - 1), false);
  if (!(lmax_lo > 0) || !std::isfinite(lmin_hi)) return 1;
  return next_up(lmin_hi / lmax_lo);
}

}  // namespace

std::array<double, 9> corner_w(const MuSpace& space, const double* w, int k) {
  const auto ws = static_cast<std::size_t>(space.w_size());
  std::array<double, 9> out{};
  for (int j = 0; j < space.dim(); ++j)
    for (int c = 0; c < 3; ++c)
      out[static_cast<std::size_t>(j * 3 + c)] = w[(static_cast<std::size_t>(j) * 3 + static_cast<std::size_t>(c)) * ws + static_cast<std::size_t>(k)];
  return out;
}

void remember_corners(const MuSpace& space, const double* w, std::vector<std::array<double, 9>>& seen) {
  for (const int k : space.w_basis().vertex_indices()) seen.push_back(corner_w(space, w, k));
}

CornerMetric corner_metric(const std::array<double, 9>& w, int dim, double err) {
  static constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  static constexpr int kPairs2[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  CornerMetric out;
  const int n = dim == 2 ? 3 : 6;
  for (int e = 0; e < n; ++e) {
    const int i = dim == 2 ? kPairs2[e][0] : kPairs[e][0];
    const int j = dim == 2 ? kPairs2[e][1] : kPairs[e][1];
    double sum = 0, mag = 0, prop = 0;
    for (int c = 0; c < 3; ++c) {
      const double a = w[static_cast<std::size_t>(i * 3 + c)], b = w[static_cast<std::size_t>(j * 3 + c)];
      sum += a * b;
      mag += std::abs(a * b);
      prop += (std::abs(a) + std::abs(b) + err) * err;
    }
    out.m[static_cast<std::size_t>(e)] = sum;
    out.err = std::max(out.err, (prop + rounding_gamma(4) * mag) * (1 + 1e-12));
  }
  return out;
}

namespace {

// A cheap estimate of R at a corner (not certified: it only orders the corners, so that
// the least bound is usually found first): det M / (tr M / dim)^dim, 1 for isotropic M.
double corner_estimate(const CornerMetric& cm, int dim) {
  const auto& m = cm.m;
  if (dim == 3) return ratio_estimate3(m.data());
  const double t = 0.5 * (m[0] + m[1]);
  return (m[0] * m[1] - m[2] * m[2]) / (t * t);
}

// 2D: the closed form q +- sqrt(s^2 + t^2) of corner k's metric cm, enclosed, instead of
// an eigen solve and Rayleigh quotients (quadval_bench, one thread, mu, 6 x 3 interleaved
// runs, medians: plate_tri_h0.05 93.1 -> 89.8 ms, plate_quad_h0.08 16.3 -> 15.4 ms). Its
// error is a few ulps of lambda_max, so relative to a small R it grows (mu 9e-4: 1.4e-9
// wider); below R = 1e-2 the Rayleigh quotients, whose error scales with
// sqrt(lambda_min lambda_max), are taken too.
double planar_corner_upper(const MuSpace& space, const double* w, double err, int k, const CornerMetric& cm) {
  const double closed = symmetric_eigen_enclosure<2>(cm.m.data(), cm.err).ratio_upper();
  if (closed >= 1e-2) return closed;
  return std::min(closed, corner_upper<2>(w_at<2>(space, w, k), err, nullptr));
}

}  // namespace

double corner_ratio_upper(const MuSpace& space, const double* w, double err,
                          std::vector<std::array<double, 9>>* seen, double below) {
  const int dim = space.dim();
  struct Corner {
    int k;
    double estimate;
    CornerMetric metric;
  };
  thread_local std::vector<Corner> corners;
  corners.clear();
  for (const int k : space.w_basis().vertex_indices()) {
    const std::array<double, 9> key = corner_w(space, w, k);
    if (seen) {
      if (std::find(seen->begin(), seen->end(), key) != seen->end()) continue;
      seen->push_back(key);
    }
    const CornerMetric cm = corner_metric(key, dim, err);
    const double estimate = corner_estimate(cm, dim);
    corners.push_back({k, std::isnan(estimate) ? -1.0 : estimate, cm});
  }
  // Stable insertion sort (std::stable_sort's order): a few corners, no buffer.
  for (std::size_t i = 1; i < corners.size(); ++i)
    for (std::size_t j = i; j > 0 && corners[j].estimate < corners[j - 1].estimate; --j)
      std::swap(corners[j], corners[j - 1]);
  double best = below;
  for (const Corner& c : corners) {
    if (best < 1 && (dim == 2 ? ratio_at_least2(c.metric.m.data(), c.metric.err, best)
                              : ratio_at_least3(c.metric.m.data(), c.metric.err, best)))
      continue;  // R >= best here: its bound would not lower best
    best = std::min(best, dim == 2 ? planar_corner_upper(space, w, err, c.k, c.metric)
                                   : corner_ratio_upper_at(space, w, err, c.k));
  }
  return best;
}

double corner_ratio_upper_at(const MuSpace& space, const double* w, double err, int k,
                             const double* eigenvectors) {
  if (space.dim() == 2 && eigenvectors == nullptr)
    return planar_corner_upper(space, w, err, k, corner_metric(corner_w(space, w, k), 2, err));
  if (space.dim() == 2) return corner_upper<2>(w_at<2>(space, w, k), err, eigenvectors);
  return corner_upper<3>(w_at<3>(space, w, k), err, eigenvectors);
}

}  // namespace quadval
