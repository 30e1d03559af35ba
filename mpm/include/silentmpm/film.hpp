#pragma once
// The tungsten-film material (Model::J2Film): one particle's stress update through the state
// machine  elastic -> plastic -> decohesion -> separated  (docs/physics.md §5).
//
//   elastic / plastic  J2 with hardening then softening (j2soft.hpp). After every plastic
//                      loading step the acoustic tensor of the continuum tangent is checked
//                      (bifurcation_check: exact bounds of the Fourier form of det Q first,
//                      the reference sweep only at bifurcation; bifurcation.hpp); at
//                      min det Q <= 0 the particle stores the critical normal, the tractions
//                      on that plane (the strengths) and its smear length, and turns to
//                      decohesion (if decohesion is enabled; otherwise it stays
//                      plastic and keeps the first critical normal).
//   decohesion         elastic continuum with frozen plastic strain plus the smeared jump
//                      (decohesion.hpp); separated once ubar reaches 1.
// Returns the dissipated energy per unit volume of the step (plastic work + decohesion work).
#include <cmath>
#include <cstddef>

#include "silentmpm/bifurcation.hpp"
#include "silentmpm/decohesion.hpp"
#include "silentmpm/j2soft.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/particles.hpp"

namespace smpm {

// The parts of film_update off its hot path (film.cpp): a particle in decohesion or separated
// (decohesion_update on its stored discontinuity), and a plastic step the J2 pre-check could not
// clear (tangent, bifurcation_check, and on bifurcation the start of decohesion).
double film_decohesion(const Material& m, Particles& p, std::size_t k, double& sxx, double& syy,
                       double& szz, double& sxy);
void film_bifurcation(const Material& m, Particles& p, std::size_t k, double H, double sxx,
                      double syy, double szz, double sxy);

inline double film_update(const Material& m, Particles& p, std::size_t k, double dexx,
                          double deyy, double dgxy, double& sxx, double& syy, double& szz,
                          double& sxy) {
  elastic_increment(m, dexx, deyy, dgxy, sxx, syy, szz, sxy);
  uint8_t& st = p.state[k];
  if (st >= kDecohesion) return film_decohesion(m, p, k, sxx, syy, szz, sxy);
  const J2Return r = j2soft_return(m.j2, m.mu, sxx, syy, szz, sxy, p.eps_p[k]);
  if (!r.plastic) return 0.0;
  st = kPlastic;
  const double w = r.q * r.dgamma;  // sigma : d eps_p = q dgamma for J2
  if (!m.bif.enabled || (!m.coh.enabled && (p.dnx[k] != 0 || p.dny[k] != 0))) return w;
  // Exact J2 pre-check: det Q(n) = G M (H - H_cr(n)) / (3G + H), so no normal bifurcates while
  // H exceeds max H_cr (closed form, bifurcation.hpp); the margin 1e-8 G keeps det Q far above
  // round-off, so the verdict is that of bifurcation_check and of the sweep.
  if (j2_cannot_bifurcate(sxx, syy, szz, sxy, m.mu, m.M, r.H)) return w;
  film_bifurcation(m, p, k, r.H, sxx, syy, szz, sxy);
  return w;
}

}  // namespace smpm
