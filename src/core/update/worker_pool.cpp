// WorkerPool (worker_pool.h): a generation counter that workers poll for a while after each job,
// then wait for on a condition variable; the caller polls the count of running workers the same
// way. The mutex orders every sleep against every notification, so no wake-up is lost, and every
// worker's end of a job against the caller's return.
#include "update/worker_pool.h"

#include <chrono>

namespace wavog {
namespace detail {
namespace {

// Polls ready() for at most WorkerPool::kSpinMicroseconds; true as soon as it holds.
template <typename Ready>
bool spinUntil(Ready ready) {
  const auto until =
      std::chrono::steady_clock::now() + std::chrono::microseconds(WorkerPool::kSpinMicroseconds);
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (ready()) return true;
      __builtin_ia32_pause();
    }
    if (std::chrono::steady_clock::now() >= until) return ready();
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
    std::lock_guard<std::mutex> lock(mu_);
    job_ = &job;
    running_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
  }
  start_.notify_all();
  job(0);
  if (!spinUntil([this] { return running_.load(std::memory_order_acquire) == 0; })) {
    std::unique_lock<std::mutex> lock(mu_);
    done_.wait(lock, [this] { return running_.load(std::memory_order_acquire) == 0; });
  }
  std::lock_guard<std::mutex> lock(mu_);
  job_ = nullptr;
}

void WorkerPool::loop(int t) {
  std::uint64_t seen = 0;
  const auto ready = [&] {
    return stop_.load(std::memory_order_acquire) ||
           generation_.load(std::memory_order_acquire) != seen;
  };
  for (;;) {
    const std::function<void(int)>* job;
    spinUntil(ready);
    {
      std::unique_lock<std::mutex> lock(mu_);
      start_.wait(lock, ready);
      if (stop_.load(std::memory_order_relaxed)) return;
      seen = generation_.load(std::memory_order_relaxed);
      job = job_;
    }
    (*job)(t);
    // Under mu_, which the caller takes after the job (also when it saw the count reach 0 while
    // polling): every worker's writes then happen before the caller goes on, through the mutex.
    std::lock_guard<std::mutex> lock(mu_);
    if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) done_.notify_one();
  }
}

}  // namespace detail
}  // namespace wavog
