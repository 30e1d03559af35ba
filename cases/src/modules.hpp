#pragma once
// Internal: the two modules a process loads only when a case needs them, so that an MPM case
// on boxes (and --help, --version, a check of such a case) starts without gmsh or deal.II:
//
//   libsilentmpm_gmsh.so  gmsh/      the gmsh session and the reading of gmsh geometries
//   libsilentmpm_fe.so    fem/, coupling/, cases/fe/
//                                    the deal.II far field, the coupling and their cases and
//                                    run-loop regions (it needs the gmsh module)
//   libsilentmpm_mpi.so   parallel/  MPI and PETSc: the MPM step over ranks (only under an MPI
//                                    launcher; built when PETSc is found)
//
// Each module gives the core one table of functions through an extern "C" entry point. Its own
// references to the core (materials, the case parsers, the output writers) are resolved against
// the program that loads it, which exports its symbols (CMakeLists.txt: smpm_program).
//
// A module is looked for, in order: already in the process (a test or a study linked it), in
// the folder of $SILENTMPM_MODULE_DIR, then in the folder of the running program. A module that
// cannot be loaded is a std::runtime_error naming the file and the loader's reason.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "case_keys.hpp"
#include "run_loop.hpp"
#include "silentmpm/case.hpp"
#include "silentmpm/decomposition.hpp"
#include "silentmpm/geometry.hpp"
#include "silentmpm/gmsh_module.hpp"

namespace smpm::detail {

// Bumped whenever the table or a signature in it changes (as kGmshModuleApi).
inline constexpr int kFarFieldModuleApi = 4;

struct FarFieldModule {
  int api;
  // scatter, skeleton: as load_case_on_ranks passes them (several ranks; a rank other than 0).
  Case (*build_fem_case)(const Ctx& ctx, const ojson& doc, bool scatter, bool skeleton);  // case_fem.cpp
  Case (*build_hybrid_case)(const Ctx& ctx, const ojson& doc);  // cases/fe/case_hybrid.cpp
  std::unique_ptr<Region> (*fem_region)(Case& c);               // cases/fe/region_fem.cpp
  std::unique_ptr<Region> (*hybrid_region)(Case& c, int across, bool resuming);  // region_hybrid.cpp
  // The FE region's line of `silentmpm check`.
  std::string (*fem_check_line)(const Case& c);
};

// Bumped whenever the table or a signature in it changes.
inline constexpr int kMpiModuleApi = 5;

// The MPI module (parallel/: MPI and PETSc), loaded only when an MPI launcher started the
// program (processes.cpp).
struct MpiModule {
  int api;
  void (*start)(int* argc, char*** argv);  // MPI (threads funnelled) and PETSc
  void (*stop)();
  int (*rank)();
  int (*size)();
  // Cuts a finalized solver, built whole on every rank, to this rank's block (`across` ranks
  // across x; 0: the layout with the fewest shared nodes); the decomposition is attached to the
  // solver and must outlive its steps. `scatter`: only rank 0 holds the particles (the others
  // are skeletons, Solver::seed_nothing), and it sends each rank its block's.
  std::unique_ptr<Decomposition> (*distribute)(Solver& s, int across, bool scatter);
  bool (*any)(bool b);                 // over every rank
  void (*abort)(int code);             // MPI_Abort: every rank stops
  void (*broadcast)(std::string& bytes);  // rank 0's bytes to every rank (collective)
  // The ranks' communicator and MPI_INFO_NULL, as pointers to an MPI_Comm and an MPI_Info (for
  // writers that open one file from every rank, SnapshotWriter::set_ranks).
  const void* (*world)();
  const void* (*no_info)();
  // One checkpoint file written by every rank at once (collective; parallel/state_write.hpp):
  // whole or not at all, an error on every rank when any rank's write fails.
  void (*write_state)(const StateWriter& w, const std::string& path);
};

const GmshModule& gmsh_module();  // loads libsilentmpm_gmsh.so on first use
const MpiModule& mpi_module();    // loads libsilentmpm_mpi.so on first use
// The MPI module when the program runs under an MPI launcher (start_processes), else null.
const MpiModule* mpi();
const FarFieldModule& far_field_module();  // loads libsilentmpm_fe.so on first use

}  // namespace smpm::detail

// The MPI module's entry point (parallel/src/module.cpp).
extern "C" const smpm::detail::MpiModule* silentmpm_mpi_module();
// The far-field module's entry point (cases/fe/module.cpp).
extern "C" const smpm::detail::FarFieldModule* silentmpm_fe_module();
