// Degrees and coordinate maps of the pyramid's Jacobian space (see pyramid_basis.hpp).
#include "bezier/pyramid_basis.hpp"

#include "quadval/error.hpp"

namespace quadval {

std::vector<FactorDegree> pyramid_jacobian_factor_degrees(int r) {
  QV_ASSERT(r >= 1, "pyramid order " << r);
  if (r == 1) return {{1, 2}, {1, 2}};
  return {{1, 3 * r - 1}, {1, 3 * r - 1}, {1, 3 * r - 3}};
}

int pyramid_generalized_size(int r) noexcept {
  if (r == 1) return 9;
  int n = 0;
  for (int k = 0; k <= 3 * r - 3; ++k) n += (k + 3) * (k + 3);
  return n;
}

std::array<double, 3> pyramid_cube_to_gmsh(double u, double v, double t) noexcept {
  return {(2 * u - 1) * t, (2 * v - 1) * t, 1 - t};
}

std::array<double, 3> pyramid_gmsh_to_cube(double xi, double eta, double zeta) noexcept {
  const double t = 1 - zeta;
  return {(xi / t + 1) / 2, (eta / t + 1) / 2, t};
}

}  // namespace quadval
