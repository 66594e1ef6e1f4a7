#pragma once
// One immutable object per element type (a space, its tables), built on first use and
// shared by all threads. A slot per Gmsh id, each under its own once_flag: after the first
// build a lookup is one acquire load, where a mutex and a map cost every element of a
// quality check two atomic operations and a tree walk (and, with threads, a contended
// cache line).
#include <array>
#include <cstddef>
#include <memory>
#include <mutex>

#include "quadval/element_type.hpp"
#include "quadval/error.hpp"

namespace quadval {

template <class T>
class PerTypeCache {
 public:
  /// The object of `type`, made by make() (returning std::unique_ptr<const T>) the first
  /// time; make() may throw, and is then tried again on the next call.
  template <class Make>
  const T& get(const ElementType& type, Make&& make) {
    const auto id = static_cast<std::size_t>(type.gmsh_id);
    QV_ASSERT(id < kSlots, "Gmsh type id " << type.gmsh_id);
    std::call_once(once_[id], [&] { slot_[id] = make(); });
    return *slot_[id];
  }

 private:
  static constexpr std::size_t kSlots = 141;  // Gmsh ids 1..140 (element_type.hpp)
  std::array<std::once_flag, kSlots> once_;
  std::array<std::unique_ptr<const T>, kSlots> slot_;
};

}  // namespace quadval
