#pragma once
// The tungsten-film material (Model::J2Film): one particle's stress update through the state
// machine  elastic -> plastic -> decohesion -> separated  (REFERENCE.md §5).
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

inline double film_update(const Material& m, Particles& p, std::size_t k, double dexx,
                          double deyy, double dgxy, double& sxx, double& syy, double& szz,
                          double& sxy) {
  elastic_increment(m, dexx, deyy, dgxy, sxx, syy, szz, sxy);
  uint8_t& st = p.state[k];
  if (st >= kDecohesion) {
    Discontinuity d;
    d.nx = p.dnx[k]; d.ny = p.dny[k]; d.L = p.dL[k];
    d.tnf = p.dtnf[k]; d.ttf = p.dttf[k];
    d.un = p.jump_n[k]; d.ut = p.jump_t[k]; d.ubar = p.ubar[k];
    const double w = decohesion_update(m.coh, m.lambda, m.mu, d, st, sxx, syy, szz, sxy);
    p.jump_n[k] = d.un; p.jump_t[k] = d.ut; p.ubar[k] = d.ubar;
    return w;
  }
  const J2Return r = j2soft_return(m.j2, m.mu, sxx, syy, szz, sxy, p.eps_p[k]);
  if (!r.plastic) return 0.0;
  st = kPlastic;
  const double w = r.q * r.dgamma;  // sigma : d eps_p = q dgamma for J2
  if (!m.bif.enabled || (!m.coh.enabled && (p.dnx[k] != 0 || p.dny[k] != 0))) return w;
  // Exact J2 pre-check: det Q(n) = G M (H - H_cr(n)) / (3G + H), so no normal bifurcates while
  // H exceeds max H_cr (closed form, bifurcation.hpp); the margin 1e-8 G keeps det Q far above
  // round-off, so the verdict is that of the check below and of the sweep.
  if (j2_cannot_bifurcate(sxx, syy, szz, sxy, m.mu, m.M, r.H)) return w;
  double C[16];
  j2_tangent(m.lambda, m.mu, sxx, syy, szz, sxy, j2_beta(m.mu, r.H), C);
  const BifurcationResult b = bifurcation_check(C, m.bif, m.mu * m.M);
  if (!b.bifurcated) return w;
  const double th = b.theta * 3.14159265358979323846 / 180.0;
  Discontinuity d;
  d.nx = std::cos(th);
  d.ny = std::sin(th);
  p.dnx[k] = d.nx;
  p.dny[k] = d.ny;
  if (!m.coh.enabled) return w;
  decohesion_start(m.coh, m.M, m.mu, sxx, syy, sxy, std::sqrt(p.vol[k]), d);
  p.dL[k] = d.L; p.dtnf[k] = d.tnf; p.dttf[k] = d.ttf;
  p.jump_n[k] = 0; p.jump_t[k] = 0; p.ubar[k] = 0;
  st = kDecohesion;
  return w;
}

}  // namespace smpm
