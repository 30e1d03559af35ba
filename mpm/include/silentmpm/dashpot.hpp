#pragma once
// The semi-implicit (trapezoidal) update of a node that carries a 2x2 dashpot block C:
//   (m + dt/2 C) v+ = (m - dt/2 C) v + dt f,
// solved for the free components only (mask bit 0: x held, bit 1: y held; a held component is
// zero). Unconditionally stable for the dashpot. Used by the MPM grid update (silent layers in
// the nodal form) and by the hybrid step (FE dashpots, at shared and FE-only nodes alike).
#include <cmath>
#include <cstdint>
#include <vector>

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

// The free case (mask 0) for any arithmetic type T: a double (dashpot_velocity's), or a vector
// of doubles whose lanes are several nodes (each lane then the scalar arithmetic, the same bits).
template <class T>
inline void dashpot_velocity_free(T m, T cxx, T cxy, T cyy, T vx, T vy, T fx, T fy, double dt,
                                  T& ax, T& ay) {
  const double h = 0.5 * dt;
  const T rx = m * vx - h * (cxx * vx + cxy * vy) + dt * fx;
  const T ry = m * vy - h * (cxy * vx + cyy * vy) + dt * fy;
  const T A = m + h * cxx, B = h * cxy, D = m + h * cyy;
  const T det = A * D - B * B;
  ax = (D * rx - B * ry) / det;
  ay = (A * ry - B * rx) / det;
}

// The update of one node (the free components of `mask`; a held one is zero).
inline void dashpot_velocity(double m, double cxx, double cxy, double cyy, double vx, double vy,
                             double fx, double fy, double dt, std::uint8_t mask, double& ax,
                             double& ay) {
  if ((mask & 3) == 0) {
    dashpot_velocity_free(m, cxx, cxy, cyy, vx, vy, fx, fy, dt, ax, ay);
    return;
  }
  const double h = 0.5 * dt;
  const double rx = m * vx - h * (cxx * vx + cxy * vy) + dt * fx;
  const double ry = m * vy - h * (cxy * vx + cyy * vy) + dt * fy;
  const double A = m + h * cxx, D = m + h * cyy;
  ax = 0;
  ay = 0;
  switch (mask & 3) {
    case 1: ay = ry / D; break;  // x held: solve for y alone
    case 2: ax = rx / A; break;  // y held
    default: break;
  }
}

// Perfectly matched layers (docs/physics.md section 9.3), shared by the FE far field and the
// particles. psi(t + dt) = e psi(t) + ca g(t) + cb g(t + dt) is the exact solution of
// psi' = -beta psi + g over one step with g linear in between (recursive convolution with
// exp(-beta t)).
inline void convolution_coefficients(double beta, double dt, double& e, double& ca, double& cb) {
  const double x = beta * dt;
  e = std::exp(-x);
  if (x < 1e-3) {  // the series, free of cancellation
    ca = dt * (0.5 - x / 3 + x * x / 8 - x * x * x / 30);
    cb = dt * (0.5 - x / 6 + x * x / 24 - x * x * x / 120);
  } else {
    ca = dt * (1 - e * (1 + x)) / (x * x);
    cb = dt * (1 - e) / x - ca;
  }
}

// The coefficients for one time step dt of every point of a layer, 3 per point: cx for alpha +
// d_x, cy for alpha + d_y (the memories of the x and y derivatives), and (e, ca, cb) for alpha.
inline void convolution_tables(double alpha, const std::vector<double>& dx,
                               const std::vector<double>& dy, double dt, std::vector<double>& cx,
                               std::vector<double>& cy, double& e, double& ca, double& cb) {
  const std::size_t n = dx.size();
  cx.resize(3 * n);
  cy.resize(3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    convolution_coefficients(alpha + dx[k], dt, cx[3 * k], cx[3 * k + 1], cx[3 * k + 2]);
    convolution_coefficients(alpha + dy[k], dt, cy[3 * k], cy[3 * k + 1], cy[3 * k + 2]);
  }
  convolution_coefficients(alpha, dt, e, ca, cb);
}

// The mass term of a layer point's component u (less its damping part m (d_x + d_y) v, which
// goes through a dashpot block), per unit of its mass: -[(d_x + d_y)(-alpha u + alpha^2 I1) +
// d_x d_y (u - 2 alpha I1 + alpha^2 I2)], I1 the convolution of u and I2 that of I1 with
// exp(-alpha t). z[0], z[1] carry the two memories between steps; (e, ca, cb) are alpha's
// coefficients.
inline double pml_mass_term(double sum, double prod, double alpha, double u, double* z, double e,
                            double ca, double cb) {
  const double i1 = z[0] + cb * u, i2 = z[1] + cb * i1;
  z[0] = e * i1 + ca * u;
  z[1] = e * i2 + ca * i1;
  return -(sum * (alpha * alpha * i1 - alpha * u) + prod * (u - 2 * alpha * i1 + alpha * alpha * i2));
}

}  // namespace smpm
