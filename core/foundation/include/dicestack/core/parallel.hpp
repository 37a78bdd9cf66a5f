#pragma once
// Parallel loops whose results do not depend on the thread count: work item i writes only to
// slot i, and callers reduce the slots in index order afterwards (STYLE 15).
#include <cstddef>
#include <functional>
#include <string_view>

namespace dicestack {

/// The most threads dicestack runs at once: each holds a world and a policy, and results do
/// not depend on the count.
inline constexpr int kMaxThreads = 1024;

/// Throws ConfigError unless 0 <= threads <= kMaxThreads (0: all cores), naming `what`.
void check_threads(int threads, std::string_view what = "threads");

/// Number of threads `threads` stands for: itself if > 0, else the hardware's core count.
/// Throws as check_threads does.
int resolve_threads(int threads);

/// Calls fn(i, worker) for every i in [0, n), on up to `threads` threads (0 = all cores).
/// `worker` is in [0, resolve_threads(threads)) and no two calls with the same worker run at
/// once, so it can index per-thread scratch state (one World per thread). The first exception
/// thrown by fn is rethrown here after the loop stops: the other threads start no further item.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t i, int worker)>& fn);

}  // namespace dicestack
