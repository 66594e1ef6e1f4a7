#pragma once
// The check shared by the tests of functions that analyse four elements at once, one per
// SIMD lane (scaled_jacobian_valid_planar4, mu_valid_planar4): wherever a lane answers, it
// must be the bits of that element's own call, whatever the other lanes hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "quadval/quality_bounds.hpp"

namespace quadval::test {

/// The elements xs in groups of four, shuffled anew for each of two runs (a group's last
/// lanes repeat its last element), through four_at_once(x, out) -> bits answered; every
/// answered lane is checked against own[i], the element's own result. Returns per element
/// the number of runs that answered it.
template <class Four>
std::vector<int> check_four_at_once(const std::vector<std::vector<double>>& xs, const std::vector<QualityBounds>& own,
                                    std::mt19937& rng, Four&& four_at_once) {
  std::vector<std::size_t> order(xs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::vector<int> answers(xs.size(), 0);
  for (int run = 0; run < 2; ++run) {
    std::shuffle(order.begin(), order.end(), rng);
    for (std::size_t g = 0; g < order.size(); g += 4) {
      std::array<std::span<const double>, 4> x;
      for (std::size_t l = 0; l < 4; ++l) x[l] = xs[order[std::min(g + l, order.size() - 1)]];
      std::array<QualityBounds, 4> out;
      const unsigned done = four_at_once(x, out);
      for (std::size_t l = 0; l < 4 && g + l < order.size(); ++l) {
        if (!((done >> l) & 1u)) continue;
        const std::size_t i = order[g + l];
        ++answers[i];
        EXPECT_EQ(std::bit_cast<std::uint64_t>(out[l].lower), std::bit_cast<std::uint64_t>(own[i].lower)) << i;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(out[l].upper), std::bit_cast<std::uint64_t>(own[i].upper)) << i;
        EXPECT_EQ(out[l].subdivisions, own[i].subdivisions) << i;
        EXPECT_EQ(out[l].tolerance_met, own[i].tolerance_met) << i;
      }
    }
  }
  return answers;
}

}  // namespace quadval::test
