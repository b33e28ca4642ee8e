// WorkerPool: threads that live as long as their map and run one job at a time together with the
// calling thread (a parallel integration, integrate.cpp). Not installed; included only by
// src/core/*. Thread-safety: run() is called by one thread at a time (the map's owner).
#ifndef WAVOG_MAPPING_SRC_CORE_UPDATE_WORKER_POOL_H_
#define WAVOG_MAPPING_SRC_CORE_UPDATE_WORKER_POOL_H_

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace wavog {
namespace detail {

class WorkerPool {
 public:
  /// Starts `threads` - 1 worker threads (the caller of run() is the last participant).
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Participants of run(): the workers and the caller.
  int threads() const { return static_cast<int>(workers_.size()) + 1; }
  /// Runs job(t) for every participant t in [0, threads()), the caller taking t = 0, and
  /// returns when all have returned. `job` must not throw.
  void run(const std::function<void(int)>& job);

  /// How long a thread polls for the next job (a worker) or for the workers to finish (the
  /// caller) before it sleeps: scans that follow each other closely (a log, four lasers) then
  /// skip the wake-up of a sleeping thread, and an idle map still costs no CPU.
  static constexpr std::int64_t kSpinMicroseconds = 100;

 private:
  void loop(int t);

  std::vector<std::thread> workers_;
  std::mutex mu_;
  std::condition_variable start_;                  // a new job, or stop
  std::condition_variable done_;                   // the last worker finished the job
  const std::function<void(int)>* job_ = nullptr;  // set before generation_ is released
  std::atomic<std::uint64_t> generation_{0};       // jobs started so far
  std::atomic<int> running_{0};                    // workers still in the current job
  std::atomic<bool> stop_{false};
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_WORKER_POOL_H_
