// WorkerPool: threads that live as long as their map and help the calling thread with one job at
// a time (a scan's preparation and its blocks' update, integrate.cpp). Not installed; included
// only by src/core/*. Thread-safety: run() is called by one thread at a time (the map's owner).
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
  /// Runs job(0) on the caller and job(t) on each worker t that joins before the caller's job(0)
  /// has returned; returns when the caller's and every joined worker's job have returned. A
  /// worker that is late (asleep, or without a core) does not join, and the caller does not wait
  /// for it: job must let the caller alone do all the work (the participants take their pieces
  /// from a shared counter), the workers only help. `job` must not throw.
  void run(const std::function<void(int)>& job);

  /// How long a thread polls for the next job (a worker) or for the joined workers to finish (the
  /// caller) before it sleeps: scans that follow each other closely (a log, four lasers) then
  /// skip the wake-up of a sleeping thread, and an idle map still costs no CPU.
  static constexpr std::int64_t kSpinMicroseconds = 100;
  /// How long the caller polls for the joined workers to finish before it sleeps: about the
  /// longest piece of work one of them may still be in, so that a worker that cannot run (its
  /// core taken, or the caller's) is not waited for by polling.
  static constexpr std::int64_t kCallerSpinMicroseconds = 20;

 private:
  void loop(int t);

  // state_: the job's generation (bits 32-63), kClosed once the caller's job(0) has returned (no
  // worker joins after it), and the joined workers still in the job (bits 0-30).
  static constexpr std::uint64_t kClosed = std::uint64_t{1} << 31;
  static constexpr std::uint64_t kJoinedMask = kClosed - 1;
  static constexpr std::uint64_t kGeneration = std::uint64_t{1} << 32;

  std::vector<std::thread> workers_;
  std::mutex mu_;
  std::condition_variable start_;                  // a new job, or stop
  std::condition_variable done_;                   // the last joined worker left a closed job
  const std::function<void(int)>* job_ = nullptr;  // set before the generation is released
  std::atomic<std::uint64_t> state_{kClosed};      // generation 0: closed, nothing to join
  std::atomic<bool> stop_{false};
  std::atomic<int> caller_cpu_{-1};  // the core the caller was on when it started the job
};

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_UPDATE_WORKER_POOL_H_
