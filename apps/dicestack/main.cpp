#include <cstdio>
#include <iostream>

#include <dicestack/core/error.hpp>

#include "cli.hpp"

#ifdef DICESTACK_WITH_MPI
#include <chrono>
#include <thread>

#include <dicestack/core/mpi_cluster.hpp>

namespace {

// Under mpirun or srun (docs/scaling.md): the root alone prints (the other ranks' std::cout and
// std::cerr are silenced); an error on any rank is printed once and ends every rank through
// MPI_Abort, so that nothing waits for a rank that failed; a normal end meets the other ranks
// and finalises MPI.
int run_as_rank(int argc, char** argv) {
  dicestack::MpiCluster cluster(argc, argv);
  if (!cluster.is_root()) {
    std::cout.setstate(std::ios::badbit);
    std::cerr.setstate(std::ios::badbit);
  }
  const int code = dicestack::cli::run(argc, argv, cluster, [&](const std::string& message, int status) -> int {
    // An error every rank meets (a bad option, a missing file) is printed by the root, whose
    // MPI_Abort ends the others while they wait; an error on one other rank only is printed by it.
    if (!cluster.is_root()) std::this_thread::sleep_for(std::chrono::seconds(1));
    const std::string where = cluster.is_root() ? "" : " (rank " + std::to_string(cluster.rank()) + " of " +
                                                           std::to_string(cluster.size()) + " on " + cluster.host() + ")";
    std::fprintf(stderr, "%s%s; ending all %d ranks\n", message.c_str(), where.c_str(), cluster.size());
    std::fflush(stderr);
    cluster.abort(status);
  });
  cluster.barrier();
  return code;
}

}  // namespace
#endif

int main(int argc, char** argv) {
#ifdef DICESTACK_WITH_MPI
  if (dicestack::MpiCluster::launched()) {
    try {
      return run_as_rank(argc, argv);
    } catch (const std::exception& e) {  // MPI itself failed to start
      std::fprintf(stderr, "dicestack: error: %s\n", dicestack::readable_message(e.what()).c_str());
      return 1;
    }
  }
#endif
  return dicestack::cli::run(argc, argv);
}
