#include "analysis/worker_threads.hpp"

#include <pthread.h>
#include <sched.h>

#include <vector>

namespace quadval {

namespace {

struct Start {
  const std::function<void(int)>* body;
  int index;
  cpu_set_t allowed;  // the caller's affinity, restored first thing
};

void* start_thread(void* p) {
  const Start& s = *static_cast<const Start*>(p);
  if (CPU_COUNT(&s.allowed) > 0) pthread_setaffinity_np(pthread_self(), sizeof s.allowed, &s.allowed);
  (*s.body)(s.index);
  return nullptr;
}

}  // namespace

void run_on_threads(int threads, const std::function<void(int)>& body) {
  if (threads <= 1) {
    body(0);
    return;
  }
  // The CPUs this process may use, the caller's own last: new threads start on the others,
  // round robin (on the caller's CPU too when there are more threads than CPUs).
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  std::vector<int> cpus;
  const int here = sched_getcpu();
  if (pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed) == 0) {
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &allowed) && c != here) cpus.push_back(c);
    if (here >= 0 && CPU_ISSET(here, &allowed)) cpus.push_back(here);
  }
  std::vector<Start> starts(static_cast<std::size_t>(threads));
  std::vector<pthread_t> handles;
  std::vector<int> inline_indices;  // threads that could not be created run here
  for (int t = 1; t < threads; ++t) {
    Start& s = starts[static_cast<std::size_t>(t)];
    s = Start{&body, t, allowed};
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    bool pinned = false;
    if (cpus.size() > 1) {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(cpus[static_cast<std::size_t>(t - 1) % cpus.size()], &one);
      pinned = pthread_attr_setaffinity_np(&attr, sizeof one, &one) == 0;
    }
    pthread_t h;
    int rc = pthread_create(&h, &attr, start_thread, &s);
    if (rc != 0 && pinned) rc = pthread_create(&h, nullptr, start_thread, &s);  // e.g. a CPU gone offline
    pthread_attr_destroy(&attr);
    if (rc == 0) handles.push_back(h);
    else inline_indices.push_back(t);
  }
  body(0);
  for (int t : inline_indices) body(t);
  for (pthread_t h : handles) pthread_join(h, nullptr);
}

}  // namespace quadval
