#pragma once
// Threads kept alive between loops, for loops run thousands of times a second (a vector env's
// step): parallel_for starts its workers on every call, which costs more than a short loop.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace dicestack {

/// parallel_for's contract (fn(i, worker) for every i, worker in [0, threads()), no two calls on
/// one worker at once, the first exception rethrown) over threads started once. The calling
/// thread is worker 0 and works too; idle workers poll for 50 µs, then sleep. One run at a time.
/// In a child forked from the creating process the threads are gone: runs there are sequential.
class WorkerPool {
 public:
  /// `threads` as in parallel_for (0 = all cores); threads() - 1 threads are started.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls fn(i, worker) for every i in [0, n). `first`, if given, runs on the calling thread
  /// after the workers start and before it takes items: work that must stay on this thread
  /// (making Python objects) overlaps the loop. Its exception does not stop the loop: it is
  /// rethrown after every item ran (an item's exception, which does stop it, comes first).
  void run(std::size_t n, const std::function<void(std::size_t i, int worker)>& fn,
           const std::function<void()>& first = {});

 private:
  void serve(int worker);
  void take_items(int worker);
  void stop_workers();

  int owner_;  // the process that started the threads
  std::vector<std::thread> workers_;
  std::atomic<std::uint64_t> generation_{0};  // bumped to start a run (or to stop, with stop_)
  std::atomic<int> running_{0};               // background workers not yet done with this run
  std::atomic<std::size_t> next_{0};
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::size_t n_ = 0;
  const std::function<void(std::size_t, int)>* fn_ = nullptr;
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

}  // namespace dicestack
