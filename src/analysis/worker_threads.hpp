#pragma once
// Runs a function on a few threads started for one job, each on a core of its own from its
// first instruction. Internal to src/analysis (check_mesh.cpp).
//
// Why not an OpenMP parallel region: Linux starts a new thread on the CPU of the thread that
// creates it, and moves it to an idle CPU only at a later load balance (a scheduler tick,
// 4 ms here). Meanwhile the two share one core. Measured on this 2-core machine, fresh
// processes: OpenMP's second thread began its work 2-8 ms after the region opened, and a
// 1 ms analysis (tets_h0.8_o2) took 1.5 ms or 6 ms by luck. A thread created with its
// affinity set to another allowed CPU starts there in about 0.1 ms; it then widens its
// affinity back to the caller's set, so it is never pinned.

#include <functional>

namespace quadval {

/// Calls body(0) on the calling thread and body(1) ... body(threads - 1) on new threads,
/// and returns when all have returned. @pre body does not throw; threads >= 1
void run_on_threads(int threads, const std::function<void(int)>& body);

/// The same, but the other threads start only when body(0) first calls the `more` it is
/// given (later calls, and the no-op `more` of the other threads, do nothing), or never:
/// for work whose size shows only once it is under way, as a started thread costs about
/// 0.5 ms before it pays (its start, and the cold caches and memory it begins with).
/// Returns the number of threads that ran body: threads, or 1.
int run_on_threads_on_demand(int threads, const std::function<void(int, const std::function<void()>& more)>& body);

}  // namespace quadval
