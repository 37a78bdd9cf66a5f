#include <dicestack/core/mpi_cluster.hpp>

// The C API only (no deprecated C++ bindings, whatever the build system defines).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <list>
#include <mutex>
#include <thread>

namespace dicestack {
namespace {

constexpr int kToRootTag = 17;

// Test hook (tests/apps/mpi_ranks.sh): DICESTACK_MPI_TEST_FAIL=<rank>:throw makes that rank
// throw at its first collective, <rank>:exit makes it exit at once (as a killed rank would).
void injected_failure(int rank) {
  const char* spec = std::getenv("DICESTACK_MPI_TEST_FAIL");
  if (!spec) return;
  const std::string s(spec);
  const auto colon = s.find(':');
  if (colon == std::string::npos || s.substr(0, colon) != std::to_string(rank)) return;
  if (s.substr(colon + 1) == "exit") std::_Exit(3);
  throw Error("rank " + std::to_string(rank) + ": failure injected by DICESTACK_MPI_TEST_FAIL");
}

int as_count(std::size_t n) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Error("a message between ranks of " + std::to_string(n) + " bytes exceeds MPI's 2 GiB count");
  return static_cast<int>(n);
}

void check(int rc, const char* call) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  throw Error(std::string("MPI: ") + call + " failed: " + std::string(text, static_cast<std::size_t>(len)));
}

}  // namespace

struct MpiCluster::Impl {
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  std::mutex mutex;  // MPI_THREAD_SERIALIZED: one call at a time, from any thread
  std::list<std::pair<std::string, MPI_Request>> sends;  // send_to_root's buffers until delivered
  bool fail_checked = false;

  // Waits for a non-blocking call by polling with short sleeps: a rank that waits (for the
  // root's refit, for a slower rank) leaves its core to the others instead of spinning in MPI.
  void wait(MPI_Request& request) {
    auto pause = std::chrono::microseconds(20);
    while (true) {
      int done = 0;
      {
        std::lock_guard lock(mutex);
        check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test");
      }
      if (done) return;
      std::this_thread::sleep_for(pause);
      pause = std::min(pause * 2, std::chrono::microseconds(2000));
    }
  }

  void before_collective() {
    if (!fail_checked) {
      fail_checked = true;
      injected_failure(rank);
    }
  }

  void reap_sends(bool all) {
    for (auto it = sends.begin(); it != sends.end();) {
      int done = 0;
      if (all) {
        MPI_Wait(&it->second, MPI_STATUS_IGNORE);
        done = 1;
      } else {
        MPI_Test(&it->second, &done, MPI_STATUS_IGNORE);
      }
      it = done ? sends.erase(it) : std::next(it);
    }
  }
};

bool MpiCluster::launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

MpiCluster::MpiCluster(int& argc, char**& argv) : impl_(std::make_unique<Impl>()) {
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_SERIALIZED) {
    MPI_Finalize();
    throw Error("MPI provides thread level " + std::to_string(provided) + ", dicestack needs MPI_THREAD_SERIALIZED (" +
                std::to_string(MPI_THREAD_SERIALIZED) + ")");
  }
  check(MPI_Comm_dup(MPI_COMM_WORLD, &impl_->comm), "MPI_Comm_dup");
  MPI_Comm_rank(impl_->comm, &impl_->rank);
  MPI_Comm_size(impl_->comm, &impl_->size);
}

MpiCluster::~MpiCluster() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->reap_sends(true);
  }
  MPI_Comm_free(&impl_->comm);
  MPI_Finalize();
}

int MpiCluster::rank() const { return impl_->rank; }
int MpiCluster::size() const { return impl_->size; }

