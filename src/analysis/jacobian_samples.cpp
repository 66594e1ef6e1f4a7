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
// Each bound is multiplied by 1.01, which covers the rounding of the bound itself.
// Subtracting x_0 is exact in the definition (the gradients of a partition of unity sum
// to zero), and keeps R the element's size, not its distance to the origin.
#include "analysis/jacobian_samples.hpp"

#include <Eigen/Core>
#include <cmath>

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
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
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
                      SampleScratch& scratch) {
  const bool straight = map == SampleMap::straight;
  const int dim = space.dim();
  const auto n_used = static_cast<Eigen::Index>(straight ? space.num_vertices() : space.num_nodes());
  const std::size_t stride = static_cast<std::size_t>(space.num_nodes()) * 3;
  const auto s = static_cast<Eigen::Index>(space.num_samples());
  const auto cols = static_cast<Eigen::Index>(3 * count);
  const double gamma = straight ? space.straight_row_sum() : space.gradient_row_sum();
  const double eps_g = straight ? space.straight_rel_error() : space.gradient_rel_error();

  scratch.coords.resize(static_cast<std::size_t>(n_used * cols));
  Eigen::Map<Eigen::MatrixXd> x(scratch.coords.data(), n_used, cols);
  std::vector<double> range(count, 0.0);
  for (std::size_t e = 0; e < count; ++e) {
    const double* xe = nodes + e * stride;
    double r = 0;
    for (Eigen::Index i = 0; i < n_used; ++i)
      for (int j = 0; j < 3; ++j) {
        const double d = xe[3 * i + j] - xe[j];
        x(i, static_cast<Eigen::Index>(3 * e) + j) = d;
        r = std::max(r, std::abs(d));
      }
    range[e] = r;
  }
  for (int c = 0; c < dim; ++c) {
    const auto& g = straight ? space.straight_gradient(c) : space.gradient(c);
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        gm(g.data(), s, n_used);
    scratch.deriv[c].resize(static_cast<std::size_t>(s * cols));
    Eigen::Map<Eigen::MatrixXd> d(scratch.deriv[c].data(), s, cols);
    d.noalias() = gm * x;
  }

  const double eps_d = eps_g + 2 * kUnit + rounding_gamma(static_cast<int>(n_used));
  const double g6 = rounding_gamma(6);
  for (std::size_t e = 0; e < count; ++e) {
    const double* xe = nodes + e * stride;
    const double delta = eps_d * gamma * range[e] * (1 + 1e-10);
    const double big_d = (1 + eps_d) * gamma * range[e] * (1 + 1e-10);
    double* out = samples + e * static_cast<std::size_t>(s);
    const auto col = static_cast<std::size_t>(3 * e);
    const auto at = [&](int c, Eigen::Index k, std::size_t j) {
      return scratch.deriv[c][static_cast<std::size_t>(k) + static_cast<std::size_t>(s) * (col + j)];
    };
    if (dim == 3) {
      for (Eigen::Index k = 0; k < s; ++k) {
        const double a0 = at(0, k, 0), a1 = at(0, k, 1), a2 = at(0, k, 2);
        const double b0 = at(1, k, 0), b1 = at(1, k, 1), b2 = at(1, k, 2);
        const double c0 = at(2, k, 0), c1 = at(2, k, 1), c2 = at(2, k, 2);
        out[k] = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0);
      }
      errors[e] = (18 * delta * big_d * big_d + 6 * g6 * big_d * big_d * big_d) * 1.01;
    } else if (dim == 2) {
      const auto n = reference_direction(space.type(), xe, planar);
      for (Eigen::Index k = 0; k < s; ++k) {
        const double a0 = at(0, k, 0), a1 = at(0, k, 1), a2 = at(0, k, 2);
        const double b0 = at(1, k, 0), b1 = at(1, k, 1), b2 = at(1, k, 2);
        out[k] = n[0] * (a1 * b2 - a2 * b1) + n[1] * (a2 * b0 - a0 * b2) + n[2] * (a0 * b1 - a1 * b0);
      }
      errors[e] = (12 * delta * big_d + 6 * g6 * big_d * big_d) * 1.01;
    } else {
      const auto t = reference_direction(space.type(), xe, planar);
      for (Eigen::Index k = 0; k < s; ++k)
        out[k] = t[0] * at(0, k, 0) + t[1] * at(0, k, 1) + t[2] * at(0, k, 2);
      errors[e] = (3 * delta + 3 * rounding_gamma(4) * big_d) * 1.01;
    }
  }
}

std::vector<mpq_class> exact_jacobian_samples(const JacobianSpace& space, const double* nodes,
                                              bool planar) {
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
