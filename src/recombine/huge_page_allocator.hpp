#pragma once
// An allocator that asks Linux for transparent huge pages (2 MiB) on large blocks: the blossom
// solver reads its per-vertex records at random over 100+ MB on a million triangles, and with
// 4 KiB pages nearly every read also misses the TLB. Where transparent huge pages are set to
// "madvise" (Debian's default) only memory advised with MADV_HUGEPAGE gets them; where they
// are "never", the advice is ignored. Measured on square-hole-1M, the solver alone, three
// alternating runs: see blossom_solver.cpp (Solver's arrays).

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

namespace quadval::recombine_detail {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  /// Blocks of at least this size are huge-page aligned and advised.
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return std::allocator<T>().allocate(n);
    void* p = std::aligned_alloc(kHugePage, rounded(bytes));
    if (p == nullptr) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    ::madvise(p, rounded(bytes), MADV_HUGEPAGE);  // a hint: failure only loses the speed-up
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePage)
      std::allocator<T>().deallocate(p, n);
    else
      std::free(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }

 private:
  static std::size_t rounded(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }
};

/// A vector whose large buffers live on huge pages.
template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace quadval::recombine_detail
