#pragma once
// Certified bounds of R = lambda_min / lambda_max of the metric M = W^T W on one
// subdomain, from the Bézier control values of the entries of W (thesis, Paper V §3-5).
// Internal to src/analysis; used by mu_bounds.cpp.
//
// 2D (Paper V §4). lambda_+- = q +- sqrt(s^2 + t^2) with q = (|w0|^2 + |w1|^2) / 2,
// s = (|w0|^2 - |w1|^2) / 2, t = w0 . w1, so R = (a - 1) / (a + 1) with
// a^2 = q^2 / (s^2 + t^2). A lower bound rho of a^2 from the control values of q^2 and
// s^2 + t^2 (degree 4n, Prop. 4; rational bound of §3.1) gives R >= (sqrt rho - 1) /
// (sqrt rho + 1), i.e. the certificate (1 - r)^2 q^2 - (1 + r)^2 (s^2 + t^2) >= 0.
//
// 3D. With D = M - q I (q = tr M / 3, eigenvalues mu_i = lambda_i - q), p^2 = tr D^2 / 6
// (Paper V App. A) and e3 = det D, the two "cyclic" products
//   C_+- = A +- X,  A = u^3 - 3 (r^2 + r + 1) u p^2 + (1 - r)(r + 2)(2r + 1) e3 / 2,
//   u = (1 - r) q,  X^2 = (27/4) r^2 (r + 1)^2 (4 p^6 - e3^2) >= 0,
// are (lambda_2 - r lambda_1)(lambda_3 - r lambda_2)(lambda_1 - r lambda_3) (minus) and
// (lambda_1 - r lambda_2)(lambda_2 - r lambda_3)(lambda_3 - r lambda_1) (plus), with the
// eigenvalues sorted. The first two factors of C_- are positive, so for 0 <= r < 1
//   R >= r  <=>  C_- >= 0  <=>  A >= 0 and Pi_r := A^2 - X^2 >= 0
// (C_+ C_- = Pi_r = prod_{i != j} (lambda_i - r lambda_j)). A has degree 6n and Pi_r
// degree 12n; both are certified nonnegative from their control values (Prop. 5), Pi_r as
// a combination of seven fixed products q^6, q^4 p^2, q^2 p^4, p^6, q^3 e3, q p^2 e3, e3^2,
// and r is maximised by bisection. Near degeneracy (R small) the same A and Pi_r are
// formed in the invariants I1 = tr M, I2, I3 = det M instead, whose terms there are of the
// size of the result (q^6 would swamp lambda_min):
//   A  = (1 - r)(r + 2)(2r + 1) I3 / 2 - r (1 - r) I1 I2 / 2,
//   Pi = (r^2+r+1)^3 I3^2 + r^2 (r+1)^2 (I2^3 + I1^3 I3) - r (r^2+r+1)(r^2+4r+1) I1 I2 I3
//        - r^3 I1^2 I2^2. This replaces the (a, K) bounding box and bounding curve
// of Paper V §5-6 by an exact pointwise equivalence (no Newton step, no closed form of R):
// the bound converges like the control values (quadratically in the subdomain size) and
// has no cancellation near the ideal element (D is formed before any product).
//
// Rounding: every control value carries a uniform absolute error bound (W from mu_space,
// Bernstein products from bernstein_product.hpp, sums with gamma_k), and a test "c >= 0"
// passes only when the computed value exceeds its error bound.
#include <array>
#include <vector>

#include "analysis/mu_space.hpp"

namespace quadval {

/// Tests only: switch the degree-6n filter of MuMetric::lower_bound off (on by default) in
/// the calling thread, to compare its bounds with those of the exact certificate alone.
void mu_use_filter(bool on) noexcept;

/// Scratch of the per-subdomain bounds; one per thread, reused.
class MuMetric {
 public:
  /// Certified lower bound of min R over the subdomain.
  /// @param w     dim columns x 3 components x w_size() control values of W
  ///              (w[(j * 3 + c) * w_size + k])
  /// @param err   |w - exact| <= err for every control value
  /// @param r_lo  a known lower bound (e.g. the parent's), 0 if none
  /// @param r_hi  a known upper bound of min R over the subdomain (e.g. corner values)
  /// @param r_target  a value that suffices: once certified, no bisection above it
  /// @param tol_r stop the 3D bisection once the bracket is this narrow
  /// @pre space.has_certificate()
  double lower_bound(const MuSpace& space, const double* w, double err, double r_lo,
                     double r_hi, double r_target, double tol_r);

  /// Certified lower bound of min R over the subdomain from the control matrices of
  /// M = W^T W alone (degree 2n; mu_control_bound.hpp): one product and one small
  /// eigenvalue enclosure per control matrix. Same parameters as lower_bound; `enough`
  /// as for control_ratio_lower (the result is at most it).
  double control_lower_bound(const MuSpace& space, const double* w, double err, double enough = 1);

