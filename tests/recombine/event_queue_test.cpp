// The blossom solver's event queue against a sort: events leave by (key, push order), with
// the lane for due events, the 4-ary heap and the renumbering before the queue order wraps
// (forced early by a small last_seq).
#include <algorithm>
#include <cstdint>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "recombine/event_queue.hpp"

namespace quadval {
namespace {

using recombine_detail::EventQueue;

// Pushes and pops at random as the solver does: "now" only rises, to the key of the event
// popped, and every key pushed is at least now (keys equal to now go to the lane). Checks each
// pop against the least (key, push count) still queued.
void check_against_sort(std::uint32_t last_seq, std::uint32_t seed, int steps) {
  std::mt19937 rng(seed);
  EventQueue queue(last_seq);
  std::vector<std::tuple<std::int64_t, std::uint64_t, std::uint32_t>> reference;  // key, order, id
  std::uint64_t pushed = 0;
  std::int64_t now = 0;
  std::size_t pops = 0;
  for (int step = 0; step < steps; ++step) {
    const bool push = reference.empty() || rng() % 100 < 55;
    if (push) {
      // Few distinct keys, so that ties (and the lane, key == now) are common.
      const std::int64_t key = now + static_cast<std::int64_t>(rng() % 4 == 0 ? 0 : rng() % 12);
      const auto id = static_cast<std::uint32_t>(rng());
      queue.push(key, id, now);
      reference.emplace_back(key, pushed++, id);
      continue;
    }
    ASSERT_FALSE(queue.empty());
    const auto least = std::min_element(reference.begin(), reference.end());
    const EventQueue::Event& top = queue.top();
    ASSERT_EQ(top.key, std::get<0>(*least)) << "pop " << pops;
    ASSERT_EQ(top.id, std::get<2>(*least)) << "pop " << pops;
    now = top.key;
    queue.pop();
    reference.erase(least);
    ++pops;
  }
  EXPECT_EQ(queue.empty(), reference.empty());
  EXPECT_GT(pops, static_cast<std::size_t>(steps) / 4);
}

TEST(EventQueue, PopsByKeyThenPushOrder) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) check_against_sort(0xffffffffu, seed, 20000);
}

TEST(EventQueue, KeepsTheOrderWhenRenumbered) {
  // Renumbered every 3, 17 and 1000 pushes: with hundreds of entries queued, the first
  // renumbers on every push (the heap alone outgrows the range).
  for (std::uint32_t last : {3u, 17u, 1000u})
    for (std::uint32_t seed = 1; seed <= 3; ++seed) check_against_sort(last, seed, 5000);
}

}  // namespace
}  // namespace quadval
