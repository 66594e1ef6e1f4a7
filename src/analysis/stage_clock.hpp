#pragma once
// Per-element timing for the stage table (Paper III Table 2) at the cost of one counter read:
// the CPU's time-stamp counter on x86-64 (a few nanoseconds; two clock_gettime calls per
// element took 15% of a check of quadratic tetrahedra, measured with perf), converted to
// seconds at the rate measured over the whole run. Elsewhere steady_clock's count. Only the
// reported stage times depend on it, never a bound or an answer. Internal to src/analysis.
#include <chrono>
#include <cstdint>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

namespace quadval {

inline std::uint64_t stage_ticks() noexcept {
#if defined(__x86_64__)
  return __rdtsc();
#else
  return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}

/// Seconds per stage tick, from the wall time and the ticks between construction and the call.
class StageClockRate {
 public:
  StageClockRate() : start_(std::chrono::steady_clock::now()), ticks_(stage_ticks()) {}
  double seconds_per_tick() const {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::uint64_t ticks = stage_ticks() - ticks_;
    return ticks > 0 && seconds > 0 ? seconds / static_cast<double>(ticks) : 0.0;
  }

 private:
  std::chrono::steady_clock::time_point start_;
  std::uint64_t ticks_;
};

}  // namespace quadval
