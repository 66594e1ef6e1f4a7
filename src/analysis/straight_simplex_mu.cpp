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

// W_0 = [a] Jinv over the element's D columns and delta: each entry within delta of the
// exact W everywhere on the element (straight_simplex_mu: the columns' margins and the
// products' roundings); then M_0 = W_0^T W_0 and the error err of every W^T W of that box
// (corner_metric).
template <int W, int D>
struct ConstantMetric {
  Lanes<W> w[D][3];             ///< w[j][k]: coordinate k of column j
  Lanes<W> delta{};
  Lanes<W> m[D * (D + 1) / 2];  ///< m00, m11, (m22,) m01, (m02, m12)
  Lanes<W> err{};
};

template <int W, int D>
ConstantMetric<W, D> constant_metric(const Lanes<W>* a, const Lanes<W>* beta, const std::array<double, 9>& jinv) {
  using namespace lanes3;
  using L = Lanes<W>;
  ConstantMetric<W, D> out;
  L a_max[D];
  for (int c = 0; c < D; ++c) a_max[c] = vmax(vmax(vabs(a[3 * c]), vabs(a[3 * c + 1])), vabs(a[3 * c + 2]));
  for (int j = 0; j < D; ++j) {
    L d{};
    for (int c = 0; c < D; ++c) d += std::abs(jinv[static_cast<std::size_t>(c * 3 + j)]) * (beta[c] + 8 * kUnit * a_max[c]);
    out.delta = vmax(out.delta, d);
    for (int k = 0; k < 3; ++k) {
      L v{};
      for (int c = 0; c < D; ++c) v += jinv[static_cast<std::size_t>(c * 3 + j)] * a[3 * c + k];
      out.w[j][k] = v;
    }
  }
  out.delta = up<W>(out.delta * kSlack);
  constexpr int kPairs3[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  constexpr int kPairs2[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  for (int e = 0; e < D * (D + 1) / 2; ++e) {
    const int i = D == 3 ? kPairs3[e][0] : kPairs2[e][0], j = D == 3 ? kPairs3[e][1] : kPairs2[e][1];
    L sum{}, mag{}, prop{};
    for (int c = 0; c < 3; ++c) {
      sum += out.w[i][c] * out.w[j][c];
      mag += vabs(out.w[i][c] * out.w[j][c]);
      prop += (vabs(out.w[i][c]) + vabs(out.w[j][c]) + out.delta) * out.delta;
    }
    out.m[e] = sum;
    out.err = vmax(out.err, (prop + rounding_gamma(4) * mag) * kSlack);
  }
  return out;
}

}  // namespace

template <int W>
StraightSimplexRatio<W> straight_tet_ratio(const Lanes<W>* a, const Lanes<W>* beta, const std::array<double, 9>& jinv) {
  using namespace lanes3;
  using L = Lanes<W>;
  StraightSimplexRatio<W> out;
  const ConstantMetric<W, 3> cm = constant_metric<W, 3>(a, beta, jinv);
  // Extreme eigenvalues (extreme_eigen_bounds3), certified; the upper bound from the
  // Rayleigh quotients at the eigenvectors of lo and hi.
  const ExtremeEigen<W> eig = extreme_eigen<W>(cm.m, cm.err);
  Mask<W> vectors_ok;
  out.upper = ratio_upper<W>(cm.w, cm.m, eig.lo, eig.hi, cm.delta, vectors_ok);
  const Mask<W> ok = finite<W>(cm.delta) & eig.ok & (eig.lo > 0) & vectors_ok;
  out.lower = vmin(vmax(down<W>(eig.lo / (ok ? eig.hi : L{} + 1)), L{}), L{} + 1);
  out.ok = mask_bits<W>(ok);
  return out;
}

template <int W>
StraightSimplexRatio<W> straight_triangle_ratio(const Lanes<W>* a, const Lanes<W>* beta,
                                                const std::array<double, 9>& jinv) {
  using namespace lanes3;
  StraightSimplexRatio<W> out;
  const ConstantMetric<W, 2> cm = constant_metric<W, 2>(a, beta, jinv);
  // The 2 x 2 eigenvalue enclosure's ratios; a lane whose enclosure is unknown or not
  // positive has lower = 0 and goes to the general path.
  out.lower = enclosure_ratio_lower2_lanes<W>(cm.m, cm.err);
  out.upper = enclosure_ratio_upper2_lanes<W>(cm.m, cm.err);
  out.ok = mask_bits<W>(finite<W>(cm.delta) & (out.lower > 0));
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
