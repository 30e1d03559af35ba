#pragma once
// The MPM solver over MPI ranks: horizontal slabs of cell rows, one per rank (docs/parallel.md).
// The grid is a PETSc DMDA of the nodes, one process column and one process row per rank, whose
// rows are cut where the particles' cost splits evenly; each rank's solver holds the DMDA's
// ghosted window of the grid and the particles of its cell rows. The halo sums run over PETSc's
// star forest (PetscSF) on the rows the ranks share only; particles move to a neighbour with MPI
// neighbourhood collectives. PETSc's headers stay in parallel/src.
#include <mpi.h>

#include <memory>
#include <vector>

#include "silentmpm/decomposition.hpp"

namespace smpm {

class Solver;

// Starts MPI (threads funnelled to the main one) and PETSc, once per process; stops them.
void parallel_init(int* argc, char*** argv);
void parallel_finalize();

class Distributed final : public Decomposition {
 public:
  // Cuts a finalized solver, on which every rank of comm built the whole case, to this rank's
  // slab and attaches itself to it (it must outlive the solver's steps). Throws
  // std::runtime_error, on every rank, when the grid has fewer cell rows than the ranks need
  // (the halo's width each) or the case uses what the ranks cannot share yet (multi-field
  // contact, step hooks).
  Distributed(Solver& s, MPI_Comm comm);
  ~Distributed() override;
  Distributed(const Distributed&) = delete;
  Distributed& operator=(const Distributed&) = delete;

  int rank() const override;
  int size() const override;
  void sum_halo(double* const* fields, int n) override;
  bool migrate(Solver& s) override;
  void sum(double* v, int n) override;
  void max(double* v, int n) override;
  bool any(bool b) override;
  Traffic traffic() const override;

  // Cell rows of every rank's slab: rank r owns [rows()[r], rows()[r + 1]) of the whole grid.
  const std::vector<int>& rows() const;
  int halo_width() const;    // node rows of the neighbours a window holds on each side
  int window_row0() const;   // the whole grid's node row of this rank's grid row 0
  // Particles sent to and received from the neighbours, over the run.
  long sent() const;
  long received() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> d_;
};

}  // namespace smpm
