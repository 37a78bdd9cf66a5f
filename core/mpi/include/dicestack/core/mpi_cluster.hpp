#pragma once
// The MPI implementation of Cluster. Its own library target, dicestack::mpi, linked
// by the `dicestack` tool and the MPI tests only: the other libraries, the Python module and
// regressor plugins neither link MPI nor include <mpi.h> (this header does not).
//
// MPI_COMM_WORLD is used in mpi_cluster.cpp alone: the cluster works on a duplicate of it and
// every MPI call goes through one object, created once in main() and passed down by reference.
#include <memory>
#include <string>

#include <dicestack/core/cluster.hpp>

namespace dicestack {

class MpiCluster final : public Cluster {
 public:
  /// True when a launcher started this process as an MPI rank: mpirun/mpiexec (Open MPI's
  /// OMPI_COMM_WORLD_SIZE, or PMI_SIZE / PMIX_RANK as Slurm's srun and MPICH's hydra set).
  /// Without one the tool runs as a single process and never initialises MPI.
  static bool launched();

  /// MPI_Init_thread asking for MPI_THREAD_SERIALIZED (any thread may call, one at a time: a
  /// mutex here serialises them). Throws Error if MPI gives less. Creates one per process.
  MpiCluster(int& argc, char**& argv);
  /// Waits for messages still being sent, then MPI_Finalize. Only after a normal end; an error
  /// ends the run through abort() instead.
  ~MpiCluster() override;
  MpiCluster(const MpiCluster&) = delete;
  MpiCluster& operator=(const MpiCluster&) = delete;

  int rank() const override;
  int size() const override;
  std::vector<std::string> all_gather(std::string mine) override;
  void broadcast(std::string& bytes) override;
  void barrier() override;
  void send_to_root(std::string bytes) override;
  std::vector<std::pair<int, std::string>> receive(bool wait) override;

  /// Ends every rank at once with exit status `code` (MPI_Abort): the run does not wait for a
  /// collective that a failed rank will never join.
  [[noreturn]] void abort(int code);

  /// The host name this rank runs on (MPI_Get_processor_name).
  std::string host() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dicestack
