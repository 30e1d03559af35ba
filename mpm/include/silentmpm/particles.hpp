#pragma once
// Particle data as structure of arrays: one contiguous array per field, no per-particle objects.
#include <cstdint>
#include <vector>

namespace smpm {

struct Particles {
  std::vector<double> x, y;          // position
  std::vector<double> vx, vy;        // velocity
  std::vector<double> mass;          // M_p (constant)
  std::vector<double> vol;           // current volume V_p (unit thickness)
  std::vector<double> sxx, syy, szz, sxy;  // Cauchy stress
  std::vector<double> eps_p;         // accumulated equivalent plastic strain
  // Film model history (decohesion.hpp): state, plane normal, smear length, strengths, jump.
  std::vector<uint8_t> state;        // ParticleState: elastic, plastic, decohesion, separated
  std::vector<double> dnx, dny;      // normal of the critical plane (0, 0 before bifurcation)
  std::vector<double> dL, dtnf, dttf;  // smear length, normal and tangential strengths
  std::vector<double> jump_n, jump_t, ubar;  // jump components, accumulated normalised jump
  std::vector<uint32_t> id;          // permanent id (seeding order); survives re-sorting
  std::vector<uint16_t> body;        // body index
  std::vector<uint16_t> group;       // material group index

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n);
  // Apply a permutation: new[k] = old[perm[k]].
  void permute(const std::vector<uint32_t>& perm);
  static constexpr std::size_t bytes_per_particle() {
    return 20 * sizeof(double) + sizeof(uint32_t) + 2 * sizeof(uint16_t) + sizeof(uint8_t);
  }
};

}  // namespace smpm
