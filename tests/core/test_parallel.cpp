#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/worker_pool.hpp>

namespace dicestack {
namespace {

TEST(ResolveThreads, PositiveIsItselfAndZeroIsTheCoreCount) {
  EXPECT_EQ(resolve_threads(1), 1);
  EXPECT_EQ(resolve_threads(3), 3);
  EXPECT_GE(resolve_threads(0), 1);
}

TEST(ParallelFor, CallsEveryIndexOnceWithAWorkerInRange) {
  for (const int threads : {1, 2, 4}) {
    const std::size_t n = 1000;
    std::vector<std::atomic<int>> calls(n);
    std::atomic<bool> bad_worker{false};
    parallel_for(n, threads, [&](std::size_t i, int worker) {
      if (worker < 0 || worker >= resolve_threads(threads)) bad_worker = true;
      ++calls[i];
    });
    EXPECT_FALSE(bad_worker) << threads << " threads";
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(calls[i], 1) << "index " << i << ", " << threads << " threads";
  }
}

TEST(ParallelFor, NoTwoCallsShareAWorkerAtOnce) {
  const int threads = 4;
  std::vector<std::atomic<int>> busy(static_cast<std::size_t>(resolve_threads(threads)));
  std::atomic<bool> shared{false};
  parallel_for(400, threads, [&](std::size_t i, int worker) {
    auto& flag = busy[static_cast<std::size_t>(worker)];
    if (flag.fetch_add(1) != 0) shared = true;
    double x = static_cast<double>(i);  // a little work so that calls overlap
    for (int k = 0; k < 2000; ++k) x = std::sqrt(x + k);
    if (x < 0) shared = true;
    flag.fetch_sub(1);
  });
  EXPECT_FALSE(shared);
}

TEST(ParallelFor, SlotResultsDoNotDependOnTheThreadCount) {
  // Work item i writes only slot i from its own seeded stream (STYLE 15).
  auto run = [](int threads) {
    std::vector<double> slots(257);
    parallel_for(slots.size(), threads, [&](std::size_t i, int) {
      Rng rng(derive_seed(42, i));
      double s = 0.0;
      for (int k = 0; k < 100; ++k) s += rng.normal();
      slots[i] = s;
    });
    return slots;
  };
  const auto one = run(1);
  EXPECT_EQ(run(2), one);
  EXPECT_EQ(run(4), one);
}

TEST(ParallelFor, RethrowsTheExceptionOfAnItem) {
  for (const int threads : {1, 2, 4}) {
    std::atomic<int> after{0};
    try {
      parallel_for(10000, threads, [&](std::size_t i, int) {
        if (i == 17) throw std::runtime_error("item 17 failed");
        if (i > 5000) ++after;
      });
      FAIL() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "item 17 failed");
    }
    if (threads == 1) {
      EXPECT_EQ(after, 0);  // the sequential loop stops at the throw
    }
  }
}

TEST(ParallelFor, EmptyAndSingleItemLoops) {
  int calls = 0;
  parallel_for(0, 4, [&](std::size_t, int) { ++calls; });
  EXPECT_EQ(calls, 0);
  parallel_for(1, 4, [&](std::size_t i, int worker) {
    EXPECT_EQ(i, 0u);
    EXPECT_EQ(worker, 0);
    ++calls;
  });
  EXPECT_EQ(calls, 1);
}

TEST(WorkerPool, ManyRunsCallEveryIndexOnceWithAWorkerInRange) {
  for (const int threads : {1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), resolve_threads(threads));
    for (const std::size_t n : {0u, 1u, 3u, 16u, 1000u}) {
      for (int run = 0; run < 50; ++run) {
        std::vector<std::atomic<int>> calls(n);
        std::atomic<bool> bad_worker{false};
        pool.run(n, [&](std::size_t i, int worker) {
          if (worker < 0 || worker >= pool.threads()) bad_worker = true;
          ++calls[i];
        });
        ASSERT_FALSE(bad_worker) << threads << " threads";
        for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(calls[i], 1) << "index " << i << ", n " << n;
      }
    }
  }
}

