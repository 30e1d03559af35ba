#pragma once
// The semi-implicit (trapezoidal) update of a node that carries a 2x2 dashpot block C:
//   (m + dt/2 C) v+ = (m - dt/2 C) v + dt f,
// solved for the free components only (mask bit 0: x held, bit 1: y held; a held component is
// zero). Unconditionally stable for the dashpot. Used by the MPM grid update (silent layers in
// the nodal form) and by the hybrid step (FE dashpots, at shared and FE-only nodes alike).
#include <cstdint>

namespace smpm {

// The Lysmer-Kuhlemeyer dashpot block per unit boundary length, B = zn n n^T + zt (I - n n^T)
// (zn = a rho c_d, zt = b rho c_s; docs/physics.md section 1), for the unit normal (nx, ny). The
// MPM silent layer and the FE dashpot boundary both assemble it.
inline void lk_block(double zn, double zt, double nx, double ny, double& bxx, double& bxy,
                     double& byy) {
  bxx = zn * nx * nx + zt * (1 - nx * nx);
  bxy = (zn - zt) * nx * ny;
  byy = zn * ny * ny + zt * (1 - ny * ny);
}

inline void dashpot_velocity(double m, double cxx, double cxy, double cyy, double vx, double vy,
                             double fx, double fy, double dt, std::uint8_t mask, double& ax,
                             double& ay) {
  const double h = 0.5 * dt;
  const double rx = m * vx - h * (cxx * vx + cxy * vy) + dt * fx;
  const double ry = m * vy - h * (cxy * vx + cyy * vy) + dt * fy;
  const double A = m + h * cxx, B = h * cxy, D = m + h * cyy;
  ax = 0;
  ay = 0;
  switch (mask & 3) {
    case 0: {
      const double det = A * D - B * B;
      ax = (D * rx - B * ry) / det;
      ay = (A * ry - B * rx) / det;
      break;
    }
    case 1: ay = ry / D; break;  // x held: solve for y alone
    case 2: ax = rx / A; break;  // y held
    default: break;
  }
}

}  // namespace smpm
