// The processes of a run (driver.hpp): one, or the ranks of an MPI launch through the MPI module.
#include <cstdlib>
#include <stdexcept>

#include "modules.hpp"
#include "silentmpm/driver.hpp"

namespace smpm {

namespace {

const detail::MpiModule* g_mpi = nullptr;

// The variables a launcher sets in every process it starts (Open MPI, MPICH's hydra, PMIx).
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (const char* s = std::getenv(v); s && *s) return true;
  return false;
}

}  // namespace

namespace detail {
const MpiModule* mpi() { return g_mpi; }
}  // namespace detail

void start_processes(int* argc, char*** argv) {
  if (g_mpi || !launched_by_mpi()) return;
  const detail::MpiModule& m = detail::mpi_module();
  m.start(argc, argv);
  g_mpi = &m;
}

void stop_processes() {
  if (g_mpi) g_mpi->stop();
  g_mpi = nullptr;
}

int process_rank() { return g_mpi ? g_mpi->rank() : 0; }
int process_count() { return g_mpi ? g_mpi->size() : 1; }

void abort_processes(int code) {
  if (g_mpi && g_mpi->size() > 1) g_mpi->abort(code);
  std::exit(code);
}

}  // namespace smpm
