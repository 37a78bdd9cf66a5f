#include <dicestack/core/parallel.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/interrupt.hpp>

#include <string>
#include <thread>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

namespace dicestack {

void check_threads(int threads, std::string_view what) {
  if (threads < 0 || threads > kMaxThreads)
    throw ConfigError(std::string(what) + ": " + std::to_string(threads) + " is not in [0, " + std::to_string(kMaxThreads) +
                      "] (0: all cores; results do not depend on the count)");
}

int resolve_threads(int threads) {
  check_threads(threads);
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t, int)>& fn) {
  const int t = resolve_threads(threads);
  if (t == 1 || n <= 1) {
    for (std::size_t i = 0; i < n; ++i) {
      throw_if_interrupted();
      fn(i, 0);
    }
    return;
  }
  tbb::task_arena arena(t);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      const int worker = tbb::this_task_arena::current_thread_index();
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        // After an item threw, the other threads stop at their next item, not at the end of
        // their chunk (which can hold most of the loop): an interrupted evaluation ends at once.
        if (tbb::is_current_task_group_canceling()) return;
        throw_if_interrupted();  // Ctrl-C on the command line: unwinds like an error
        fn(i, worker);
      }
    });
  });
}

}  // namespace dicestack
