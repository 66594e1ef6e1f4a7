// R's bounds from W's vertex values, in lanes (see the header).
#include "analysis/vertex_metric_ratio.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/lane_vector.hpp"
#include "analysis/straight_simplex_mu.hpp"
#include "analysis/symmetric3_lanes.hpp"
#include "quadval/error.hpp"

namespace quadval {

CertifiedRatio vertex_metric_ratio(const VertexProducts& domain, const double (*w)[8][3], double delta, double b) {
  using namespace lanes3;
  const int nv = domain.vertices;
  QV_ASSERT(nv >= 1 && nv <= 8 && domain.slots >= nv && domain.slots <= VertexProducts::kSlots,
            nv << " vertices, " << domain.slots << " slots");
  const double err = next_up((3 * (2 * b + delta) * delta + rounding_gamma(10) * 3 * b * b) * kSlack);
  if (!(err < kMax) || !(b > 0)) return {};
  // The control values of M's entries m00, m11, m22, m01, m02, m12, by slot: the products
  // of every vertex pair, then each slot's mean of its pairs'.
  constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  alignas(64) double m[6][VertexProducts::kSlots];
  for (int e = 0; e < 6; ++e) {
    const auto& wx = w[kPairs[e][0]];
    const auto& wy = w[kPairs[e][1]];
    double dot[64];
    for (int q = 0; q < nv; ++q)
      for (int r = 0; r < nv; ++r) dot[q * nv + r] = wx[q][0] * wy[r][0] + wx[q][1] * wy[r][1] + wx[q][2] * wy[r][2];
    for (int s = 0; s < domain.slots; ++s) {
      const auto& pairs = domain.pairs[static_cast<std::size_t>(s)];
      double sum = dot[pairs[0]];
      for (int t = 1; t < domain.pair_count[static_cast<std::size_t>(s)]; ++t) sum += dot[pairs[static_cast<std::size_t>(t)]];
      m[e][s] = sum * domain.inverse_count[static_cast<std::size_t>(s)];
    }
  }
  return control_matrix_ratio(m, domain.slots, nv, w, err, delta);
}

CertifiedRatio control_matrix_ratio(const double (*m)[VertexProducts::kSlots], int slots, int vertices,
                                    const double (*w)[8][3], double err, double delta, double enough) {
  using namespace lanes3;
  // A block of 8 slots in kParts registers of kW lanes (lane_vector.hpp: wider vectors cost
  // more than their parts); each slot's arithmetic, the decisions and the folds' order are
  // those of one 8-lane block.
  constexpr int kW = kNativeLanes, kParts = 8 / kW;
  constexpr unsigned kAll = (1u << kW) - 1;
  using LW = Lanes<kW>;
  const auto load_block = [&](int block, LW (*mb)[6]) {
    for (int p = 0; p < kParts; ++p)
      for (int e = 0; e < 6; ++e) mb[p][e] = load_lanes<kW>(&m[e][8 * block + kW * p]);
  };
  // The enclosures of a block's matrices; false unless all are certified positive definite.
  const auto enclose = [&](LW (*mb)[6], ExtremeEigen<kW>* eig) {
    bool positive = true;
    for (int p = 0; p < kParts; ++p) {
      eig[p] = extreme_eigen<kW>(mb[p], broadcast_lanes<kW>(err));
      positive = positive && mask_bits<kW>(eig[p].ok & (eig[p].lo > 0)) == kAll;
    }
    return positive;
  };
  const auto fold_ratios = [&](const ExtremeEigen<kW>* eig, double r) {
    for (int p = 0; p < kParts; ++p) r = fold_min(down<kW>(eig[p].lo / eig[p].hi), r);
    return r;
  };
  CertifiedRatio out;
  // Lower: the least certified ratio of the control matrices (mu_control_bound.hpp), or 0
  // where one of them is not certified positive definite (control matrices of M need not
  // be where M is: a distorted element; halves of it have better ones). The vertices'
  // block is enclosed first; a later block only where the cheaper test does not certify
  // all its lanes at least the least ratio so far (or `enough`, if less), which then is
  // the bound (a good element's later blocks mostly pass: hex_box_30 mu 30.3 -> 24.6 ms).
  LW vertex_m[kParts][6];
  ExtremeEigen<kW> vertex_eig[kParts];
  load_block(0, vertex_m);
  if (!enclose(vertex_m, vertex_eig)) return out;
  double lower = fold_ratios(vertex_eig, 1.0);
  for (int block = 1; block < slots / 8; ++block) {
    LW mb[kParts][6];
    load_block(block, mb);
    const double floor = std::min(lower, enough);
    if (floor > 0 && floor < 1) {
      bool all = true;
      for (int p = 0; p < kParts && all; ++p) all = mask_bits<kW>(ratio_at_least<kW>(mb[p], err, floor)) == kAll;
      if (all) {
        lower = floor;
        continue;
      }
    }
    ExtremeEigen<kW> eig[kParts];
    if (!enclose(mb, eig)) {
      lower = 0;  // R >= 0 is all that is known
      break;
    }
    lower = fold_ratios(eig, lower);
  }
  // Upper: Rayleigh quotients of W at the vertices (slots 0 to vertices - 1 of block 0).
  double best = 1;
  for (int p = 0; p < kParts && kW * p < vertices; ++p) {
    LW wv[3][3];
    for (int j = 0; j < 3; ++j)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kW; ++l) wv[j][c][l] = w[j][kW * p + l < vertices ? kW * p + l : 0][c];
    Mask<kW> vectors_ok;
    const LW upper = ratio_upper<kW>(wv, vertex_m[p], vertex_eig[p].lo, vertex_eig[p].hi,
                                     broadcast_lanes<kW>(delta), vectors_ok);
    for (int l = 0; l < kW && kW * p + l < vertices; ++l) best = std::min(best, upper[l]);
  }
  out.lower = std::clamp(lower, 0.0, 1.0);
  out.upper = std::clamp(best, 0.0, 1.0);
  out.ok = out.lower <= out.upper;
  return out;
}

