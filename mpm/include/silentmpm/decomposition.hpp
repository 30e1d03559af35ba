#pragma once
// A solver split over processes: each rank holds the particles of a block of cells and a window
// of the grid, its own nodes and copies of its neighbours' nearest nodes (the halo).
// The step asks its decomposition (set by Solver::set_decomposition; implemented over MPI in
// parallel/) to
//   * sum the nodal values every rank scattered into the nodes it shares with others, once all
//     particles have been mapped and before any node is updated (every copy then holds the sum,
//     and the grid update runs on all the window's nodes, the copies giving the same values);
//   * move the particles that left the block to the rank that owns them, at the end of the step;
//   * sum and take maxima of the health checks' reductions over the ranks.
// The serial solver has none and makes none of these calls.
#include <array>
#include <vector>

namespace smpm {

class Solver;

class Decomposition {
 public:
  virtual ~Decomposition() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual int across() const = 0;  // ranks across x (the blocks' layout)
  // Sums the halo of the n grid arrays over the ranks sharing nodes: node i's value of field f
  // at fields[f][i * strides[f]] (strides null: every stride 1).
  virtual void sum_halo(double* const* fields, int n, const int* strides) = 0;
  // Moves the particles outside this rank's cells (with their boundary-layer entries) to
  // their owners; returns whether any particle left or arrived here.
  virtual bool migrate(Solver& s) = 0;
  // In place over the ranks.
  virtual void sum(double* v, int n) = 0;
  virtual void max(double* v, int n) = 0;
  // This rank's own nodes in the whole grid's numbering {i0, i1, j0, j1} (inclusive), and the
  // whole grid's node of its window's node (0, 0).
  virtual std::array<int, 4> own_nodes() const = 0;
  virtual std::array<int, 2> window_origin() const = 0;
  // This rank's communication so far: seconds in halo sums and in migrations, bytes it sent in
  // halo sums and in migrations, particles it sent.
  struct Traffic {
    double halo_seconds = 0, migration_seconds = 0, halo_bytes = 0, migration_bytes = 0;
    long particles_sent = 0;
  };
  virtual Traffic traffic() const = 0;
};

}  // namespace smpm
