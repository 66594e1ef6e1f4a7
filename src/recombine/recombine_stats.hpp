#pragma once
// Statistics of a recombined mesh (Paper I §2 and Table I).

#include "mixed_mesh.hpp"
#include "quadval/recombine.hpp"

namespace quadval::recombine_detail {

/// Adimensional length of the segment a-b in the size field h, eq. (1):
/// |ab| ∫_0^1 dt / h(a + t ab), by 5-point Gauss-Legendre quadrature.
double adimensional_length(const std::array<double, 3>& a, const std::array<double, 3>& b,
                           const SizeFunction& h);

/// Efficiency index tau (percent), eq. (2), over the given adimensional edge lengths.
double efficiency_index(const std::vector<double>& lengths);

/// Fills the final-mesh fields of `stats`: quads, triangles, nodes used, invalid_quads,
/// eta_min / eta_mean over quads (eq. 3, signed by each element's reference normal),
/// degree statistics over interior nodes (not on a region boundary; degree = number of
/// elements around the node), and tau when `size_field` is set (over the unique edges).
void compute_statistics(const MixedMesh& m, const SizeFunction& size_field, RecombineStats& stats);

}  // namespace quadval::recombine_detail
