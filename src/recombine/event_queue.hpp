#pragma once
// The blossom solver's event queues (blossom_solver.cpp): events by (key, queue order).
//
// A FIFO lane holds the events queued when already due (key == the caller's "now"): on meshes
// most grow events are, since whole regions of tight edges are absorbed at one dual value,
// and the lane spares them the heap (measured: 2x less time on uniform meshes). The order is
// that of one heap: an event in the heap with the lane's key was queued before the dual value
// reached it, so before every event in the lane. (The lane holds only events of the current
// key: the dual value cannot rise while it is not empty.) Taken last in, first out instead
// (depth-first trees; the same optimum, another optimal pairing among equal costs), the
// matching was slower: uniform-30k-a6 0.16 -> 0.22 s, uniform-100k-a6 4.4 -> 5.2 s (medians
// of 5 alternating runs), square-hole-100k the same.
//
// The heap is 4-ary: half the levels of a binary heap, and the four children of an entry are
// contiguous (two cache lines, where a binary heap takes one per level). On square-hole-1M,
// whose grow heap holds 284k entries on average (450k at most), pops took a fifth of the
// solver's time in a binary heap. Counted by cachegrind (the same run every time, where wall
// times on this machine vary by 20%), the solver on square-hole-1M with 16-byte entries:
// L1 data misses 268M -> 220M, instructions 10.5G -> 11.4G. Radix heaps (keys are integers
// that never fall below the last popped) did no better: by bit, 12.1G instructions (keys span
// about 2^31, so an entry moves down up to 31 times); by byte, 10.8G instructions, 200M L1
// misses but 11% more last-level misses.
//
// The entries have since grown to 24 bytes with the edge's two ends, which the solver reads
// first when an event surfaces: loading the edge record for them was a cache miss (a fifth
// of the solver's time, perf), where the heap's top entries are in cache. square-hole-1M's
// matching 7.8 -> 6.8 s (medians of 5 alternating runs, twice), square-hole-100k 0.39 ->
// 0.35 s, uniform-100k within the noise.

#include <algorithm>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

namespace quadval::recombine_detail {

class EventQueue {
 public:
  struct Event {
    std::int64_t key;
    std::uint32_t id;
    std::uint32_t seq;   ///< queue order, the tie-break among equal keys
    std::uint32_t u, v;  ///< the caller's: an edge event's two ends (the solver's edges are 24 MB on 1M triangles)
  };

  /// @param last_seq  the queue orders run 0..last_seq before the heap is renumbered (tests
  ///                  lower it to exercise the renumbering)
  explicit EventQueue(std::uint32_t last_seq = std::numeric_limits<std::uint32_t>::max())
      : last_seq_(last_seq) {}

  /// Queues (key, id) with the caller's u and v; key == now puts it in the lane, so keys
  /// queued later must not be below now (the solver's dual value only rises).
  void push(std::int64_t key, std::uint32_t id, std::int64_t now, std::uint32_t u = 0, std::uint32_t v = 0) {
    if (seq_ >= last_seq_) renumber();
    const Event ev{key, id, seq_++, u, v};
    if (key == now)
      due_.push_back(ev);
    else
      heap_push(ev);
  }
  bool empty() const { return due_.empty() && heap_.empty(); }
  /// The first event by (key, queue order). @pre !empty()
  const Event& top() const { return from_heap() ? heap_.front() : due_.front(); }
  void pop() {
    if (from_heap())
      heap_pop();
    else
      due_.pop_front();
  }

 private:
  static bool before(const Event& a, const Event& b) {
    return a.key < b.key || (a.key == b.key && a.seq < b.seq);
  }
  bool from_heap() const {
    return due_.empty() || (!heap_.empty() && heap_.front().key <= due_.front().key);
  }
  void heap_push(const Event& ev) {
    std::size_t i = heap_.size();
    heap_.push_back(ev);
    while (i > 0) {
      const std::size_t parent = (i - 1) / 4;
      if (!before(ev, heap_[parent])) break;
      heap_[i] = heap_[parent];
      i = parent;
    }
    heap_[i] = ev;
  }
  void heap_pop() {
    const Event last = heap_.back();
    heap_.pop_back();
    const std::size_t n = heap_.size();
    if (n == 0) return;
    std::size_t i = 0;
    while (true) {
      const std::size_t first = 4 * i + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t end = std::min(first + 4, n);
      for (std::size_t c = first + 1; c < end; ++c)
        if (before(heap_[c], heap_[best])) best = c;
      if (!before(heap_[best], last)) break;
      heap_[i] = heap_[best];
      i = best;
    }
    heap_[i] = last;
  }
  // Before the queue order wraps: the heap's entries numbered again in their order (a sorted
  // array is a heap), the next push after them. The lane's order is its position; its
  // entries' seq is never compared.
  void renumber() {
    std::sort(heap_.begin(), heap_.end(), before);
    seq_ = 0;
    for (Event& ev : heap_) ev.seq = seq_++;
  }

  std::vector<Event> heap_;
  std::deque<Event> due_;
  std::uint32_t seq_ = 0;
  std::uint32_t last_seq_;
};

}  // namespace quadval::recombine_detail
