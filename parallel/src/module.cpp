// The MPI module's table (cases/src/modules.hpp): the program loads libsilentmpm_mpi.so only
// when an MPI launcher started it.
#include <mpi.h>

#include <string>

#include "modules.hpp"
#include "silentmpm/distributed.hpp"
#include "silentmpm/mpi_bytes.hpp"
#include "silentmpm/solver.hpp"
#include "silentmpm/state_write.hpp"

namespace smpm::detail {
namespace {

void start(int* argc, char*** argv) { parallel_init(argc, argv); }
void stop() { parallel_finalize(); }
int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}
std::unique_ptr<Decomposition> distribute(Solver& s, int across, bool scatter) {
  return std::make_unique<Distributed>(s, MPI_COMM_WORLD, across, scatter);
}
bool any(bool b) {
  int v = b ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  return v != 0;
}
void abort(int code) { MPI_Abort(MPI_COMM_WORLD, code); }
void broadcast(std::string& bytes) { broadcast_bytes(bytes, MPI_COMM_WORLD); }

const void* world() {
  static const MPI_Comm w = MPI_COMM_WORLD;
  return &w;
}
const void* no_info() {
  static const MPI_Info i = MPI_INFO_NULL;
  return &i;
}

void write_state(const StateWriter& w, const std::string& path) {
  write_state_collectively(w, path, MPI_COMM_WORLD);
}

const MpiModule kTable = {kMpiModuleApi, start, stop,  rank,      size,    distribute,
                          any,           abort, broadcast, world, no_info, write_state};

}  // namespace
}  // namespace smpm::detail

extern "C" const smpm::detail::MpiModule* silentmpm_mpi_module() { return &smpm::detail::kTable; }
