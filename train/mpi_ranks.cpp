#include "train/mpi_ranks.hpp"

#include "gdsr/error.hpp"

#include <cstdlib>

#ifdef GDSR_WITH_MPI
#include <mpi.h>
#endif

namespace gdsr {

namespace {
// Open MPI's mpirun (and other PMIx launchers) set these in every rank's environment.
bool started_by_mpirun() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK"); }
}  // namespace

bool MpiRanks::built_with_mpi() {
#ifdef GDSR_WITH_MPI
  return true;
#else
  return false;
#endif
}

MpiRanks::MpiRanks() {
#ifdef GDSR_WITH_MPI
  if (!started_by_mpirun()) return;
  if (MPI_Init(nullptr, nullptr) != MPI_SUCCESS) gdsr::fail("mpi", "MPI_Init failed");
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  if (started_by_mpirun() && std::getenv("OMPI_COMM_WORLD_SIZE") && std::atoi(std::getenv("OMPI_COMM_WORLD_SIZE")) > 1)
    gdsr::fail("mpi", "started by mpirun, but this gdsr was built without MPI (cmake -DGDSR_MPI=ON)");
#endif
}

MpiRanks::~MpiRanks() {
#ifdef GDSR_WITH_MPI
  if (initialised_) MPI_Finalize();
#endif
}

void MpiRanks::allreduce_sum(std::vector<double>& buf) const {
#ifdef GDSR_WITH_MPI
  if (size_ > 1 &&
      MPI_Allreduce(MPI_IN_PLACE, buf.data(), static_cast<int>(buf.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD) !=
          MPI_SUCCESS)
    gdsr::fail("mpi", "MPI_Allreduce failed");
#else
  (void)buf;
#endif
}

void MpiRanks::abort_all() const {
#ifdef GDSR_WITH_MPI
  if (initialised_) MPI_Abort(MPI_COMM_WORLD, 1);
#endif
  std::exit(1);
}

}  // namespace gdsr
