#pragma once
// Where each multi-index of one degree sits in a list (simplex_multi_indices order): a
// table over its components 1-3 (component 0 follows from the degree), so a lookup is
// an index computation, not a search (a search or a std::map was most of the set-up of
// the Jacobian products, the Bernstein products and the bisections). Internal to src/.
#include <array>
#include <cstddef>
#include <vector>

namespace quadval {

class MultiIndexTable {
 public:
  /// @param list multi-indices of degree `degree` (at most 4 components)
  MultiIndexTable(const std::vector<std::array<int, 4>>& list, int degree)
      : base_(static_cast<std::size_t>(degree + 1)), position_(base_ * base_ * base_, -1) {
    for (std::size_t i = 0; i < list.size(); ++i) position_[key(list[i])] = static_cast<int>(i);
  }

  /// The position of a in the list, or -1 when it is not there.
  int operator()(const std::array<int, 4>& a) const noexcept {
    for (std::size_t c = 1; c < 4; ++c)
      if (a[c] < 0 || static_cast<std::size_t>(a[c]) >= base_) return -1;
    return position_[key(a)];
  }

 private:
  std::size_t key(const std::array<int, 4>& a) const noexcept {
    return (static_cast<std::size_t>(a[1]) * base_ + static_cast<std::size_t>(a[2])) * base_ + static_cast<std::size_t>(a[3]);
  }

  std::size_t base_;
  std::vector<int> position_;
};

}  // namespace quadval
