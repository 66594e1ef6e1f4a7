// run_on_threads: every index once, index 0 on the caller, the others on threads of their
// own, which run with the caller's CPU affinity (placed on another CPU to start, never
// left pinned there). run_on_threads_on_demand: the others only once index 0 asks.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <functional>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "analysis/worker_threads.hpp"

namespace quadval {
namespace {

cpu_set_t affinity() {
  cpu_set_t s;
  CPU_ZERO(&s);
  EXPECT_EQ(pthread_getaffinity_np(pthread_self(), sizeof s, &s), 0);
  return s;
}

TEST(WorkerThreads, EveryIndexOnceOnThreadsOfTheirOwn) {
  for (int threads : {1, 2, 3, 7}) {
    SCOPED_TRACE(threads);
    const cpu_set_t callers = affinity();
    std::mutex m;
    std::vector<int> calls(static_cast<std::size_t>(threads), 0);
    std::set<std::thread::id> ids;
    std::vector<char> same_affinity(static_cast<std::size_t>(threads), 0);
    run_on_threads(threads, [&](int t) {
      const cpu_set_t mine = affinity();
      const std::lock_guard<std::mutex> lock(m);
      ++calls[static_cast<std::size_t>(t)];
      ids.insert(std::this_thread::get_id());
      same_affinity[static_cast<std::size_t>(t)] = CPU_EQUAL(&mine, &callers);
    });
    for (int t = 0; t < threads; ++t) {
      EXPECT_EQ(calls[static_cast<std::size_t>(t)], 1) << "index " << t;
      EXPECT_TRUE(same_affinity[static_cast<std::size_t>(t)]) << "index " << t;
    }
    EXPECT_EQ(ids.size(), static_cast<std::size_t>(threads));
    const cpu_set_t after = affinity();
    EXPECT_TRUE(CPU_EQUAL(&after, &callers));  // the caller's own is untouched
  }
}

TEST(WorkerThreads, IndexZeroRunsOnTheCaller) {
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id zero;
  std::mutex m;
  run_on_threads(3, [&](int t) {
    if (t != 0) return;
    const std::lock_guard<std::mutex> lock(m);
    zero = std::this_thread::get_id();
  });
  EXPECT_EQ(zero, caller);
}

TEST(WorkerThreads, OnDemandRunsOthersOnlyWhenAsked) {
  std::mutex m;
  std::vector<int> calls(4, 0);
  const auto count = [&](int t) {
    const std::lock_guard<std::mutex> lock(m);
    ++calls[static_cast<std::size_t>(t)];
  };
  // Never asked: index 0 alone.
  EXPECT_EQ(run_on_threads_on_demand(4, [&](int t, const std::function<void()>&) { count(t); }), 1);
  EXPECT_EQ(calls, (std::vector<int>{1, 0, 0, 0}));
  // Asked (twice by index 0, and by the others, whose `more` does nothing): every index once.
  calls.assign(4, 0);
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id zero;
  EXPECT_EQ(run_on_threads_on_demand(4,
                                     [&](int t, const std::function<void()>& more) {
                                       more();
                                       more();
                                       if (t == 0) zero = std::this_thread::get_id();
                                       count(t);
                                     }),
            4);
  EXPECT_EQ(calls, (std::vector<int>{1, 1, 1, 1}));
  EXPECT_EQ(zero, caller);
  // One thread: nothing to start.
  calls.assign(4, 0);
  EXPECT_EQ(run_on_threads_on_demand(1, [&](int t, const std::function<void()>& more) { more(); count(t); }), 1);
  EXPECT_EQ(calls, (std::vector<int>{1, 0, 0, 0}));
}

}  // namespace
}  // namespace quadval
