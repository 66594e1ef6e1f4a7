#pragma once
// Room reserved up front in the pools of subdomain slots that the refinements (mu,
// scaled Jacobian) keep per thread. Internal to src/analysis.
//
// Why: grown by doubling, a pool was copied into fresh pages each time it outgrew itself,
// and on this machine (a VM) the first touch of a page costs a fault of about 3 us; a
// process's one analysis (the CLI's) touches every page for the first time. Page faults of
// the first analysis of a process (getrusage): warped_prism_o2's mu, one thread, 196 -> 124
// (3.04 -> 2.81 ms, alternating runs); on two threads, warped_prism_o2's mu 352-358 -> 185-213,
// warped_tetrahedron_o3's scaled Jacobian 2,289-2,403 -> 1,745, mixed_h0.6_o2's 2,712-2,839
// -> 1,680. Room that is never touched costs address space only.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace quadval {

/// Slots a pool has room for from its first element on, within kMaxReservedValues (8 MiB:
/// a cubic tetrahedron's scaled-Jacobian slots, 455 coefficients x at most 14 vectors, take
/// about 3 MiB for 64; very high orders get fewer).
inline constexpr std::size_t kReservedSlots = 64;
inline constexpr std::size_t kMaxReservedValues = std::size_t{1} << 20;

/// Reserves room for kReservedSlots slots of slot_size values in pool, or for as many as
/// kMaxReservedValues allow (at least one), keeping its contents.
inline void reserve_slots(std::vector<double>& pool, std::size_t slot_size) {
  const std::size_t fit = kMaxReservedValues / std::max<std::size_t>(1, slot_size);
  const std::size_t slots = std::max<std::size_t>(1, std::min(kReservedSlots, fit));
  if (pool.capacity() < slots * slot_size) pool.reserve(slots * slot_size);
}

}  // namespace quadval