template <int W>
StraightSimplexRatio<W> constant_columns_ratio(const Lanes<W> (*col)[8][3], int vertices, const Lanes<W>* rounding,
                                               const std::array<double, 9>& jinv) {
  using L = Lanes<W>;
  L scale{}, spread{}, edges[9], margins[3];
  for (int c = 0; c < 3; ++c) {
    L beta{};
    for (int q = 0; q < vertices; ++q)
      for (int k = 0; k < 3; ++k) {
        scale = vmax(scale, vabs(col[c][q][k]));
        if (q > 0) beta = vmax(beta, vabs(col[c][q][k] - col[c][0][k]));
      }
    spread = vmax(spread, beta);
    margins[c] = lanes3::up<W>((beta + rounding[c]) * lanes3::kSlack);
    for (int k = 0; k < 3; ++k) edges[3 * c + k] = col[c][0][k];
  }
  const unsigned constant = lanes3::mask_bits<W>(spread <= 1e-9 * scale);
  if (constant == 0) {  // most prisms and pyramids: their columns vary
    StraightSimplexRatio<W> none;
    none.lower = none.upper = L{};
    return none;
  }
  StraightSimplexRatio<W> r = straight_tet_ratio<W>(edges, margins, jinv);
  r.ok &= constant;
  return r;
}

template StraightSimplexRatio<2> constant_columns_ratio<2>(const Lanes<2> (*)[8][3], int, const Lanes<2>*,
                                                           const std::array<double, 9>&);
template StraightSimplexRatio<kNativeLanes> constant_columns_ratio<kNativeLanes>(const Lanes<kNativeLanes> (*)[8][3],
                                                                                 int, const Lanes<kNativeLanes>*,
                                                                                 const std::array<double, 9>&);

CertifiedRatio columns_ratio(const VertexProducts& domain, const double (*col)[8][3], const double* rounding,
                             const std::array<double, 9>& jinv) {
  constexpr double kUnit = 0x1p-53;
  constexpr double kSlack = lanes3::kSlack;
  const int nv = domain.vertices;
  // Constant W: the closed form, the element in both lanes (as one tetrahedron in mu_bounds).
  {
    Lanes<2> lanes[3][8][3], round[3];
    for (int c = 0; c < 3; ++c) {
      round[c] = broadcast_lanes<2>(rounding[c]);
      for (int q = 0; q < nv; ++q)
        for (int k = 0; k < 3; ++k) lanes[c][q][k] = broadcast_lanes<2>(col[c][q][k]);
    }
    const StraightSimplexRatio<2> r = constant_columns_ratio<2>(lanes, nv, round, jinv);
    if ((r.ok & 1u) != 0) return {r.lower[0], r.upper[0], r.lower[0] <= r.upper[0]};
  }
  double a[3] = {0, 0, 0};  // per column, its largest |entry|
  for (int c = 0; c < 3; ++c)
    for (int q = 0; q < nv; ++q)
      for (int k = 0; k < 3; ++k) a[c] = std::max(a[c], std::abs(col[c][q][k]));
  double w[3][8][3] = {};
  double delta = 0, b = 0;
  for (int j = 0; j < 3; ++j) {
    double dj = 0, bj = 0;
    for (int c = 0; c < 3; ++c) {
      const double s = std::abs(jinv[static_cast<std::size_t>(3 * c + j)]);
      dj += s * (rounding[c] + 4 * kUnit * a[c]);
      bj += s * a[c];
    }
    delta = std::max(delta, dj);
    b = std::max(b, bj);
    for (int q = 0; q < nv; ++q)
      for (int k = 0; k < 3; ++k) {
        double v = 0;
        for (int c = 0; c < 3; ++c) v += jinv[static_cast<std::size_t>(3 * c + j)] * col[c][q][k];
        w[j][q][k] = v;
      }
  }
  delta = next_up(delta * kSlack);
  return vertex_metric_ratio(domain, w, delta, next_up((b + delta) * kSlack));
}

}  // namespace quadval
