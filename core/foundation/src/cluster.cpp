#include <dicestack/core/cluster.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>
#include <stdexcept>

namespace dicestack {
namespace {

class LocalCluster final : public Cluster {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  std::vector<std::string> all_gather(std::string mine) override { return {std::move(mine)}; }
  void broadcast(std::string&) override {}
  void barrier() override {}
  void send_to_root(std::string) override { throw std::logic_error("send_to_root on the root of a single process"); }
  std::vector<std::pair<int, std::string>> receive(bool wait) override {
    if (wait) throw std::logic_error("receive(wait) on a single process would never return");
    return {};
  }
};

}  // namespace

Cluster& local_cluster() {
  static LocalCluster local;  // stateless
  return local;
}

std::vector<int> deal_items(std::size_t n, int ranks, const std::vector<double>& cost) {
  if (ranks < 1) throw std::invalid_argument("deal_items: ranks must be >= 1");
  if (!cost.empty() && cost.size() != n) throw std::invalid_argument("deal_items: one cost per item");
  std::vector<int> owner(n, 0);
  if (cost.empty()) {
    for (std::size_t i = 0; i < n; ++i) owner[i] = static_cast<int>(i % static_cast<std::size_t>(ranks));
    return owner;
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost[a] > cost[b]; });
  std::vector<double> load(static_cast<std::size_t>(ranks), 0.0);
  for (std::size_t i : order) {
    const auto r = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = static_cast<int>(r);
    load[r] += cost[i];
  }
  return owner;
}

std::vector<std::string> distributed_map_bytes(Cluster& cluster, std::size_t n, int threads,
                                               const std::function<std::string(std::size_t, int)>& fn,
                                               const std::vector<double>& cost) {
  const std::vector<int> owner = deal_items(n, cluster.size(), cost);
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < n; ++i)
    if (owner[i] == cluster.rank()) mine.push_back(i);
  std::vector<std::string> results(mine.size());
  parallel_for(mine.size(), threads, [&](std::size_t k, int w) { results[k] = fn(mine[k], w); });
  Packer p;
  for (std::size_t k = 0; k < mine.size(); ++k) p.put<std::uint64_t>(mine[k]).put_string(results[k]);
  results.clear();
  std::vector<std::string> out(n);
  std::vector<bool> seen(n, false);
  for (const std::string& blob : cluster.all_gather(p.take())) {
    Unpacker u(blob, "distributed_map");
    while (!u.done()) {
      const auto i = static_cast<std::size_t>(u.get<std::uint64_t>());
      if (i >= n || seen[i]) throw Error("distributed_map: item " + std::to_string(i) + " arrived twice or out of range");
      out[i] = u.get_string();
      seen[i] = true;
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!seen[i]) throw Error("distributed_map: no rank returned item " + std::to_string(i));
  return out;
}

void deal_jobs(Cluster& cluster, const std::vector<double>& cost,
               const std::function<std::string(std::size_t, const std::function<void()>&)>& run,
               const std::function<void(std::size_t, const std::string&, int)>& arrived) {
  const std::size_t n = cost.size();
  const std::vector<int> owner = deal_items(n, cluster.size(), cost);
  std::vector<std::string> results(n);
  std::vector<bool> seen(n, false);
  std::size_t count = 0;
  auto take = [&](std::size_t i, std::string bytes, int rank) {
    results[i] = std::move(bytes);
    seen[i] = true;
    ++count;
    arrived(i, results[i], rank);
  };
  // Root: the results other ranks have sent so far (or, with `wait`, at least one).
  auto take_arrivals = [&](bool wait) {
    for (auto& [rank, bytes] : cluster.receive(wait)) {
      Unpacker u(bytes, "deal_jobs: result from rank " + std::to_string(rank));
      const auto i = static_cast<std::size_t>(u.get<std::uint64_t>());
      if (i >= n || seen[i] || owner[i] != rank)
        throw Error("deal_jobs: rank " + std::to_string(rank) + " sent result " + std::to_string(i) + " unexpectedly");
      take(i, u.get_string(), rank);
    }
  };
  // Set while the root takes results: a poll meanwhile (from `arrived`, or a second thread)
  // returns at once.
  std::atomic<bool> taking{false};
  struct Taking {
    std::atomic<bool>& flag;
    ~Taking() { flag = false; }
  };
  std::chrono::steady_clock::time_point last_poll{};
  const std::function<void()> poll = [&] {
    if (cluster.size() == 1 || !cluster.is_root() || taking.exchange(true)) return;
    const Taking release{taking};
    const auto now = std::chrono::steady_clock::now();
    if (now - last_poll < std::chrono::seconds(1)) return;
    last_poll = now;
    take_arrivals(false);
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (owner[i] != cluster.rank()) continue;
    std::string bytes = run(i, poll);
    if (cluster.is_root()) {
      taking = true;
      const Taking release{taking};
      take(i, std::move(bytes), cluster.rank());
      if (cluster.size() > 1) take_arrivals(false);
    } else {
      cluster.send_to_root(Packer().put<std::uint64_t>(i).put_string(bytes).take());
    }
  }
  if (cluster.size() == 1) return;
  if (cluster.is_root()) {
    taking = true;
    const Taking release{taking};
    while (count < n) take_arrivals(true);
  }
  Packer all;
  if (cluster.is_root())
    for (const std::string& r : results) all.put_string(r);
  std::string bytes = all.take();
  cluster.broadcast(bytes);
  if (cluster.is_root()) return;
  Unpacker u(bytes, "deal_jobs: results from rank 0");
  for (std::size_t i = 0; i < n; ++i) arrived(i, u.get_string(), owner[i]);
}

std::string on_root(Cluster& cluster, const std::function<std::string()>& fn) {
  std::string bytes;
  if (cluster.is_root()) bytes = fn();
  if (cluster.size() > 1) cluster.broadcast(bytes);
  return bytes;
}

}  // namespace dicestack
