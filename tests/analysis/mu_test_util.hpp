#pragma once
// Helpers of the mu tests: the pointwise measure sigma_min / sigma_max of W = J_p J_i^-1
// from the Lagrange shape-function gradients and Eigen's SVD, with J_i built here from the
// ideal elements' vertices (no code shared with src/analysis/mu_*), and element makers.
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "jacobian_test_util.hpp"
#include "quadval/element_type.hpp"
#include "quadval/lagrange_basis.hpp"

namespace quadval::test {

/// Vertices of the ideal element of a family (mu_bounds.hpp), in Gmsh vertex order.
inline std::vector<Eigen::Vector3d> ideal_vertices(ElementFamily f) {
  const double h = std::sqrt(3.0) / 2;
  switch (f) {
    case ElementFamily::triangle: return {{0, 0, 0}, {1, 0, 0}, {0.5, h, 0}};
    case ElementFamily::quadrangle: return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    case ElementFamily::tetrahedron:
      return {{0, 0, 0}, {1, 0, 0}, {0.5, h, 0}, {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3)}};
    case ElementFamily::prism:
      return {{0, 0, 0}, {1, 0, 0}, {0.5, h, 0}, {0, 0, 1}, {1, 0, 1}, {0.5, h, 1}};
    case ElementFamily::hexahedron:
      return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    case ElementFamily::pyramid:  // unit square base, equilateral triangular faces
      return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1 / std::sqrt(2.0)}};
    default: return {};
  }
}

/// J_i: the Jacobian of the affine map from Gmsh's reference element onto the ideal one,
/// from the vertex images (simplex directions: v_k - v_0; [-1, 1] directions: half).
inline Eigen::MatrixXd ideal_jacobian(ElementFamily f) {
  const auto v = ideal_vertices(f);
  const int dim = family_dimension(f);
  Eigen::MatrixXd j(dim, dim);
  const auto col = [&](int c, const Eigen::Vector3d& d) { j.col(c) = d.head(dim); };
  switch (f) {
    case ElementFamily::triangle: col(0, v[1] - v[0]); col(1, v[2] - v[0]); break;
    case ElementFamily::tetrahedron: col(0, v[1] - v[0]); col(1, v[2] - v[0]); col(2, v[3] - v[0]); break;
    case ElementFamily::quadrangle: col(0, (v[1] - v[0]) / 2); col(1, (v[3] - v[0]) / 2); break;
    case ElementFamily::hexahedron:
      col(0, (v[1] - v[0]) / 2); col(1, (v[3] - v[0]) / 2); col(2, (v[4] - v[0]) / 2); break;
    case ElementFamily::prism: col(0, v[1] - v[0]); col(1, v[2] - v[0]); col(2, (v[3] - v[0]) / 2); break;
    case ElementFamily::pyramid:  // zeta runs from the base centre to the apex
      col(0, (v[1] - v[0]) / 2); col(1, (v[3] - v[0]) / 2); col(2, v[4] - (v[0] + v[1] + v[2] + v[3]) / 4); break;
    default: break;
  }
  return j;
}

/// J_p (3 x dim) at a reference point.
inline Eigen::MatrixXd physical_jacobian(const LagrangeBasis& basis, const std::vector<double>& x,
                                         const RefPoint& p) {
  const int n = basis.num_nodes();
  const int dim = basis.type().dim;
  std::vector<double> g(static_cast<std::size_t>(3 * n));
  basis.evaluate_gradients(p, g);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(3, dim);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < dim; ++c)
      for (int a = 0; a < 3; ++a)
        j(a, c) += g[static_cast<std::size_t>(3 * i + c)] * x[static_cast<std::size_t>(3 * i + a)];
  return j;
}

/// sigma_min / sigma_max of W = J_p J_i^-1 at a reference point.
inline double pointwise_mu(const LagrangeBasis& basis, const std::vector<double>& x, const RefPoint& p) {
  const Eigen::MatrixXd w = physical_jacobian(basis, x, p) * ideal_jacobian(basis.type().family).inverse();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(w);
  const auto s = svd.singularValues();
  return s(s.size() - 1) / s(0);
}

/// pointwise_mu sampled at `points`: its least and greatest value, and whether J <= 0 at
/// one of them (planar J for 2D elements: jacobian_at).
struct SampledMu {
  double lo = 1, hi = 0;
  bool j_nonpositive = false;
};
inline SampledMu sample_mu(const LagrangeBasis& basis, const std::vector<double>& x,
                           const std::vector<RefPoint>& points) {
  SampledMu out;
  for (const RefPoint& p : points) {
    if (jacobian_at(basis, x, p, true) <= 0) out.j_nonpositive = true;
    const double m = pointwise_mu(basis, x, p);
    out.lo = std::min(out.lo, m);
    out.hi = std::max(out.hi, m);
  }
  return out;
}

/// Nodes of `type` placed by an affine map of the ideal element: x = A y + b, y the ideal
/// element's point of each reference node.
inline std::vector<double> affine_ideal_element(const ElementType& type, const Eigen::Matrix3d& a,
                                                const Eigen::Vector3d& b) {
  const auto v = ideal_vertices(type.family);
  const Eigen::MatrixXd ji = ideal_jacobian(type.family);
  const int dim = type.dim;
  // reference vertex 0 of each family, in Gmsh coordinates
  Eigen::VectorXd r0(dim);
  const auto ref0 = reference_vertices(type.family)[0];
  for (int c = 0; c < dim; ++c) r0(c) = ref0[static_cast<std::size_t>(c)];
  std::vector<double> x;
  for (const auto& p : reference_nodes(type)) {
    Eigen::VectorXd r(dim);
    for (int c = 0; c < dim; ++c) r(c) = p[static_cast<std::size_t>(c)];
    Eigen::Vector3d y = v[0];
    y.head(dim) += ji * (r - r0);
    const Eigen::Vector3d z = a * y + b;
    x.insert(x.end(), {z(0), z(1), z(2)});
  }
  return x;
}

}  // namespace quadval::test
