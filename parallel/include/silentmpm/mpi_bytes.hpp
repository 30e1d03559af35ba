#pragma once
// Rank 0's bytes to every rank of comm (collective), in pieces an MPI count (an int) holds: the
// MSH text of a mesh and a packed geometry, which may exceed 2^31 - 1 bytes. Header-only, so
// that the far-field module and the MPI module share it without linking each other.
#include <mpi.h>

#include <algorithm>
#include <string>

namespace smpm {

inline void broadcast_bytes(std::string& bytes, MPI_Comm comm) {
  unsigned long long n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  bytes.resize(n);
  for (unsigned long long at = 0; at < n;) {
    const int piece = static_cast<int>(std::min<unsigned long long>(n - at, 1ull << 30));
    MPI_Bcast(bytes.data() + at, piece, MPI_CHAR, 0, comm);
    at += static_cast<unsigned long long>(piece);
  }
}

}  // namespace smpm
