#pragma once
// Helpers of the tests that run under mpirun (tests/mpi): this rank, the number of ranks, a
// maximum over them, rank 0's string, a scratch folder.
#include <mpi.h>

#include <filesystem>
#include <string>

namespace smpm::mpi_testing {

inline int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

inline double max_over_ranks(double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return v;
}

// Rank 0's string on every rank (collective).
inline std::string root_string(std::string s) {
  int n = static_cast<int>(s.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  s.resize(static_cast<std::size_t>(n));
  MPI_Bcast(s.data(), n, MPI_CHAR, 0, MPI_COMM_WORLD);
  return s;
}

// An empty folder in the temporary directory, named for the test, the rank count and `name`,
// made by rank 0 before any rank returns (collective).
inline std::filesystem::path scratch_folder(const std::string& test, const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
      ("smpm_" + test + "_" + std::to_string(world_size()) + "_" + name);
  if (world_rank() == 0) {
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return d;
}

}  // namespace smpm::mpi_testing
