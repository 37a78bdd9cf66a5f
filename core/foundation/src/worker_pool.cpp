#include <dicestack/core/parallel.hpp>
#include <dicestack/core/worker_pool.hpp>

#include <unistd.h>

#include <chrono>
#include <utility>

namespace dicestack {
namespace {

// How long an idle thread polls before it sleeps on a futex: long enough to bridge the gap
// between two steps called from Python, short enough not to steal a loaded machine's cores.
constexpr auto kSpin = std::chrono::microseconds(50);

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

// Waits until `value` differs from `old`: polls for kSpin, then sleeps on the atomic.
template <class T>
T wait_change(const std::atomic<T>& value, T old) {
  const auto deadline = std::chrono::steady_clock::now() + kSpin;
  for (int i = 1;; ++i) {
    const T now = value.load(std::memory_order_acquire);
    if (now != old) return now;
    relax();
    if (i % 64 == 0 && std::chrono::steady_clock::now() > deadline) break;
  }
  value.wait(old, std::memory_order_acquire);
  return value.load(std::memory_order_acquire);
}

}  // namespace

WorkerPool::WorkerPool(int threads) : owner_(getpid()) {
  const int t = resolve_threads(threads);
  workers_.reserve(static_cast<std::size_t>(t - 1));
  try {
    for (int w = 1; w < t; ++w) workers_.emplace_back([this, w] { serve(w); });
  } catch (...) {  // a thread could not start: stop those that did
    stop_workers();
    throw;
  }
}

WorkerPool::~WorkerPool() { stop_workers(); }

void WorkerPool::stop_workers() {
  if (getpid() != owner_) {  // a forked child has none of the threads: nothing to join
    for (auto& t : workers_) t.detach();
    return;
  }
  stop_ = true;
  generation_.fetch_add(1, std::memory_order_acq_rel);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

void WorkerPool::take_items(int worker) {
  for (;;) {
    if (failed_.load(std::memory_order_relaxed)) return;
    const std::size_t i = next_.fetch_add(1, std::memory_order_relaxed);
    if (i >= n_) return;
    try {
      (*fn_)(i, worker);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex_);
      if (!error_) error_ = std::current_exception();
      failed_ = true;
    }
  }
}

void WorkerPool::serve(int worker) {
  std::uint64_t seen = 0;
  for (;;) {
    seen = wait_change(generation_, seen);
    if (stop_.load(std::memory_order_acquire)) return;
    take_items(worker);
    if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) running_.notify_one();
  }
}

void WorkerPool::run(std::size_t n, const std::function<void(std::size_t, int)>& fn,
                     const std::function<void()>& first) {
  if (workers_.empty() || n <= 1 || getpid() != owner_) {  // (in a forked child the threads are gone)
    std::exception_ptr first_error;
    if (first) {
      try {
        first();
      } catch (...) {
        first_error = std::current_exception();
      }
    }
    for (std::size_t i = 0; i < n; ++i) fn(i, 0);
    if (first_error) std::rethrow_exception(first_error);
    return;
  }
  n_ = n;
  fn_ = &fn;
  next_.store(0, std::memory_order_relaxed);
  failed_.store(false, std::memory_order_relaxed);
  error_ = nullptr;
  running_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_acq_rel);  // publishes the fields above
  generation_.notify_all();
  std::exception_ptr first_error;  // does not stop the loop: every item runs, as without `first`
  if (first) {
    try {
      first();
    } catch (...) {
      first_error = std::current_exception();
    }
  }
  take_items(0);
  for (int left = running_.load(std::memory_order_acquire); left != 0;
       left = running_.load(std::memory_order_acquire))
    wait_change(running_, left);
  fn_ = nullptr;
  if (auto e = std::exchange(error_, nullptr)) std::rethrow_exception(e);
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace dicestack
