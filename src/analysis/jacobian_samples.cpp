// Batched Jacobian samples with a priori rounding-error bounds (Paper III §4.4; the
// bound follows Higham, Accuracy and Stability of Numerical Algorithms, §3.1).
//
// Error model, per element (u = 2^-53, N nodes, Gamma = max row sum of |gradient|,
// eps_G the gradient entries' relative error, R = max |x_i - x_0| over nodes and axes):
//   each derivative d = sum_i g_i (x_i - x_0) is computed within
//     delta = (eps_G + 2u + gamma_N) Gamma R        (coordinates differenced: u each)
//   and |d| <= D = (1 + eps_G + 2u + gamma_N) Gamma R;
//   3D: |det(computed) - det(exact)| <= 18 delta D^2 + 6 gamma_6 D^3
//       (6 triple products, each perturbed by <= 3 delta D^2; cofactor evaluation)
//   2D: J = n . (a x b), |n_i| <= 1: <= 12 delta D + 6 gamma_6 D^2
//   1D: J = t . a, |t_i| <= 1:       <= 3 delta + 3 gamma_4 D
// The tight variant uses, per sample, the computed magnitudes plus their own error bounds
// (a^ = |a~| + delta_j per coordinate j, delta_j = (eps_G + 2u + gamma_N) Gamma R_j):
//   3D: sum over the 6 terms a_j b_k c_l of (delta_j b^_k c^_l + a^_j delta_k c^_l +
//       a^_j b^_k delta_l) + gamma_6 perm(a^, b^, c^);  2D and 1D likewise with |n_i|, |t_j|.
// Each bound is multiplied by 1.01, which covers the rounding of the bound itself.
// Subtracting x_0 is exact in the definition (the gradients of a partition of unity sum
// to zero), and keeps R the element's size, not its distance to the origin.
#include "analysis/jacobian_samples.hpp"

#include <cstddef>
#include <algorithm>
#include <cmath>

#include "analysis/sqrt_rn.hpp"
#include "quadval/error.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;

std::array<double, 3> sub(const double* a, const double* b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
std::array<double, 3> cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::array<double, 3> unit(const std::array<double, 3>& v) {
  const double n = sqrt_rn(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(n > 0) || !std::isfinite(n)) return {0, 0, 0};
  return {v[0] / n, v[1] / n, v[2] / n};
}

}  // namespace

std::array<double, 3> reference_direction(const ElementType& type, const double* x,
                                          bool planar) noexcept {
  switch (type.family) {
    case ElementFamily::line: return unit(sub(x + 3, x));
    case ElementFamily::triangle:
      return planar ? std::array<double, 3>{0, 0, 1} : unit(cross(sub(x + 3, x), sub(x + 6, x)));
    case ElementFamily::quadrangle:
      return planar ? std::array<double, 3>{0, 0, 1}
                    : unit(cross(sub(x + 6, x), sub(x + 9, x + 3)));
    default: return {0, 0, 0};
  }
}

