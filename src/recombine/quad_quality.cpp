#include "quadval/quad_quality.hpp"

#include <algorithm>
#include <cmath>

#include "eta_of_cosine.hpp"

namespace quadval {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) noexcept { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross(const V3& a, const V3& b) noexcept {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const V3& a, const V3& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const V3& a) noexcept { return std::sqrt(dot(a, a)); }

}  // namespace

QuadEta quad_eta(const QuadCorners& x, const std::array<double, 3>& normal) noexcept {
  if (norm(normal) == 0.0) return {0.0, QuadShape::degenerate};
  // |pi/2 - alpha| = asin(|cos alpha|) for alpha in [0, pi], and asin is increasing: the
  // worst corner is the one with the largest |cos alpha| (one asin per quad, not four).
  double worst_cos = 0.0;
  bool invalid = false;
  for (int k = 0; k < 4; ++k) {
    const V3 forward = sub(x[(k + 1) % 4], x[k]);
    const V3 backward = sub(x[(k + 3) % 4], x[k]);
    const double lengths = norm(forward) * norm(backward);
    if (lengths == 0.0) return {0.0, QuadShape::degenerate};
    // A corner that turns against the normal is reflex (alpha > pi) or inverted.
    if (dot(cross(forward, backward), normal) <= 0.0) invalid = true;
    worst_cos = std::max(worst_cos, std::abs(dot(forward, backward)) / lengths);
  }
  if (invalid) return {0.0, QuadShape::ok};
  return {recombine_detail::eta_of_cosine(std::min(worst_cos, 1.0)), QuadShape::ok};
}

QuadEta quad_eta(const QuadCorners& x) noexcept {
  return quad_eta(x, cross(sub(x[2], x[0]), sub(x[3], x[1])));
}

double quad_min_corner_sine(const QuadCorners& x, const std::array<double, 3>& normal) noexcept {
  const double nn = norm(normal);
  if (nn == 0.0) return -1.0;
  double worst = 1.0;
  for (int k = 0; k < 4; ++k) {
    const V3 forward = sub(x[(k + 1) % 4], x[k]);
    const V3 backward = sub(x[(k + 3) % 4], x[k]);
    const double scale = norm(forward) * norm(backward) * nn;
    if (scale == 0.0) return -1.0;
    worst = std::min(worst, dot(cross(forward, backward), normal) / scale);
  }
  return worst;
}

std::vector<double> element_eta(const Mesh& mesh, double other) {
  std::vector<double> eta(mesh.num_elements(), other);
  std::size_t first = 0;  // the block's first element
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type->family == ElementFamily::quadrangle) {
      const auto count = static_cast<std::ptrdiff_t>(b.size());
#pragma omp parallel for schedule(static) if (count > 16384)
      for (std::ptrdiff_t e = 0; e < count; ++e) {
        const auto n = b.element(static_cast<std::size_t>(e));
        eta[first + static_cast<std::size_t>(e)] =
            quad_eta({mesh.node(n[0]), mesh.node(n[1]), mesh.node(n[2]), mesh.node(n[3])}).eta;
      }
    }
    first += b.size();
  }
  return eta;
}

}  // namespace quadval
