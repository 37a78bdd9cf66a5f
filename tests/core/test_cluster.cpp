#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <condition_variable>
#include <mutex>
#include <numeric>
#include <thread>

#include <dicestack/core/cluster.hpp>

namespace dicestack {
namespace {

TEST(Cluster, LocalIsOneRootRank) {
  Cluster& c = local_cluster();
  EXPECT_EQ(c.rank(), 0);
  EXPECT_EQ(c.size(), 1);
  EXPECT_TRUE(c.is_root());
  EXPECT_EQ(c.all_gather("abc"), std::vector<std::string>{"abc"});
  std::string b = "x";
  c.broadcast(b);
  EXPECT_EQ(b, "x");
  EXPECT_TRUE(c.receive(false).empty());
}

TEST(Cluster, RoundRobinDealWithoutCosts) {
  EXPECT_EQ(deal_items(7, 3), (std::vector<int>{0, 1, 2, 0, 1, 2, 0}));
  EXPECT_EQ(deal_items(3, 1), (std::vector<int>{0, 0, 0}));
  EXPECT_TRUE(deal_items(0, 4).empty());
  EXPECT_THROW(deal_items(2, 0), std::invalid_argument);
  EXPECT_THROW(deal_items(2, 2, {1.0}), std::invalid_argument);
}

TEST(Cluster, LongestFirstDealBalancesUnevenCosts) {
  // One row 100x the others: it gets a rank to itself, the small ones share the rest.
  const std::vector<double> cost{1, 1, 100, 1, 1, 1, 1};
  const auto owner = deal_items(cost.size(), 2, cost);
  EXPECT_EQ(owner[2], 0);
  for (std::size_t i = 0; i < cost.size(); ++i) {
    if (i != 2) {
      EXPECT_EQ(owner[i], 1) << i;
    }
  }
  // Greedy LPT on a textbook case: loads 12 and 11 (optimal 11.5 is not reachable).
  const std::vector<double> c2{5, 4, 3, 3, 3, 2, 3};
  const auto o2 = deal_items(c2.size(), 2, c2);
  double load[2] = {0, 0};
  for (std::size_t i = 0; i < c2.size(); ++i) load[o2[i]] += c2[i];
  EXPECT_LE(std::max(load[0], load[1]), 12.0);
  // Ties go to the lower index and the lower rank: the same deal on every rank, every time.
  EXPECT_EQ(deal_items(4, 2, {1, 1, 1, 1}), (std::vector<int>{0, 1, 0, 1}));
}

TEST(Cluster, PackerRoundTripsEveryBit) {
  Packer p;
  const double odd = std::nextafter(0.1, 1.0);
  p.put(odd).put<int>(-3).put_string("h\0llo").put_vector(std::vector<double>{1.5, -0.0, std::numeric_limits<double>::denorm_min()});
  const std::string bytes = p.take();
  Unpacker u(bytes, "test");
  EXPECT_EQ(u.get<double>(), odd);
  EXPECT_EQ(u.get<int>(), -3);
  EXPECT_EQ(u.get_string(), "h");
  const auto v = u.get_vector<double>();
  ASSERT_EQ(v.size(), 3u);
  EXPECT_TRUE(std::signbit(v[1]));
  EXPECT_EQ(v[2], std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(u.done());
  Unpacker short_one(bytes.substr(0, 5), "a short message");
  try {
    short_one.get<double>();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("a short message: truncated"), std::string::npos);
  }
}

// A cluster of `size` ranks simulated by threads: all_gather and broadcast meet at a shared
// table, so distributed_map runs its real deal-compute-gather path without MPI.
struct ThreadRanks {
  explicit ThreadRanks(int n) : size(n), slots(static_cast<std::size_t>(n)) {}
  int size;
  std::mutex m;
  std::condition_variable cv;
  std::vector<std::string> slots;
  int arrived = 0, generation = 0;
  std::vector<std::string> gathered;
  std::vector<std::pair<int, std::string>> mailbox;  // messages to the root

  void send(int rank, std::string bytes) {
    std::lock_guard lock(m);
    mailbox.emplace_back(rank, std::move(bytes));
    cv.notify_all();
  }
  std::vector<std::pair<int, std::string>> receive(bool wait) {
    std::unique_lock lock(m);
    if (wait) cv.wait(lock, [&] { return !mailbox.empty(); });
    return std::exchange(mailbox, {});
  }

  std::vector<std::string> gather(int rank, std::string mine) {
    std::unique_lock lock(m);
    const int gen = generation;
    slots[static_cast<std::size_t>(rank)] = std::move(mine);
    if (++arrived == size) {
      gathered = slots;
      arrived = 0;
      ++generation;
      cv.notify_all();
    } else {
      cv.wait(lock, [&] { return generation != gen; });
    }
    return gathered;
  }
};

class ThreadRank final : public Cluster {
 public:
  ThreadRank(ThreadRanks& all, int rank) : all_(all), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return all_.size; }
  std::vector<std::string> all_gather(std::string mine) override { return all_.gather(rank_, std::move(mine)); }
  void broadcast(std::string& bytes) override { bytes = all_.gather(rank_, rank_ == 0 ? bytes : "")[0]; }
  void barrier() override { all_.gather(rank_, ""); }
  void send_to_root(std::string bytes) override { all_.send(rank_, std::move(bytes)); }
  std::vector<std::pair<int, std::string>> receive(bool wait) override { return all_.receive(wait); }

