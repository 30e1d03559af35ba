#pragma once
// The explicit MPM solver: one region of particles on a background grid.
//
// The time step (MUSL shown; USF and USL differ only in where the stress update sits):
//
//   reset grid
//   p2g          masses, momenta, internal forces  (Eq. 15, 18)
//   loads        tractions and silent-layer dashpots carried by boundary particles (Eq. 16, 20-21)
//   grid update  v+ = v + dt f / m  (semi-implicit where a nodal dashpot block is present)
//   constraints  fixed / roller components
//   g2p          particle velocity (FLIP/PIC blend); MUSL re-maps the momentum
//   stress       velocity gradient -> strain increment -> material update; positions advance
//
// Particle loops run over contiguous ranges of one material group, so the material model is a
// template argument of the inner loop. Scatters to the grid run in parallel over horizontal
// strips of particles: even strips first, then odd strips, so no two threads write one node.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "silentmpm/boundary.hpp"
#include "silentmpm/contact.hpp"
#include "silentmpm/grid.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/particles.hpp"
#include "silentmpm/shape.hpp"

namespace smpm {

enum class Scheme { USF, USL, MUSL };
const char* scheme_name(Scheme s);

struct SolverOptions {
  Scheme scheme = Scheme::MUSL;
  double flip = 1.0;          // 1 = FLIP, 0 = PIC
  double mass_tolerance = 1e-12;  // nodes lighter than this fraction of the smallest particle mass are void
  int threads = 0;            // 0 = OpenMP default
};

struct Energies {
  double kinetic = 0, elastic = 0;
  double dissipated = 0;      // plastic (+ decohesion) dissipation, accumulated
  double absorbed = 0;        // energy taken out by silent-layer dashpots, accumulated
  double external_work = 0;   // work of tractions, accumulated
  double initial = 0;         // kinetic + elastic at t = 0
  // (kinetic + elastic + dissipated + absorbed) - (initial + external_work)
  double imbalance() const { return kinetic + elastic + dissipated + absorbed - initial - external_work; }
};

struct ProbeSample {
  double sxx = 0, syy = 0, szz = 0, sxy = 0, j2 = 0, vx = 0, vy = 0;
  bool valid = false;  // false when no particle is near the point
};

class Solver {
  friend class Contact;  // the multi-field step runs the stages below per body
  friend class Hybrid;   // the MPM-FEM coupled step (coupling/src/hybrid.cpp) runs them too

 public:
  Grid grid;
  Particles p;
  std::vector<Material> materials;  // material of group g is materials[g]
  std::vector<NodalConstraint> constraints;
  std::vector<TractionLoad> tractions;
  std::vector<SilentBoundary> silents;
  SolverOptions opt;
  double dt = 0, t = 0;
  long steps = 0;
  Energies energy;
  Contact contact;  // contact of bodies: single velocity field (default) or one per body

  // --- setup -------------------------------------------------------------------------------
  // Fill the rectangle [x0, x1] x [y0, y1] with particles on a lattice of n x n per cell
  // (n = 1, 2, 3), spacing adjusted so the rectangle is covered exactly. Returns the number added.
  std::size_t seed_rectangle(double x0, double y0, double x1, double y1, int n_per_side,
                             int group, int body, double vx0, double vy0);
  // Particles of `body` within `width` inside the straight edge p0 -> p1 whose outward normal is
  // (nx, ny) (the edge is the segment; particles must project onto it).
  BoundaryLayer select_layer(const std::string& name, int body, double ex0, double ey0,
                             double ex1, double ey1, double nx, double ny, double width) const;
  // Grid nodes whose position lies in [x0, x1] x [y0, y1] (inclusive, with a tolerance of h/1000).
  std::vector<uint32_t> nodes_in_box(double x0, double y0, double x1, double y1) const;
  // Call once after seeding and adding boundary conditions.
  void finalize();
  double critical_dt() const;  // h / max c_d over materials present

  // --- run ---------------------------------------------------------------------------------
  void step();
  // Recompute kinetic and elastic energies (a pass over the particles).
  void update_energies();
  // Mass-weighted projection of particle fields to the nodes of the cell holding (x, y), then
  // bilinear interpolation at the point.
  ProbeSample sample(double x, double y) const;
  // Several points in one pass over the particles.
  std::vector<ProbeSample> sample(const std::vector<std::array<double, 2>>& points) const;
  // Same, each point sampling only the particles of body bodies[q] (-1: every body).
  std::vector<ProbeSample> sample(const std::vector<std::array<double, 2>>& points,
                                  const std::vector<int>& bodies) const;
  int thread_count() const { return nthreads_; }
  // Check every particle is inside the grid; returns the index of the first outside, or -1.
  long first_particle_outside() const;

 private:
  int nthreads_ = 1;
  int nstrips_ = 2;
  bool strips_ok_ = false;
  bool has_nodal_dashpot_ = false;
  std::vector<long> dashpot_nodes_;  // nodes holding a dashpot block this step
  double mass_floor_ = 0;
  // ranges_[s * G + g] = [begin, end) of particles of strip s and group g.
  std::vector<std::array<uint32_t, 2>> ranges_;
  std::vector<int> strip_lo_, strip_hi_;  // cell-row range each strip touches
  std::vector<int> strip_out_;            // particles of each strip outside the grid columns
  std::vector<uint32_t> where_;           // permanent id -> current index

  void sort_particles();
  void refresh_strip_rows();
  bool strips_conflict() const;
  void reset_grid();
  template <class Fn> void scatter_over_groups(Fn&& fn);
  template <class Fn> void parallel_over_groups(Fn&& fn);
  void p2g(bool with_momentum, bool with_force);
  void apply_loads();
  void layer_shape(const BoundaryLayer& L, std::size_t q, Anchor anchor, Bilinear& sf,
                   long nodes[4]) const;
  void grid_update();
  void boundary_work(const std::vector<double>* wx = nullptr, const std::vector<double>* wy = nullptr);
  void g2p_velocity(bool remap, bool move);
  void update_stress_and_position(const std::vector<double>& gx, const std::vector<double>& gy,
                                  bool move);
  void nodal_velocity(std::vector<double>& ax, std::vector<double>& ay,
                      const std::vector<double>& mx, const std::vector<double>& my);
  void check_outside();
  long outside_ = -1;  // index of a particle that left the grid in the last pass
};

}  // namespace smpm
