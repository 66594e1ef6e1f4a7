#include "analysis/worker_threads.hpp"

#include <pthread.h>
#include <sched.h>

#include <optional>
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

// Threads running body(1) .. body(threads - 1), started one by one on the CPUs of this
// process other than the caller's (see the header); join() waits for them, running here
// the bodies of threads that could not be created.
class Helpers {
 public:
  Helpers(int threads, const std::function<void(int)>& body) : body_(body) {
    // The CPUs this process may use, the caller's own last: new threads start on the
    // others, round robin (on the caller's CPU too when there are more threads than CPUs).
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    std::vector<int> cpus;
    const int here = sched_getcpu();
    if (pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed) == 0) {
      for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &allowed) && c != here) cpus.push_back(c);
      if (here >= 0 && CPU_ISSET(here, &allowed)) cpus.push_back(here);
    }
    starts_.resize(static_cast<std::size_t>(threads));
    for (int t = 1; t < threads; ++t) {
      Start& s = starts_[static_cast<std::size_t>(t)];
      s = Start{&body_, t, allowed};
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
      if (rc == 0) handles_.push_back(h);
      else inline_indices_.push_back(t);
    }
  }
  Helpers(const Helpers&) = delete;
  Helpers& operator=(const Helpers&) = delete;

  void join() {
    for (int t : inline_indices_) body_(t);
    for (pthread_t h : handles_) pthread_join(h, nullptr);
  }

 private:
  const std::function<void(int)>& body_;
  std::vector<Start> starts_;
  std::vector<pthread_t> handles_;
  std::vector<int> inline_indices_;  // threads that could not be created run in join()
};

}  // namespace

void run_on_threads(int threads, const std::function<void(int)>& body) {
  if (threads <= 1) {
    body(0);
    return;
  }
  Helpers helpers(threads, body);
  body(0);
  helpers.join();
}

int run_on_threads_on_demand(int threads, const std::function<void(int, const std::function<void()>&)>& body) {
  const std::function<void()> nothing = [] {};
  if (threads <= 1) {
    body(0, nothing);
    return 1;
  }
  const std::function<void(int)> helper_body = [&](int t) { body(t, nothing); };
  std::optional<Helpers> helpers;
  const std::function<void()> more = [&] {
    if (!helpers) helpers.emplace(threads, helper_body);
  };
  body(0, more);
  if (!helpers) return 1;
  helpers->join();
  return threads;
}

}  // namespace quadval
