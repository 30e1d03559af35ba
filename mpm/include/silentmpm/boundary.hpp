#pragma once
// Boundary conditions of the MPM region.
//
//  * NodalConstraint: fixed / roller components on a set of grid nodes (essential conditions).
//  * TractionLoad: a traction carried by boundary-layer particles and mapped to the nodes of
//    their cells with the boundary-layer width h (paper Eq. 16, 20):
//        f_i = t * (V_p / h) * N_i(x_p)
//  * SilentBoundary: the Lysmer-Kuhlemeyer dashpot traction carried by the boundary-layer
//    particles (paper Eq. 21), for any outward normal n:
//        t = -[ a rho c_d (v.n) n + b rho c_s (v - (v.n) n) ]
//    With springs (the Kelvin-Voigt or viscous-spring boundary, docs/physics.md section 9.1) the
//    layer also carries t_s = -[ k_n (u.n) n + k_t (u - (u.n) n) ], u the displacement of the
//    layer particle's anchor since the start, k_n = alpha_n rho c_d^2 / delta, k_t = alpha_t rho c_s^2 / delta.
#include <cstdint>
#include <string>
#include <vector>

#include "silentmpm/time_function.hpp"

namespace smpm {

// Particles that form a boundary layer, each with its outward normal.
struct BoundaryLayer {
  std::string name;                 // for messages
  std::vector<uint32_t> ids;        // permanent particle ids
  std::vector<uint32_t> idx;        // current particle indices (refreshed after a re-sort)
  std::vector<double> nx, ny;       // outward unit normal per particle
  // Distance from the particle to the boundary along n (at selection). With Anchor::Boundary the
  // traction acts at the boundary point x_p + d n, which moves with the particle.
  std::vector<double> d;
  // Boundary length carried by each particle, V_p / h of Eq. 16 with the reference volume V_p.
  // h is the effective layer width sum(V_p) / L, so that sum(w) = L exactly: a uniform traction
  // t then gives nodal forces summing to t L whatever the particles per cell.
  std::vector<double> w;
  double depth = 0;                 // selection depth requested (m)
  double width = 0;                 // effective layer width h = sum(V_p) / L (m)
  double length = 0;                // boundary length L (m)
};

// Where a particle-carried traction is mapped to the grid.
enum class Anchor {
  Particle,  // paper Eq. 20: f_i = t (V_p / h) N_i(x_p), at the particle
  Boundary   // f_i = t (V_p / h) N_i(x_p + d_p n): at the particle's point of the boundary
};

struct TractionLoad {
  BoundaryLayer layer;
  Anchor anchor = Anchor::Boundary;
  // Traction = f(t) * (normal * n + tangential * s + (vx, vy)); s = (-n_y, n_x).
  double normal = 0, tangential = 0, vx = 0, vy = 0;
  TimeFunction fn;
};

enum class SilentForm {
  Particle,  // paper Eq. 20-21: dashpot traction from the particle velocity of the last step
  Nodal      // same dashpot assembled into a nodal 2x2 block, integrated semi-implicitly
};

struct SilentBoundary {
  BoundaryLayer layer;
  Anchor anchor = Anchor::Boundary;
  double a = 1, b = 1;               // LK coefficients
  std::vector<double> zn, zt;        // a rho c_d and b rho c_s per particle (its material)
  SilentForm form = SilentForm::Nodal;
  // Kelvin-Voigt springs: delta > 0 turns them on. The spring force is explicit (from the
  // displacement at the start of the step); its energy 1/2 u.K u is booked as elastic energy.
  // u is the displacement of the point where the layer particle's load is mapped (its anchor),
  // integrated with the grid velocity there: the same weights as the force, so the spring's
  // work and its energy agree.
  double delta = 0, alpha_n = 1, alpha_t = 1;
  std::vector<double> kn, kt;        // alpha_n rho c_d^2 / delta and alpha_t rho c_s^2 / delta
  std::vector<double> ux, uy;        // displacement of each particle's anchor since the start
  bool springs() const { return delta > 0; }
};

// A graded (Rayleigh, mass-proportional) damping layer: the particles within `width` of an edge
// carry a damping alpha(s) = alpha0 s^power per unit mass, s = 1 - d / width the normalised depth
// (0 at the layer's inner edge, 1 on the boundary), assembled each step into the nodal dashpot
// blocks, C_i += alpha_q m_q N_i(x_q) I, and integrated with them (docs/physics.md section 9.2).
// alpha0 = -(power + 1) c_d ln(R0) / width makes the normal-incidence round trip return R0.
struct DampingLayer {
  BoundaryLayer layer;
  double r0 = 1e-3, power = 2;
  std::vector<double> alpha;         // alpha per layer particle (1/s), set by Solver::finalize
};

struct NodalConstraint {
  std::string name;
  std::vector<uint32_t> nodes;
  uint8_t mask = 0;  // bit 0: x, bit 1: y
};

}  // namespace smpm