std::vector<std::string> MpiCluster::all_gather(std::string mine) {
  impl_->before_collective();
  const auto n = static_cast<std::size_t>(impl_->size);
  std::vector<std::uint64_t> sizes(n);
  const std::uint64_t my_size = mine.size();
  MPI_Request request;
  {
    std::lock_guard lock(impl_->mutex);
    check(MPI_Iallgather(&my_size, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, impl_->comm, &request), "MPI_Iallgather");
  }
  impl_->wait(request);
  std::vector<int> counts(n), displs(n);
  std::size_t total = 0;
  for (std::size_t r = 0; r < n; ++r) {
    counts[r] = as_count(static_cast<std::size_t>(sizes[r]));
    displs[r] = as_count(total);
    total += static_cast<std::size_t>(sizes[r]);
  }
  as_count(total);
  std::string all(total, '\0');
  {
    std::lock_guard lock(impl_->mutex);
    check(MPI_Iallgatherv(mine.data(), as_count(mine.size()), MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE,
                          impl_->comm, &request),
          "MPI_Iallgatherv");
  }
  impl_->wait(request);
  std::vector<std::string> out(n);
  for (std::size_t r = 0; r < n; ++r) out[r] = all.substr(static_cast<std::size_t>(displs[r]), static_cast<std::size_t>(counts[r]));
  return out;
}

void MpiCluster::broadcast(std::string& bytes) {
  impl_->before_collective();
  std::uint64_t n = bytes.size();
  MPI_Request request;
  {
    std::lock_guard lock(impl_->mutex);
    check(MPI_Ibcast(&n, 1, MPI_UINT64_T, 0, impl_->comm, &request), "MPI_Ibcast");
  }
  impl_->wait(request);
  if (impl_->rank != 0) bytes.assign(static_cast<std::size_t>(n), '\0');
  {
    std::lock_guard lock(impl_->mutex);
    check(MPI_Ibcast(bytes.data(), as_count(bytes.size()), MPI_BYTE, 0, impl_->comm, &request), "MPI_Ibcast");
  }
  impl_->wait(request);
}

void MpiCluster::barrier() {
  impl_->before_collective();
  MPI_Request request;
  {
    std::lock_guard lock(impl_->mutex);
    check(MPI_Ibarrier(impl_->comm, &request), "MPI_Ibarrier");
  }
  impl_->wait(request);
}

void MpiCluster::send_to_root(std::string bytes) {
  if (impl_->rank == 0) throw std::logic_error("send_to_root on the root");
  std::lock_guard lock(impl_->mutex);
  impl_->reap_sends(false);
  auto& entry = impl_->sends.emplace_back(std::move(bytes), MPI_REQUEST_NULL);
  check(MPI_Isend(entry.first.data(), as_count(entry.first.size()), MPI_BYTE, 0, kToRootTag, impl_->comm, &entry.second),
        "MPI_Isend");
}

std::vector<std::pair<int, std::string>> MpiCluster::receive(bool wait) {
  if (impl_->rank != 0) throw std::logic_error("receive on a rank other than the root");
  std::vector<std::pair<int, std::string>> out;
  auto pause = std::chrono::microseconds(20);
  while (true) {
    {
      std::lock_guard lock(impl_->mutex);
      while (true) {
        int flag = 0;
        MPI_Status status;
        check(MPI_Iprobe(MPI_ANY_SOURCE, kToRootTag, impl_->comm, &flag, &status), "MPI_Iprobe");
        if (!flag) break;
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        std::string bytes(static_cast<std::size_t>(count), '\0');
        check(MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, kToRootTag, impl_->comm, MPI_STATUS_IGNORE), "MPI_Recv");
        out.emplace_back(status.MPI_SOURCE, std::move(bytes));
      }
    }
    if (!out.empty() || !wait) return out;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(2000));
  }
}

void MpiCluster::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);  // MPI_Abort does not return; should it, end this rank anyway
}

std::string MpiCluster::host() const {
  char name[MPI_MAX_PROCESSOR_NAME];
  int len = 0;
  MPI_Get_processor_name(name, &len);
  return std::string(name, static_cast<std::size_t>(len));
}

}  // namespace dicestack
