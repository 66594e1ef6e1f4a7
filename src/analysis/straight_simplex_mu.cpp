// Lane-parallel closed-form bounds of R for straight-sided tetrahedra and planar triangles
// (see the header).
// Rounding: as the scalar functions it follows (mu_constant.cpp, mu_metric.cpp,
// mu_control_bound.cpp), every bound is enlarged for its own rounding and stepped outward.
#include "analysis/straight_simplex_mu.hpp"

#include "analysis/mu_control_bound.hpp"
#include "analysis/symmetric3_lanes.hpp"

namespace quadval {
namespace {

constexpr double kUnit = 0x1p-53;

}  // namespace

template <int W>
StraightSimplexRatio<W> straight_tet_ratio(const Lanes<W>* a, const Lanes<W>* beta, const std::array<double, 9>& jinv) {
  using namespace lanes3;
  using L = Lanes<W>;
  StraightSimplexRatio<W> out;
  // W_0 = [a] Jinv and delta: each entry within delta of the exact W everywhere on the
  // element (straight_simplex_mu: the columns' margins and the products' roundings).
  L a_max[3];
  for (int c = 0; c < 3; ++c) a_max[c] = vmax(vmax(vabs(a[3 * c]), vabs(a[3 * c + 1])), vabs(a[3 * c + 2]));
  L w[3][3];  // w[j][k]: coordinate k of column j
  L delta{};
  for (int j = 0; j < 3; ++j) {
    L d{};
    for (int c = 0; c < 3; ++c) d += std::abs(jinv[static_cast<std::size_t>(c * 3 + j)]) * (beta[c] + 8 * kUnit * a_max[c]);
    delta = vmax(delta, d);
    for (int k = 0; k < 3; ++k) {
      L v{};
      for (int c = 0; c < 3; ++c) v += jinv[static_cast<std::size_t>(c * 3 + j)] * a[3 * c + k];
      w[j][k] = v;
    }
  }
  delta = up<W>(delta * kSlack);
  // M_0 = W_0^T W_0 (entries m00, m11, m22, m01, m02, m12) and its error (corner_metric).
  constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  L m[6], err{};
  for (int e = 0; e < 6; ++e) {
    const int i = kPairs[e][0], j = kPairs[e][1];
    L sum{}, mag{}, prop{};
    for (int c = 0; c < 3; ++c) {
      sum += w[i][c] * w[j][c];
      mag += vabs(w[i][c] * w[j][c]);
      prop += (vabs(w[i][c]) + vabs(w[j][c]) + delta) * delta;
    }
    m[e] = sum;
    err = vmax(err, (prop + rounding_gamma(4) * mag) * kSlack);
  }
  // Extreme eigenvalues (extreme_eigen_bounds3), certified; the upper bound from the
  // Rayleigh quotients at the eigenvectors of lo and hi.
  const ExtremeEigen<W> eig = extreme_eigen<W>(m, err);
  Mask<W> vectors_ok;
  out.upper = ratio_upper<W>(w, m, eig.lo, eig.hi, delta, vectors_ok);
  const Mask<W> ok = finite<W>(delta) & eig.ok & (eig.lo > 0) & vectors_ok;
  out.lower = vmin(vmax(down<W>(eig.lo / (ok ? eig.hi : L{} + 1)), L{}), L{} + 1);
  out.ok = mask_bits<W>(ok);
  return out;
}

template <int W>
StraightSimplexRatio<W> straight_triangle_ratio(const Lanes<W>* a, const Lanes<W>* beta,
                                                const std::array<double, 9>& jinv) {
  using namespace lanes3;
  using L = Lanes<W>;
  StraightSimplexRatio<W> out;
  // W_0 = [a] Jinv (3 x 2) and delta, as straight_tet_ratio over two columns.
  L a_max[2];
  for (int c = 0; c < 2; ++c) a_max[c] = vmax(vmax(vabs(a[3 * c]), vabs(a[3 * c + 1])), vabs(a[3 * c + 2]));
  L w[2][3];
  L delta{};
  for (int j = 0; j < 2; ++j) {
    L d{};
    for (int c = 0; c < 2; ++c) d += std::abs(jinv[static_cast<std::size_t>(c * 3 + j)]) * (beta[c] + 8 * kUnit * a_max[c]);
    delta = vmax(delta, d);
    for (int k = 0; k < 3; ++k) {
      L v{};
      for (int c = 0; c < 2; ++c) v += jinv[static_cast<std::size_t>(c * 3 + j)] * a[3 * c + k];
      w[j][k] = v;
    }
  }
  delta = up<W>(delta * kSlack);
  // M_0 = W_0^T W_0 (m00, m11, m01) and its error (corner_metric).
  constexpr int kPairs[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  L m[3], err{};
  for (int e = 0; e < 3; ++e) {
    const int i = kPairs[e][0], j = kPairs[e][1];
    L sum{}, mag{}, prop{};
    for (int c = 0; c < 3; ++c) {
      sum += w[i][c] * w[j][c];
      mag += vabs(w[i][c] * w[j][c]);
      prop += (vabs(w[i][c]) + vabs(w[j][c]) + delta) * delta;
    }
    m[e] = sum;
    err = vmax(err, (prop + rounding_gamma(4) * mag) * kSlack);
  }
  // The eigenvalue enclosure's ratios; a lane whose enclosure is unknown or not positive
  // has lower = 0 and goes to the general path.
  out.lower = enclosure_ratio_lower2_lanes<W>(m, err);
  out.upper = enclosure_ratio_upper2_lanes<W>(m, err);
  out.ok = mask_bits<W>(finite<W>(delta) & (out.lower > 0));
  return out;
}

template StraightSimplexRatio<2> straight_tet_ratio<2>(const Lanes<2>*, const Lanes<2>*, const std::array<double, 9>&);
template StraightSimplexRatio<kNativeLanes> straight_tet_ratio<kNativeLanes>(const Lanes<kNativeLanes>*,
                                                                         const Lanes<kNativeLanes>*,
                                                                         const std::array<double, 9>&);
template StraightSimplexRatio<2> straight_triangle_ratio<2>(const Lanes<2>*, const Lanes<2>*,
                                                            const std::array<double, 9>&);
template StraightSimplexRatio<kNativeLanes> straight_triangle_ratio<kNativeLanes>(const Lanes<kNativeLanes>*,
                                                                                  const Lanes<kNativeLanes>*,
                                                                                  const std::array<double, 9>&);

}  // namespace quadval
