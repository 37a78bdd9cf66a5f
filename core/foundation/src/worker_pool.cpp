#include <dicestack/core/parallel.hpp>
#include <dicestack/core/worker_pool.hpp>

namespace dicestack {
namespace {

// About 20-50 µs of polling before a futex sleep: long enough to bridge the gap between two
// steps called from Python, short enough not to steal a loaded machine's cores.
constexpr int kSpins = 4000;

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

// Waits until `value` differs from `old`: spins, then sleeps on the atomic.
template <class T>
T wait_change(const std::atomic<T>& value, T old) {
  for (int i = 0; i < kSpins; ++i) {
    const T now = value.load(std::memory_order_acquire);
    if (now != old) return now;
    relax();
  }
  value.wait(old, std::memory_order_acquire);
  return value.load(std::memory_order_acquire);
}

}  // namespace

WorkerPool::WorkerPool(int threads) {
  const int t = resolve_threads(threads);
  workers_.reserve(static_cast<std::size_t>(t - 1));
  for (int w = 1; w < t; ++w) workers_.emplace_back([this, w] { serve(w); });
}

WorkerPool::~WorkerPool() {
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
      record_error();
    }
  }
}

void WorkerPool::record_error() {
  const std::lock_guard<std::mutex> lock(error_mutex_);
  if (!error_) error_ = std::current_exception();
  failed_ = true;
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
  if (workers_.empty() || n <= 1) {
    if (first) first();
    for (std::size_t i = 0; i < n; ++i) fn(i, 0);
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
  if (first) {
    try {
      first();
    } catch (...) {
      record_error();
    }
  }
  take_items(0);
  for (int left = running_.load(std::memory_order_acquire); left != 0;
       left = running_.load(std::memory_order_acquire))
    wait_change(running_, left);
  fn_ = nullptr;
  if (error_) std::rethrow_exception(error_);
}

}  // namespace dicestack
