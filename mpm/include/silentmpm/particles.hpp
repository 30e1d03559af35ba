#pragma once
// Particle data as structure of arrays: one contiguous array per field, no per-particle objects.
// The history of a material model lives in its own block of arrays, sized only when a material
// of the run uses that model: an elastic or von Mises run carries no film arrays.
#include <cstdint>
#include <vector>

namespace smpm {

// Where a body's particles sit in each cell: the centres of its n x n sub-cells, or its n x n
// Gauss-Legendre points (Solver::seed_rectangle, docs/physics.md section 1.1).
enum class Seeding { Uniform, Gauss };

struct Particles {
  std::vector<double> x, y;          // position
  std::vector<double> x0, y0;        // position where it was seeded (displacement = x - x0)
  std::vector<double> vx, vy;        // velocity
  std::vector<double> mass;          // M_p (constant)
  std::vector<double> vol;           // current volume V_p (unit thickness)
  std::vector<double> sxx, syy, szz, sxy;  // Cauchy stress
  std::vector<double> eps_p;         // accumulated equivalent plastic strain
  // Film model history (decohesion.hpp): state, plane normal, smear length, strengths, jump.
  // Empty unless enable_film() was called (Solver::finalize does, for a j2_softening material).
  std::vector<uint8_t> state;        // ParticleState: elastic, plastic, decohesion, separated
  std::vector<double> dnx, dny;      // normal of the critical plane (0, 0 before bifurcation)
  std::vector<double> dL, dtnf, dttf;  // smear length, normal and tangential strengths
  std::vector<double> jump_n, jump_t, ubar;  // jump components, accumulated normalised jump
  std::vector<uint32_t> id;          // permanent id (seeding order); survives re-sorting
  std::vector<uint16_t> body;        // body index
  std::vector<uint16_t> group;       // material group index

  std::size_t size() const { return x.size(); }
  // Resizes every array (the film block too when it is on); new entries are zero.
  void resize(std::size_t n);
  // Turns the film block on (sized to the particles, zero: elastic, no plane, no jump).
  void enable_film();
  bool has_film() const { return film_; }
  // Set the seeding fields of particle k (its id is k; stresses and history stay as resize left
  // them, at zero).
  void place(std::size_t k, double px, double py, double volume, double density, double v_x,
             double v_y, int body_id, int group_id) {
    x[k] = px;
    y[k] = py;
    x0[k] = px;
    y0[k] = py;
    vx[k] = v_x;
    vy[k] = v_y;
    vol[k] = volume;
    mass[k] = density * volume;
    id[k] = static_cast<uint32_t>(k);
    body[k] = static_cast<uint16_t>(body_id);
    group[k] = static_cast<uint16_t>(group_id);
  }
  // Apply a permutation: new[k] = old[perm[k]]. A shorter perm keeps only the particles it lists.
  void permute(const std::vector<uint32_t>& perm);
  // Every field of particle k appended to out as doubles (ids and indices are exact in a
  // double); unpack appends such a record as a new particle and returns the doubles it read.
  void pack(std::size_t k, std::vector<double>& out) const;
  std::size_t unpack(const double* in);
  // Puts the particles in the order of their ids, which must be 0 .. size() - 1; returns the
  // permutation applied (new k was old perm[k]).
  std::vector<uint32_t> sort_by_id();
  // Bytes per particle of the arrays every run carries, and of the film block.
  static constexpr std::size_t bytes_per_particle() {
    return 13 * sizeof(double) + sizeof(uint32_t) + 2 * sizeof(uint16_t);
  }
  static constexpr std::size_t film_bytes_per_particle() { return 8 * sizeof(double) + sizeof(uint8_t); }

 private:
  bool film_ = false;
};

}  // namespace smpm