TEST(WorkerPool, NoTwoCallsShareAWorkerAtOnceAndSlotsDoNotDependOnThreads) {
  auto run = [](int threads) {
    WorkerPool pool(threads);
    std::vector<std::atomic<int>> busy(static_cast<std::size_t>(pool.threads()));
    std::atomic<bool> shared{false};
    std::vector<double> slots(64);
    for (int repeat = 0; repeat < 20; ++repeat) {
      pool.run(slots.size(), [&](std::size_t i, int worker) {
        auto& flag = busy[static_cast<std::size_t>(worker)];
        if (flag.fetch_add(1) != 0) shared = true;
        Rng rng(derive_seed(static_cast<std::uint64_t>(repeat), i));
        double s = 0.0;
        for (int k = 0; k < 200; ++k) s += rng.normal();
        slots[i] += s;
        flag.fetch_sub(1);
      });
    }
    EXPECT_FALSE(shared) << threads << " threads";
    return slots;
  };
  const auto one = run(1);
  EXPECT_EQ(run(2), one);
  EXPECT_EQ(run(4), one);
}

TEST(WorkerPool, RethrowsTheExceptionOfAnItemAndStaysUsable) {
  WorkerPool pool(3);
  for (int attempt = 0; attempt < 5; ++attempt) {
    try {
      pool.run(1000, [&](std::size_t i, int) {
        if (i == 17) throw std::runtime_error("item 17 failed");
      });
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "item 17 failed");
    }
    std::atomic<int> calls{0};
    pool.run(100, [&](std::size_t, int) { ++calls; });
    EXPECT_EQ(calls, 100);
  }
}

TEST(WorkerPool, RunsFirstOnTheCallingThreadBeforeItTakesItems) {
  for (const int threads : {1, 2}) {
    WorkerPool pool(threads);
    const auto caller = std::this_thread::get_id();
    std::atomic<bool> first_done{false};
    std::atomic<bool> caller_item_before_first{false};
    std::atomic<int> calls{0};
    pool.run(
        64,
        [&](std::size_t, int worker) {
          if (worker == 0 && !first_done) caller_item_before_first = true;
          ++calls;
        },
        [&] {
          EXPECT_EQ(std::this_thread::get_id(), caller);
          first_done = true;
        });
    EXPECT_TRUE(first_done);
    EXPECT_FALSE(caller_item_before_first) << threads << " threads";
    EXPECT_EQ(calls, 64);
    calls = 0;
    try {  // an exception from `first` comes back after every item ran, and the pool stays usable
      pool.run(64, [&](std::size_t, int) { ++calls; }, [] { throw std::runtime_error("first failed"); });
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "first failed");
    }
    EXPECT_EQ(calls, 64) << threads << " threads";
    calls = 0;
    pool.run(10, [&](std::size_t, int) { ++calls; });
    EXPECT_EQ(calls, 10);
  }
}

TEST(WorkerPool, AForkedChildRunsSequentiallyAndEndsWithoutItsParentsThreads) {
  WorkerPool pool(2);
  pool.run(8, [](std::size_t, int) {});  // the threads exist and have run
  const pid_t child = fork();
  ASSERT_NE(child, -1);
  if (child == 0) {
    int calls = 0;
    pool.run(8, [&](std::size_t, int worker) { calls += worker == 0; });
    pool.~WorkerPool();  // must not wait for threads the child does not have (_exit runs no destructor)
    _exit(calls == 8 ? 0 : 1);
  }
  int status = 0;
  for (int waited = 0; waited < 100 && waitpid(child, &status, WNOHANG) == 0; ++waited) usleep(100000);
  if (waitpid(child, &status, WNOHANG) == 0) {
    kill(child, SIGKILL);
    waitpid(child, &status, 0);
    FAIL() << "the forked child hung";
  }
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

}  // namespace
}  // namespace dicestack
