#pragma once
// W at one control point, as a fixed-size Eigen matrix (no allocation per call). Internal to
// src/analysis; used by mu_metric.cpp (corner bounds) and mu_constant.cpp (constant W).
#include <Eigen/Dense>

#include <cstddef>

#include "analysis/mu_space.hpp"

namespace quadval {

/// Column j of the 3 x D result is W's column j at control point k of `w` (the layout of
/// MuMetric::lower_bound: entry (j, c) is the vector w + (j * 3 + c) * w_size).
/// @pre D == space.dim()
template <int D>
Eigen::Matrix<double, 3, D> w_at(const MuSpace& space, const double* w, int k) {
  const auto ws = static_cast<std::size_t>(space.w_size());
  Eigen::Matrix<double, 3, D> wm;
  for (int j = 0; j < D; ++j)
    for (int c = 0; c < 3; ++c)
      wm(c, j) = w[(static_cast<std::size_t>(j) * 3 + static_cast<std::size_t>(c)) * ws + static_cast<std::size_t>(k)];
  return wm;
}

}  // namespace quadval
