// WorkerPool (worker_pool.h): one atomic word holds the job's generation, whether it is closed and
// how many workers joined it. Workers poll it for a while after each job, then wait for a new
// generation on a condition variable; a worker joins an open job by incrementing the count, and
// the caller closes the job when its own part returns, then waits for the joined ones only. The
// mutex orders every sleep against every notification, so no wake-up is lost.
#include "update/worker_pool.h"

#include <sched.h>

#include <chrono>

namespace wavog {
namespace detail {
namespace {

// Polls ready() for at most `micros`, or until stop() holds (tested now and then); true as soon
// as ready() holds.
template <typename Ready, typename Stop>
bool spinUntil(std::int64_t micros, Ready ready, Stop stop) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(micros);
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (ready()) return true;
      __builtin_ia32_pause();
    }
    if (stop() || std::chrono::steady_clock::now() >= until) return ready();
  }
}

}  // namespace

WorkerPool::WorkerPool(int threads) {
  for (int t = 1; t < threads; ++t) workers_.emplace_back([this, t] { loop(t); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_.store(true, std::memory_order_release);
  }
  start_.notify_all();
  for (auto& w : workers_) w.join();
}

void WorkerPool::run(const std::function<void(int)>& job) {
  {
    // The last job is closed and no worker is in it: a new generation, open, none joined.
    std::lock_guard<std::mutex> lock(mu_);
    job_ = &job;
    caller_cpu_.store(sched_getcpu(), std::memory_order_relaxed);
    const std::uint64_t generation = state_.load(std::memory_order_relaxed) & ~(kGeneration - 1);
    state_.store(generation + kGeneration, std::memory_order_release);
  }
  start_.notify_all();
  job(0);
  const auto finished = [this] {
    return (state_.load(std::memory_order_acquire) & kJoinedMask) == 0;
  };
  // From here on no worker joins; the joined ones' writes happen before the caller goes on
  // (their release decrement, this acquire load).
  if ((state_.fetch_or(kClosed, std::memory_order_acq_rel) & kJoinedMask) == 0) return;
  if (spinUntil(kCallerSpinMicroseconds, finished, [] { return false; })) return;
  std::unique_lock<std::mutex> lock(mu_);
  done_.wait(lock, finished);
}

void WorkerPool::loop(int t) {
  std::uint64_t seen = 0;  // the generation last seen (joined or not)
  const auto ready = [&] {
    return stop_.load(std::memory_order_acquire) ||
           (state_.load(std::memory_order_acquire) & ~(kGeneration - 1)) != seen;
  };
  // A worker that finds itself on the caller's core (the scheduler may put the two there while
  // another process holds the other core) stops polling: it would only take the core from the
  // caller.
  const auto sharesCore = [this] {
    return sched_getcpu() == caller_cpu_.load(std::memory_order_relaxed);
  };
  for (;;) {
    if (!spinUntil(kSpinMicroseconds, ready, sharesCore)) {
      std::unique_lock<std::mutex> lock(mu_);
      start_.wait(lock, ready);
    }
    if (stop_.load(std::memory_order_acquire)) return;
    std::uint64_t s = state_.load(std::memory_order_acquire);
    seen = s & ~(kGeneration - 1);
    bool joined = false;
    while ((s & kClosed) == 0 && (s & ~(kGeneration - 1)) == seen) {
      if (state_.compare_exchange_weak(s, s + 1, std::memory_order_acq_rel,
                                       std::memory_order_acquire)) {
        joined = true;
        break;
      }
    }
    if (!joined) continue;  // the caller finished without this worker
    (*job_)(t);
    const std::uint64_t before = state_.fetch_sub(1, std::memory_order_acq_rel);
    if ((before & kJoinedMask) == 1 && (before & kClosed) != 0) {
      // The caller may be asleep waiting for this: notify under mu_, which it holds from its
      // test of the count to its sleep.
      std::lock_guard<std::mutex> lock(mu_);
      done_.notify_one();
    }
  }
}

}  // namespace detail
}  // namespace wavog
