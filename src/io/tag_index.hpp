#pragma once
// Tag -> position lookup for MSH node (and element) tags. Tags are usually dense (1..n), so
// a plain array indexed by tag is used up to a limit proportional to the count; larger
// tags fall back to a hash map, so that a file with tag 10^18 cannot make us allocate it.

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace quadval::io {

class TagIndex {
 public:
  static constexpr std::uint32_t kMissing = 0xffffffffu;

  TagIndex() = default;
  /// `expected_count`: how many tags will be inserted (sets the dense limit).
  explicit TagIndex(std::uint64_t expected_count)
      : dense_limit_(4 * expected_count + 1024) {}

  /// Records tag -> value; false (and no change) if the tag is already present.
  bool insert(std::uint64_t tag, std::uint32_t value) {
    if (tag < dense_limit_) {
      if (tag >= dense_.size()) dense_.resize(std::max<std::uint64_t>(tag + 1, 2 * dense_.size()), kMissing);
      if (dense_[tag] != kMissing) return false;
      dense_[tag] = value;
      return true;
    }
    return sparse_.emplace(tag, value).second;
  }

  /// The value stored for `tag`, or kMissing.
  std::uint32_t find(std::uint64_t tag) const noexcept {
    if (tag < dense_.size()) return dense_[tag];
    if (tag < dense_limit_ || sparse_.empty()) return kMissing;
    auto it = sparse_.find(tag);
    return it == sparse_.end() ? kMissing : it->second;
  }

 private:
  std::uint64_t dense_limit_ = 1024;
  std::vector<std::uint32_t> dense_;
  std::unordered_map<std::uint64_t, std::uint32_t> sparse_;
};

}  // namespace quadval::io
