#pragma once
// Decohesion after discontinuous bifurcation (docs/physics.md §5; Chen, Shen, Mai & Shen 2004,
// Schreyer-Sulsky-Zhou). From the step a particle bifurcates on, its continuum is elastic (the
// plastic strain is frozen) and a displacement jump u = u_n n + u_t t, t = (-n_y, n_x), on the
// critical plane, smeared over the length L, takes the inelastic strain:
//   d eps = d eps_e + (1/L) sym(du (x) n).
// Tractions on the plane: tau_n = n.sigma.n, tau_t = t.sigma.n.
//   failure surface   F = (<tau_n>/tau_nf)^2 + (tau_t/tau_tf)^2 - (1 - ubar)^2 <= 0
//   strengths         tau_nf, tau_tf = tractions on the plane at bifurcation (|tau_t|); when the
//                     plane is in compression at bifurcation, tau_nf = compressed_normal_strength
//                     (default: tau_tf); both floored at min_strength
//   evolution         ubar = accumulated sqrt((du_n/u_nf)^2 + (du_t/u_tf)^2), never decreases;
//                     the strengths decay linearly to zero at ubar = 1 (fracture energy
//                     1/2 tau_f u_f per area in a pure mode)
//   flow              associated, du = dlambda dF/dtau (backward Euler): one scalar equation,
//                     solved by bisection on a bracket (guaranteed)
//   closure           an open plane (u_n > 0) under normal compression closes first, down to
//                     u_n = 0, at zero normal traction; u_n never goes negative
//   separation        ubar >= 1: the plane carries no tension and no shear, only contact
//                     compression
//   snap-back guard   the softening of a particle is stable only for L < M u_nf / tau_nf and
//                     L < mu u_tf / tau_tf. The guard CLAMPS: L is reduced, per particle at
//                     bifurcation, to snap_back_factor (0.5) times the smaller limit. The energy
//                     per crack area stays 1/2 tau_f u_f, so a clamped particle dissipates more
//                     per volume.
#include <cmath>
#include <cstdint>

namespace smpm {

// Per-particle state (Particles::state).
enum ParticleState : uint8_t { kElastic = 0, kPlastic = 1, kDecohesion = 2, kSeparated = 3 };

struct DecohesionParams {
  bool enabled = true;
  double u_nf = 10e-9;                // critical normal jump (m)
  double u_tf = 10e-9;                // critical tangential jump (m)
  double smear_length = 0;            // L (m); 0 = the particle's size sqrt(V_p) at bifurcation
  double compressed_normal_strength = 0;  // tau_nf when tau_n <= 0 at bifurcation; 0 = tau_tf
  double min_strength = 0;            // floor of both strengths (Pa); set from sigma_y if 0
  double snap_back_factor = 0.5;      // L is clamped to this fraction of the snap-back limit
};

// History of one particle's discontinuity.
struct Discontinuity {
  double nx = 1, ny = 0;    // unit normal of the plane
  double L = 0;             // smear length
  double tnf = 0, ttf = 0;  // strengths
  double un = 0, ut = 0;    // jump components
  double ubar = 0;          // accumulated normalised jump
};

// Strengths and smear length at bifurcation, from the stress at that moment and the normal.
// Returns true when the smear length had to be clamped by the snap-back guard.
bool decohesion_start(const DecohesionParams& P, double M, double mu, double sxx, double syy,
                      double sxy, double particle_size, Discontinuity& d);

// Tractions on the plane of normal (nx, ny).
inline void plane_tractions(double nx, double ny, double sxx, double syy, double sxy, double& tn,
                            double& tt) {
  tn = nx * nx * sxx + ny * ny * syy + 2 * nx * ny * sxy;
  tt = nx * ny * (syy - sxx) + (nx * nx - ny * ny) * sxy;
}

// Update of a particle in decohesion or separated state. On entry the stress holds the elastic
// trial (old stress + C : d eps); on exit the stress after the jump increment. Returns the
// dissipated energy per unit volume. state is kDecohesion or kSeparated (may become kSeparated).
double decohesion_update(const DecohesionParams& P, double lambda, double mu,
                         Discontinuity& d, uint8_t& state, double& sxx, double& syy, double& szz,
                         double& sxy);

}  // namespace smpm
