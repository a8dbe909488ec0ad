// Data-parallel training over MPI (a build with cmake -DGDSR_MPI=ON and Debian's
// libopenmpi-dev): one process per rank, started by `mpirun -np N gdsr train ...`; each
// rank computes its share of every step's frames and the gradients are summed with an
// all-reduce (gdsr::TrainOptions::allreduce_sum). Without MPI in the build, or in a process
// not started by mpirun, this is one rank of one.
#pragma once

#include <vector>

namespace gdsr {

class MpiRanks {
 public:
  MpiRanks();   // MPI_Init when built with MPI and started by mpirun
  ~MpiRanks();  // MPI_Finalize
  MpiRanks(const MpiRanks&) = delete;
  MpiRanks& operator=(const MpiRanks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  static bool built_with_mpi();
  // Element-wise sum of `buf` over all ranks, in place (every rank passes the same length).
  void allreduce_sum(std::vector<double>& buf) const;
  // Ends every rank with exit status 1 (after a rank printed its error): a rank that throws
  // must not leave the others waiting in an all-reduce.
  [[noreturn]] void abort_all() const;

 private:
  int rank_ = 0, size_ = 1;
  bool initialised_ = false;
};

}  // namespace gdsr