  /// The control values of M = W^T W's entries (degree 2n, space.size(2) each), in the
  /// order m00, m11, (m22,) m01, (m02, m12), written to `out` one entry after the other.
  /// @return a bound on |out - exact| for every value
  double metric(const MuSpace& space, const double* w, double err, double* out);

 private:
  struct Poly {
    std::vector<double> c;
    double err = 0;  // |c - exact| <= err
    double mag = 0;  // max |c|
  };
  void product(const BernsteinProduct& table,
               std::initializer_list<std::tuple<double, const Poly*, const Poly*>> terms, Poly& out);
  // out.err and out.mag of a sum of products of `table` already in out.c.
  static void bound_product(const BernsteinProduct& table,
                            std::initializer_list<std::tuple<double, const Poly*, const Poly*>> terms, Poly& out);
  void metric_entries(const MuSpace& space, const double* w, double err);
  bool certify_3d(double r);
  bool certify_direct(const BernsteinProduct& p66, double r);
  // Degree-6n sufficient test A - sqrt(27) r (r+1) P^3 >= 0, P >= p (make_p_upper).
  void make_p_upper();
  bool certify_filter(double r);

  Poly a_, w_[9], m_[6], q_, d_[3], s_, t_, q2_, p2_, n2_, de_[5], e3_, q3_, qp2_, q2p2_, p4_, tmp_;
  Poly pu_, pu2_, pu3_;  // P >= p (degree 2n), P^2, P^3
  // q^6, q^4 p^2, q^2 p^4, p^6, q^3 e3, q p^2 e3, e3^2; or (invariant form)
  // I3^2, I2^3, I1 I2 I3, I1^2 I2^2, I1^3 I3
  Poly big_[7];
  bool invariant_form_ = false;
  std::vector<double> comb_;
};

/// Entries of M = W^T W per dimension: 3 in 2D, 6 in 3D.
constexpr int metric_vectors(int dim) noexcept { return dim == 2 ? 3 : 6; }

/// control_lower_bound from M's control values in MuMetric::metric's layout (size values
/// per entry, all within err of the exact ones): a subdivided subdomain's M comes from its
/// parent's by the same bisection as W, without products.
double control_lower_bound_of_metric(int dim, const double* m, double err, int size, double enough = 1);

/// Certified upper bound of R at the subdomain's corners (the vertex control values of W
/// are values of W): the Rayleigh quotients of W at approximate eigenvectors of W^T W,
/// evaluated in interval fashion, bound lambda_min from above and lambda_max from below
/// (2D: the closed-form enclosure of the corner's metric W^T W, with the quotients too
/// where that bound is below 1e-2). Returns min over the corners (<= 1).
/// @param seen  optional: the W values (dim x 3, as laid out per corner) of corners already
///              bounded with an error bound at most `err`; a corner whose W equals one of
///              them bit for bit is skipped (its bound could only be the same or looser),
///              and every corner not seen before is appended (also one skipped for
///              `below`: its R stays above every later, smaller bound). Subdivision
///              children share most corners with their parent and their siblings (a
///              hexahedron's 8 children: 64 corners, 27 points, 8 of them the parent's).
/// @param below  the result is at most this (an upper bound known already); a corner
///               whose R is certified to be at least the least bound so far
///               (ratio_at_least2/3 of mu_control_bound.hpp, on its metric) is not bounded,
///               as its bound could not lower the result: the same value as bounding every
///               corner, with a fraction of the eigen solves.
double corner_ratio_upper(const MuSpace& space, const double* w, double err,
                          std::vector<std::array<double, 9>>* seen = nullptr, double below = 1);
/// The same bound at one control point k of W (a corner: a value of R at a point of the
/// subdomain, so an upper bound of its minimum on its own).
/// @param eigenvectors  optional: approximate eigenvectors of the corner's metric (dim x dim,
///                      column-major, eigenvalues ascending) to use instead of solving for
///                      them; any vectors give a true bound, only its tightness depends on them
double corner_ratio_upper_at(const MuSpace& space, const double* w, double err, int k,
                             const double* eigenvectors = nullptr);
/// W at control point k (a corner when k is a vertex index): entries j * 3 + c for column
/// j and coordinate c, zero beyond dim.
std::array<double, 9> corner_w(const MuSpace& space, const double* w, int k);
/// The metric W^T W of such a W in control_ratio_lower's entry order (m00, m11, (m22,) m01,
/// (m02, m12)), and a bound on its distance to the exact metric of every W within err
/// entrywise: |W'^T W' - W^T W|_ij <= sum_c (|w_ci| + |w_cj| + err) err, plus gamma_4 of
/// sum_c |w_ci w_cj| for the computed sums (and 1e-12 relative for the bound's own rounding).
struct CornerMetric {
  std::array<double, 6> m{};
  double err = 0;
};
CornerMetric corner_metric(const std::array<double, 9>& w, int dim, double err);
/// Appends the W values of the subdomain's corners to `seen` (corner_ratio_upper's layout).
void remember_corners(const MuSpace& space, const double* w, std::vector<std::array<double, 9>>& seen);

}  // namespace quadval