void jacobian_samples(const JacobianSpace& space, SampleMap map, const double* nodes,
                      std::size_t count, bool planar, double* samples, double* errors,
                      SampleScratch& scratch, bool tight) {
  if (!space.has_sample_gradients()) {
    // Values of the Bézier form at the points: V has nonnegative rows summing to 1, so a
    // value errs by at most the coefficients' error plus V's rounding of max|coefficient|.
    const BezierBasis& basis = space.basis();
    const auto s = static_cast<std::size_t>(basis.size());
    scratch.coeffs.resize(s * count);
    space.product()->coefficients(map, nodes, count, planar, scratch.coeffs.data(), errors,
                                  scratch.product);
    scratch.transposed.resize(s * count);
    for (std::size_t e = 0; e < count; ++e)
      for (std::size_t k = 0; k < s; ++k) scratch.transposed[k * count + e] = scratch.coeffs[e * s + k];
    scratch.scratch.resize(2 * s * count);
    basis.from_bezier_batch(scratch.transposed.data(), count, scratch.coeffs.data(), scratch.scratch.data());
    for (std::size_t e = 0; e < count; ++e) {
      double big = 0;
      for (std::size_t k = 0; k < s; ++k) {
        samples[e * s + k] = scratch.coeffs[k * count + e];
        big = std::max(big, std::abs(scratch.transposed[k * count + e]));
      }
      errors[e] = (errors[e] * (1 + 4 * kUnit) + basis.from_bezier_rounding() * big) * 1.01;
    }
    return;
  }
  const bool straight = map == SampleMap::straight;
  const int dim = space.dim();
  const auto n_used = static_cast<std::ptrdiff_t>(straight ? space.num_vertices() : space.num_nodes());
  const std::size_t stride = static_cast<std::size_t>(space.num_nodes()) * 3;
  const auto s = static_cast<std::ptrdiff_t>(space.num_samples());
  const auto cols = static_cast<std::ptrdiff_t>(3 * count);
  const double gamma = straight ? space.straight_row_sum() : space.gradient_row_sum();
  const double eps_g = straight ? space.straight_rel_error() : space.gradient_rel_error();

  // coords: #nodes x (3 * count), row-major: node i of element e, axis j at
  // [i * cols + 3 e + j], relative to the element's first node.
  const auto ucols = static_cast<std::size_t>(cols);
  const auto un = static_cast<std::size_t>(n_used);
  const auto us = static_cast<std::size_t>(s);
  scratch.coords.resize(un * ucols);
  double* x = scratch.coords.data();
  std::vector<double> range(count, 0.0);
  std::vector<std::array<double, 3>> axis_range(count, {0, 0, 0});
  for (std::size_t e = 0; e < count; ++e) {
    const double* xe = nodes + e * stride;
    double r = 0;
    for (std::size_t i = 0; i < un; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double d = xe[3 * i + j] - xe[j];
        x[i * ucols + 3 * e + j] = d;
        r = std::max(r, std::abs(d));
        axis_range[e][j] = std::max(axis_range[e][j], std::abs(d));
      }
    range[e] = r;
  }
  // deriv[c] = G_c (S x N) * coords (N x 3count): a plain loop, so that the summation
  // order is fixed (no library threading or blocking that could vary between runs).
  for (int c = 0; c < dim; ++c) {
    const double* g = (straight ? space.straight_gradient(c) : space.gradient(c)).data();
    scratch.deriv[c].assign(us * ucols, 0.0);
    double* d = scratch.deriv[c].data();
    for (std::size_t k = 0; k < us; ++k) {
      double* dk = d + k * ucols;
      for (std::size_t i = 0; i < un; ++i) {
        const double w = g[k * un + i];
        if (w == 0) continue;
        const double* xi = x + i * ucols;
        for (std::size_t col = 0; col < ucols; ++col) dk[col] += w * xi[col];
      }
    }
  }

  const double eps_d = eps_g + 2 * kUnit + rounding_gamma(static_cast<int>(n_used));
  const double g6 = rounding_gamma(6);
  for (std::size_t e = 0; e < count; ++e) {
    const double* xe = nodes + e * stride;
    const double delta = eps_d * gamma * range[e] * (1 + 1e-10);
    const double big_d = (1 + eps_d) * gamma * range[e] * (1 + 1e-10);
    double* out = samples + e * static_cast<std::size_t>(s);
    const auto col = static_cast<std::size_t>(3 * e);
    const auto at = [&](int c, std::ptrdiff_t k, std::size_t j) {
      return scratch.deriv[c][static_cast<std::size_t>(k) * ucols + col + j];
    };
    if (tight) {
      std::array<double, 3> dj;
      for (std::size_t j = 0; j < 3; ++j) dj[j] = eps_d * gamma * axis_range[e][j] * (1 + 1e-10);
      const auto hat = [&](int c, std::ptrdiff_t k, std::size_t j) { return std::abs(at(c, k, j)) + dj[j]; };
      static constexpr int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};
      const auto ref = reference_direction(space.type(), xe, planar);
      double worst = 0;
      for (std::ptrdiff_t k = 0; k < s; ++k) {
        double pert = 0, perm = 0;
        if (dim == 3) {
          for (const auto& p : kPerm) {
            const auto j0 = static_cast<std::size_t>(p[0]), j1 = static_cast<std::size_t>(p[1]), j2 = static_cast<std::size_t>(p[2]);
            const double a = hat(0, k, j0), b = hat(1, k, j1), c = hat(2, k, j2);
            pert += dj[j0] * b * c + a * dj[j1] * c + a * b * dj[j2];
            perm += a * b * c;
          }
        } else if (dim == 2) {
          for (const auto& p : kPerm) {  // n_i a_j b_k
            const auto i = static_cast<std::size_t>(p[0]), j1 = static_cast<std::size_t>(p[1]), j2 = static_cast<std::size_t>(p[2]);
            const double ni = std::abs(ref[i]), a = hat(0, k, j1), b = hat(1, k, j2);
            pert += ni * (dj[j1] * b + a * dj[j2]);
            perm += ni * a * b;
          }
        } else {
          for (std::size_t j = 0; j < 3; ++j) {
            pert += std::abs(ref[j]) * dj[j];
            perm += std::abs(ref[j]) * hat(0, k, j);
          }
        }
        worst = std::max(worst, pert + g6 * perm);
      }
      errors[e] = worst * 1.01;
    }
    if (dim == 3) {
      for (std::ptrdiff_t k = 0; k < s; ++k) {
        const double a0 = at(0, k, 0), a1 = at(0, k, 1), a2 = at(0, k, 2);
        const double b0 = at(1, k, 0), b1 = at(1, k, 1), b2 = at(1, k, 2);
        const double c0 = at(2, k, 0), c1 = at(2, k, 1), c2 = at(2, k, 2);
        out[k] = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0);
      }
      if (!tight) errors[e] = (18 * delta * big_d * big_d + 6 * g6 * big_d * big_d * big_d) * 1.01;
    } else if (dim == 2) {
      const auto n = reference_direction(space.type(), xe, planar);
      for (std::ptrdiff_t k = 0; k < s; ++k) {
        const double a0 = at(0, k, 0), a1 = at(0, k, 1), a2 = at(0, k, 2);
        const double b0 = at(1, k, 0), b1 = at(1, k, 1), b2 = at(1, k, 2);
        out[k] = n[0] * (a1 * b2 - a2 * b1) + n[1] * (a2 * b0 - a0 * b2) + n[2] * (a0 * b1 - a1 * b0);
      }
      if (!tight) errors[e] = (12 * delta * big_d + 6 * g6 * big_d * big_d) * 1.01;
    } else {
      const auto t = reference_direction(space.type(), xe, planar);
      for (std::ptrdiff_t k = 0; k < s; ++k)
        out[k] = t[0] * at(0, k, 0) + t[1] * at(0, k, 1) + t[2] * at(0, k, 2);
      if (!tight) errors[e] = (3 * delta + 3 * rounding_gamma(4) * big_d) * 1.01;
    }
  }
}

