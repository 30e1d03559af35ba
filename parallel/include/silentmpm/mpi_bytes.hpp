#pragma once
// Messages larger than an MPI count (an int) holds, in pieces. Header-only, so that the
// far-field module and the MPI module share them without linking each other.
#include <mpi.h>

#include <algorithm>
#include <string>
#include <vector>

namespace smpm {

// Rank 0's values (a string or a vector of `type`) to every rank of comm (collective), in
// pieces of at most 2^30: the whole may exceed 2^31 - 1 values.
template <class C>
void broadcast_all(C& v, MPI_Datatype type, MPI_Comm comm) {
  unsigned long long n = v.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  v.resize(n);
  for (unsigned long long at = 0; at < n;) {
    const int piece = static_cast<int>(std::min<unsigned long long>(n - at, 1ull << 30));
    MPI_Bcast(v.data() + at, piece, type, 0, comm);
    at += static_cast<unsigned long long>(piece);
  }
}

// Rank 0's bytes to every rank of comm (collective): the MSH text of a mesh and a packed
// geometry, which may exceed 2^31 - 1 bytes.
inline void broadcast_bytes(std::string& bytes, MPI_Comm comm) {
  broadcast_all(bytes, MPI_CHAR, comm);
}

// Every rank's values to rank 0 (collective), joined in rank order, rank by rank in messages of
// at most `piece` values, so that the whole may hold more than 2^31 - 1 of them. On rank 0
// counts[r] is rank r's count.
inline void gather_doubles(const std::vector<double>& mine, std::vector<double>& on_root,
                           std::vector<long long>& counts, MPI_Comm comm, long long piece) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const long long n = static_cast<long long>(mine.size());
  counts.assign(static_cast<std::size_t>(size), 0);
  MPI_Gather(&n, 1, MPI_LONG_LONG, counts.data(), 1, MPI_LONG_LONG, 0, comm);
  constexpr int kTag = 7302;
  if (rank != 0) {
    for (long long at = 0; at < n; at += piece)
      MPI_Send(mine.data() + at, static_cast<int>(std::min(piece, n - at)), MPI_DOUBLE, 0, kTag,
               comm);
    return;
  }
  long long total = 0;
  for (const long long c : counts) total += c;
  on_root.resize(static_cast<std::size_t>(total));
  std::copy(mine.begin(), mine.end(), on_root.begin());
  long long from = n;
  for (int r = 1; r < size; ++r) {
    for (long long at = 0; at < counts[r]; at += piece)
      MPI_Recv(on_root.data() + from + at, static_cast<int>(std::min(piece, counts[r] - at)),
               MPI_DOUBLE, r, kTag, comm, MPI_STATUS_IGNORE);
    from += counts[r];
  }
}

}  // namespace smpm
