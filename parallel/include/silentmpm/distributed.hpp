#pragma once
// The MPM solver over MPI ranks: blocks of cells, m across and n along y, one per rank
// (docs/parallel.md); m = 1 gives horizontal slabs. The grid is a PETSc DMDA of the nodes whose
// ownership is the blocks' cells, cut where the particles' cost splits evenly; each rank's
// solver holds the DMDA's ghosted window of the grid and the particles of its cells. The halo
// sums run over PETSc's star forest (PetscSF) on the nodes the ranks share only; particles move
// to a neighbour with MPI neighbourhood collectives. PETSc's headers stay in parallel/src.
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
  // block and attaches itself to it (it must outlive the solver's steps). `across`: ranks
  // across x (1: slabs of rows; 0: the layout with the fewest shared nodes). `scatter`: rank 0
  // built the whole case and the others its skeleton (Solver::seed_nothing): rank 0's costs,
  // grid constraints and body scalars go to every rank, and rank 0 sends each rank its block's
  // particles with their layer entries (docs/parallel.md "Set-up"). Throws
  // std::runtime_error, on every rank, when the ranks do not divide by `across` or the grid has
  // fewer cells than the blocks need (the halo's width each way).
  Distributed(Solver& s, MPI_Comm comm, int across = 0, bool scatter = false);
  ~Distributed() override;
  Distributed(const Distributed&) = delete;
  Distributed& operator=(const Distributed&) = delete;

  int rank() const override;
  int size() const override;
  void sum_halo(double* const* fields, int n, const int* strides) override;
  bool migrate(Solver& s) override;
  void sum(double* v, int n) override;
  void max(double* v, int n) override;
  std::array<int, 4> own_nodes() const override;
  std::array<int, 2> window_origin() const override;
  Traffic traffic() const override;

  // The blocks: rank r = b * across() + a owns the whole grid's cells
  // [columns()[a], columns()[a + 1]) x [rows()[b], rows()[b + 1]).
  int across() const override;
  const std::vector<int>& columns() const;
  const std::vector<int>& rows() const;
  int halo_width() const;      // nodes of the neighbours a window holds on each side
  int window_column0() const;  // the whole grid's node of this rank's grid node (0, 0)
  int window_row0() const;
  // Particles sent to and received from the neighbours, over the run.
  long sent() const;
  long received() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> d_;
};

}  // namespace smpm
