#pragma once
// Several processes working on one job: the MPI-free interface the libraries see.
// A Cluster is a fixed set of ranks 0..size()-1 that run the same program on the same inputs
// and meet in collective calls (all_gather, broadcast, barrier), which every rank must make in
// the same order. Rank 0 is the root: it alone writes files and reports progress.
//
// The libraries never create a cluster. They take one by reference through their options
// (LearnContext::cluster, LeaderboardRequest::cluster, the `cluster` argument of evaluate and
// record_expert) and default to local_cluster(), the single process. The `dicestack` tool makes
// an MPI cluster (dicestack/core/mpi_cluster.hpp, its own target) when it was started by mpirun
// or srun and passes it down; MPI_COMM_WORLD appears in that one file and nowhere else.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <dicestack/core/error.hpp>

namespace dicestack {

class Cluster {
 public:
  virtual ~Cluster() = default;

  /// This process's rank, in [0, size()).
  virtual int rank() const = 0;
  /// Number of ranks, >= 1.
  virtual int size() const = 0;
  /// Rank 0: writes the outputs and reports progress; the other ranks stay silent.
  bool is_root() const { return rank() == 0; }

  /// Collective: every rank passes its bytes; every rank receives all ranks' bytes, in rank order.
  virtual std::vector<std::string> all_gather(std::string mine) = 0;
  /// Collective: the root's `bytes` replace every other rank's.
  virtual void broadcast(std::string& bytes) = 0;
  /// Collective: returns when every rank has called it.
  virtual void barrier() = 0;

  /// A message from a non-root rank to the root, sent without waiting (the root picks it up with
  /// receive()). Messages from one rank arrive in the order they were sent. Not on the root.
  virtual void send_to_root(std::string bytes) = 0;
  /// Root: the messages that have arrived so far, as (sender rank, bytes); with `wait`, blocks
  /// until at least one has. Not on other ranks.
  virtual std::vector<std::pair<int, std::string>> receive(bool wait) = 0;
};

/// The single process: rank 0 of 1. Stateless; shared by every default argument.
Cluster& local_cluster();

/// Which rank runs each of `n` items: round-robin (item i on rank i % ranks) when `cost` is
/// empty; otherwise longest-processing-time first (items by decreasing cost, ties by index, each
/// to the rank with the least cost so far, ties to the lower rank). The same on every rank.
/// Throws std::invalid_argument if `cost` is neither empty nor of size n, or ranks < 1.
std::vector<int> deal_items(std::size_t n, int ranks, const std::vector<double>& cost = {});

/// Plain values as bytes, for results that travel between ranks (same build, same machine type:
/// native byte order, no versioning). Doubles keep every bit.
class Packer {
 public:
  template <class T>
  Packer& put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&value), sizeof(T));
    return *this;
  }
  Packer& put_string(std::string_view s) {
    put<std::uint64_t>(s.size());
    out_.append(s);
    return *this;
  }
  template <class T>
  Packer& put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<std::uint64_t>(v.size());
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    return *this;
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

/// Reads what a Packer wrote; throws Error("<what>: truncated") when the bytes run out.
class Unpacker {
 public:
  Unpacker(std::string_view bytes, std::string what) : in_(bytes), what_(std::move(what)) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T value;
    std::memcpy(&value, in_.data(), sizeof(T));
    in_.remove_prefix(sizeof(T));
    return value;
  }
  std::string get_string() {
    const auto n = static_cast<std::size_t>(get<std::uint64_t>());
    need(n);
    std::string s(in_.substr(0, n));
    in_.remove_prefix(n);
    return s;
  }
  template <class T>
  std::vector<T> get_vector() {
    const auto n = static_cast<std::size_t>(get<std::uint64_t>());
    if (n > in_.size() / sizeof(T)) need(in_.size() + 1);
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), in_.data(), n * sizeof(T));
    in_.remove_prefix(n * sizeof(T));
    return v;
  }
  bool done() const { return in_.empty(); }

 private:
  void need(std::size_t n) const {
    if (in_.size() < n) throw Error(what_ + ": truncated message between ranks");
  }
  std::string_view in_;
  std::string what_;
};

/// The bytes of `n` items, computed where `deal_items(n, cluster.size(), cost)` puts them: each
/// rank runs its own items with parallel_for on `threads` threads (fn(i, worker), worker as in
/// parallel_for), then the ranks all-gather the results. Returns every item's bytes in index
/// order, on every rank. Collective. An exception from fn is rethrown on its own rank (the tool
/// then ends the whole run; see docs/scaling.md).
std::vector<std::string> distributed_map_bytes(Cluster& cluster, std::size_t n, int threads,
                                               const std::function<std::string(std::size_t i, int worker)>& fn,
                                               const std::vector<double>& cost = {});

/// distributed_map_bytes for results of type T: `pack` and `unpack` convert one result (and
/// must round-trip it exactly). With a single rank, nothing is packed: fn's results are returned.
template <class T>
std::vector<T> distributed_map(Cluster& cluster, std::size_t n, int threads, const std::function<T(std::size_t, int)>& fn,
                               const std::function<std::string(const T&)>& pack,
                               const std::function<T(std::string_view)>& unpack, const std::vector<double>& cost = {});

/// `cost.size()` jobs, each run whole (it may use the rank's threads) on the rank that
/// deal_items gives it, a rank's own jobs in index order. Every rank sees every result once
/// through `arrived(i, bytes, rank that ran it)`: the root as results come in (after each of its
/// own jobs, and whenever one of them calls `poll`: at most once a second, and a call from
/// inside `arrived` or from a second thread meanwhile returns at once; `arrived` then runs on
/// the polling thread, beside the job's other threads), the other ranks at the end, in index
/// order. A non-root rank sends each result to the root as it finishes; the root broadcasts
/// them all at the end. Collective. On one rank the jobs run in index order. An exception from
/// `run` on a non-root rank leaves the root waiting: the tool then ends the whole run, as for
/// distributed_map (docs/scaling.md).
void deal_jobs(Cluster& cluster, const std::vector<double>& cost,
               const std::function<std::string(std::size_t i, const std::function<void()>& poll)>& run,
               const std::function<void(std::size_t i, const std::string& bytes, int rank)>& arrived);

/// Runs `fn` on the root only and gives every rank its bytes (a refit, a file read once).
/// Collective.
std::string on_root(Cluster& cluster, const std::function<std::string()>& fn);

}  // namespace dicestack

#include <dicestack/core/parallel.hpp>

namespace dicestack {

template <class T>
std::vector<T> distributed_map(Cluster& cluster, std::size_t n, int threads, const std::function<T(std::size_t, int)>& fn,
                               const std::function<std::string(const T&)>& pack,
                               const std::function<T(std::string_view)>& unpack, const std::vector<double>& cost) {
  std::vector<T> out(n);
  if (cluster.size() == 1) {
    parallel_for(n, threads, [&](std::size_t i, int w) { out[i] = fn(i, w); });
    return out;
  }
  const auto bytes = distributed_map_bytes(cluster, n, threads, [&](std::size_t i, int w) { return pack(fn(i, w)); }, cost);
  for (std::size_t i = 0; i < n; ++i) out[i] = unpack(bytes[i]);
  return out;
}

}  // namespace dicestack
