#pragma once
// The run driver: steps a Case to t_end, samples probes and energies into history.csv, writes
// snapshots and summary.json, prints progress.
#include <stdexcept>
#include <string>

#include "silentmpm/case.hpp"

namespace smpm {

struct RunResult {
  long steps = 0;
  long steps_run = 0;  // the steps this run made (steps less a restart's first)
  double wall_seconds = 0;
  double particle_updates_per_second = 0;
  std::size_t particles = 0;            // MPM region, over every rank
  std::size_t dofs = 0;                 // FEM region
  double dof_updates_per_second = 0;    // FEM region
};

// A run that started and then failed (instability, a particle leaving the grid, an I/O error):
// the command exits 2. DIR/RUN_INCOMPLETE says why; the last checkpoint, if any, is kept. A step
// that fails (a health check, a particle leaving the grid) also leaves its state for inspection:
// DIR/failed.smpm (a checkpoint of the failed step) and, when the case writes snapshots, a last
// snapshot of it.
struct RunFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A run stopped by SIGINT or SIGTERM after finishing its step: it wrote DIR/checkpoint.smpm, the
// history and snapshots so far and DIR/RUN_INCOMPLETE (no summary.json); the command exits 3.
struct RunInterrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RunOptions {
  // A checkpoint to continue from ("": start at t = 0). It must come from the same case (the
  // same keys and values, except output.*, time.end and scheme.threads) and the same version.
  std::string restart;
  // Under an MPI launcher: ranks across x of the blocks (1: slabs of rows); 0 picks the layout
  // with the fewest nodes shared.
  int ranks_across = 0;
};

// Runs the case and writes DIR/history.csv, DIR/summary.json, DIR/particles.{h5,xdmf}, and
// DIR/checkpoint.smpm when the case asks for checkpoints. summary.json is written last, so its
// presence marks a complete run. Throws CaseError/StateError for an unusable restart file
// (before the output folder is touched), RunFailure and RunInterrupted as above.
RunResult run_case(Case& c, const std::string& out_dir, const RunOptions& opt = {});

// The processes of a run. A program started by an MPI launcher (mpirun; Open MPI, MPICH or a
// PMIx launcher) runs an MPM case on every rank, each with a slab of the particles and the grid
// (docs/parallel.md); otherwise it is one process. start_processes loads the MPI module and
// starts MPI when a launcher is seen (a std::runtime_error when the module is missing), and
// does nothing otherwise; stop_processes ends MPI. Under several ranks only rank 0 writes the
// output folder and prints; snapshots, checkpoints, restarts, multi-field contact and FE regions
// are refused (errors before the run). abort_processes ends every rank with `code` (a failure
// on one rank, which the others cannot see).
void start_processes(int* argc, char*** argv);
void stop_processes();
int process_rank();
int process_count();
[[noreturn]] void abort_processes(int code);

// The checkpoint file's name in the output folder, and that of the state of a failed step.
inline const char* checkpoint_file_name() { return "checkpoint.smpm"; }
inline const char* failed_state_file_name() { return "failed.smpm"; }

}  // namespace smpm