std::vector<mpq_class> exact_jacobian_samples(const JacobianSpace& space, const double* nodes,
                                              bool planar) {
  QV_ASSERT(space.has_sample_gradients(), "no sample gradients for " << space.type().name);
  const int dim = space.dim();
  const auto n = static_cast<std::size_t>(space.num_nodes());
  const auto s = static_cast<std::size_t>(space.num_samples());
  std::vector<std::array<mpq_class, 3>> x(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < 3; ++j) x[i][j] = mpq_class(nodes[3 * i + j]);
  std::array<mpq_class, 3> ref;
  const auto r = reference_direction(space.type(), nodes, planar);
  for (std::size_t j = 0; j < 3; ++j) ref[j] = mpq_class(r[j]);
  std::vector<mpq_class> out(s);
  std::array<std::array<mpq_class, 3>, 3> d;
  for (std::size_t k = 0; k < s; ++k) {
    for (int c = 0; c < dim; ++c) {
      const auto& g = space.exact_gradient(c);
      for (std::size_t j = 0; j < 3; ++j) {
        mpq_class sum = 0;
        for (std::size_t i = 0; i < n; ++i)
          if (sgn(g[k * n + i]) != 0) sum += g[k * n + i] * x[i][j];
        d[static_cast<std::size_t>(c)][j] = sum;
      }
    }
    const auto& a = d[0];
    const auto& b = d[1];
    const auto& c = d[2];
    if (dim == 3) {
      out[k] = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    } else if (dim == 2) {
      out[k] = ref[0] * (a[1] * b[2] - a[2] * b[1]) + ref[1] * (a[2] * b[0] - a[0] * b[2]) +
               ref[2] * (a[0] * b[1] - a[1] * b[0]);
    } else {
      out[k] = ref[0] * a[0] + ref[1] * a[1] + ref[2] * a[2];
    }
  }
  return out;
}

}  // namespace quadval