 private:
  ThreadRanks& all_;
  int rank_;
};

TEST(Cluster, DistributedMapGivesEveryRankAllResultsInIndexOrder) {
  const std::size_t n = 23;
  auto fn = [](std::size_t i, int) { return i * i + 1; };
  const std::function<std::string(const std::size_t&)> pack = [](const std::size_t& v) { return Packer().put(v).take(); };
  const std::function<std::size_t(std::string_view)> unpack = [](std::string_view b) { return Unpacker(b, "t").get<std::size_t>(); };
  const auto alone = distributed_map<std::size_t>(local_cluster(), n, 2, fn, pack, unpack);
  for (int ranks : {2, 3}) {
    for (bool costed : {false, true}) {
      ThreadRanks all(ranks);
      std::vector<std::vector<std::size_t>> got(static_cast<std::size_t>(ranks));
      std::atomic<int> ran{0};
      std::vector<std::thread> threads;
      std::vector<double> cost(n);
      for (std::size_t i = 0; i < n; ++i) cost[i] = static_cast<double>(i % 5);
      for (int r = 0; r < ranks; ++r)
        threads.emplace_back([&, r] {
          ThreadRank me(all, r);
          got[static_cast<std::size_t>(r)] = distributed_map<std::size_t>(
              me, n, 1, [&](std::size_t i, int w) { ++ran; return fn(i, w); }, pack, unpack,
              costed ? cost : std::vector<double>{});
        });
      for (auto& t : threads) t.join();
      EXPECT_EQ(ran, static_cast<int>(n)) << "each item runs on exactly one rank";
      for (const auto& g : got) EXPECT_EQ(g, alone);
    }
  }
}

TEST(Cluster, DealtJobsRunOnceAndEveryRankSeesEveryResult) {
  const std::size_t n = 11;
  std::vector<double> cost(n);
  for (std::size_t i = 0; i < n; ++i) cost[i] = static_cast<double>((i * 7) % 4);
  auto result = [](std::size_t i) { return "job " + std::to_string(i); };
  for (int ranks : {1, 2, 3}) {
    ThreadRanks all(ranks);
    const std::vector<int> owner = deal_items(n, ranks, cost);
    std::vector<std::vector<std::size_t>> seen(static_cast<std::size_t>(ranks));
    std::vector<std::vector<std::size_t>> ran(static_cast<std::size_t>(ranks));
    std::vector<std::thread> threads;
    for (int r = 0; r < ranks; ++r)
      threads.emplace_back([&, r] {
        ThreadRank me(all, r);
        Cluster& cluster = ranks == 1 ? local_cluster() : me;
        const auto mine = static_cast<std::size_t>(r);
        deal_jobs(
            cluster, cost,
            [&](std::size_t i, const std::function<void()>& poll) {
              ran[mine].push_back(i);
              poll();  // as a job's progress report does; no result may come twice through it
              poll();
              return result(i);
            },
            [&](std::size_t i, const std::string& bytes, int rank) {
              EXPECT_EQ(bytes, result(i));
              EXPECT_EQ(rank, owner[i]) << "the rank that ran it";
              seen[mine].push_back(i);
            });
      });
    for (auto& t : threads) t.join();
    for (int r = 0; r < ranks; ++r) {
      std::vector<std::size_t> expected;
      for (std::size_t i = 0; i < n; ++i)
        if (owner[i] == r) expected.push_back(i);
      EXPECT_EQ(ran[static_cast<std::size_t>(r)], expected) << "a rank runs its own jobs, in index order";
      std::vector<std::size_t> got = seen[static_cast<std::size_t>(r)];
      if (r == 0) std::sort(got.begin(), got.end());  // the root takes them as they come
      std::vector<std::size_t> every(n);
      std::iota(every.begin(), every.end(), std::size_t{0});
      EXPECT_EQ(got, every) << ranks << " ranks, rank " << r;
    }
  }
}

TEST(Cluster, OnRootRunsOnceAndBroadcasts) {
  EXPECT_EQ(on_root(local_cluster(), [] { return std::string("made"); }), "made");
  ThreadRanks all(3);
  std::atomic<int> calls{0};
  std::vector<std::string> got(3);
  std::vector<std::thread> threads;
  for (int r = 0; r < 3; ++r)
    threads.emplace_back([&, r] {
      ThreadRank me(all, r);
      got[static_cast<std::size_t>(r)] = on_root(me, [&] { ++calls; return std::string("model bytes"); });
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(calls, 1);
  for (const auto& g : got) EXPECT_EQ(g, "model bytes");
}

}  // namespace
}  // namespace dicestack
