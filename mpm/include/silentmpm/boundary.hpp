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
#include <cmath>
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
  // This step's load weights, K nodes and shape values per entry (K: the shape's nodes), set
  // where the forces are assembled and used again for their work.
  std::vector<long> nodes;
  std::vector<double> N;
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
  std::vector<long> nodes;           // this step's load weights, as TractionLoad's
  std::vector<double> N;
  // MUSL, nodal form, one velocity field: strain the particles with the updated grid velocity
  // v+ (the one the dashpots acted on) at this layer's dashpot nodes, where they are heavy
  // enough, instead of the re-mapped one (docs/physics.md section 4; the case key
  // "edge_velocity": "updated").
  bool updated_velocity = false;
  // MUSL and USF, nodal form, one velocity field, 1 particle per cell and the edge on a grid
  // line: the closure of the scheme's two particle sublattices (docs/physics.md section 4; the
  // case key "edge_velocity": "delayed"). At this layer's dashpot nodes the dashpot acts with the
  // node's start velocity of h/c - dt/2 earlier on the node weighed as a whole one, and the
  // particles are strained with the mean of the re-mapped velocity and the force of as long ago
  // over the dashpot's coefficient.
  bool delayed = false;
  bool springs() const { return delta > 0; }
};

// A graded (Rayleigh, mass-proportional) damping layer: the particles within `width` of an edge
// carry a damping alpha(s) = alpha0 s^power per unit mass, s = 1 - d / width the normalised depth
// (0 at the layer's inner edge, 1 on the boundary), assembled each step into the nodal dashpot
// blocks, C_i += alpha_q m_q N_i(x_q) I, and integrated with them (docs/physics.md section 9.2).
// alpha0 = -(power + 1) c_d ln(R0) / width makes the normal-incidence round trip return R0.
// With beta0 > 0 also a stiffness-proportional part graded alike, beta = beta0 s^power (s): a
// viscous stress beta C : D at each layer particle, D the strain rate of the velocity that
// strains the particles in one step, whose force acts in the next (explicit; the critical time
// step shrinks, Solver::critical_dt).
struct DampingLayer {
  BoundaryLayer layer;
  double r0 = 1e-3, power = 2, beta0 = 0;
  std::vector<double> alpha;         // alpha per layer particle (1/s), set by Solver::finalize
  std::vector<double> beta;          // beta per layer particle (s), set by Solver::finalize
  std::vector<double> sv;            // 3 per layer particle: the viscous stress xx, yy, xy (Pa)
  // This step's weights of each particle (kNodes per particle: node, N), from the assembly of
  // the blocks; the power of the damping force is booked with the same ones.
  std::vector<long> nodes;
  std::vector<double> N;
  // The stiffness part's shape gradients of each particle at its position when the step began
  // (kNodes per particle: node, dN/dx, dN/dy): the viscous force, its power and the next viscous
  // stress all take them, wherever the scheme has moved the particle by then.
  std::vector<long> gnodes;
  std::vector<double> dNx, dNy;
};

// A perfectly matched layer inside a straight side of a body (docs/physics.md section 9.3): the
// body's particles within `width` of the line x = c (axis 0) or y = c (axis 1), the body lying on
// the side `side` (+1: at coordinates below c). d = d0 s^power with s the depth into the band over
// width and d0 = -(power + 1) c_d ln(r0) / (2 width); alpha the frequency shift (1/s).
struct PmlBand {
  std::string name;
  int body = -1, axis = 0, side = 1;
  double c = 0, width = 0, r0 = 1e-3, power = 2, alpha = 0;
  double parallel = 0;  // the multi-axial layer's share of d along the side (docs/physics.md 9.3)
};

// A case file's `r0` of a `pml` when it gives none (both methods). At 10 cells, power 2, it keeps
// every plane wave at 0-80 degrees within both layers' goals: 0.46 % in the FE far field, 0.85 %
// on particles at 1 ppc under USL (studies/absorbing; 1e-2 returns 1.00 % there, 1e-3 0.55 % in
// FE at normal incidence). The C++ structs keep r0 = 1e-3, which the column's shorter pulses
// favour.
inline constexpr double kPmlDefaultR0 = 5e-3;

// What the energy checks of both methods add when a run with a PML blows up.
// What an unstable USL run adds to its error: the step limit of a node holding a sliver of mass.
inline constexpr const char* kUslSliverHint =
    "under USL a node that holds a sliver of a particle's mass (a free surface just past a grid "
    "line) strains the particles with its own updated velocity and needs a far smaller step; "
    "\"MUSL\" strains with the particles' re-mapped velocity and does not, docs/physics.md "
    "section 9.3";
inline constexpr const char* kPmlGrowthHint =
    "a pml between two free surfaces needs \"alpha\" >= 0.04 sqrt(d0 c_d / h) or \"parallel\", "
    "docs/physics.md section 9.3";

// The power of the layer particles' PIC share in their depth (Solver::pml_pic).
inline constexpr double kPmlPicPower = 5;

// Under MUSL and USF at 1 particle per cell the scheme carries slow backward waves (its odd-even
// branch), which a stretching amplifies; a layer there needs at least kPmlOnePpcCells cells and a
// frequency shift alpha of at least pml_one_ppc_alpha (docs/physics.md section 9.3).
inline constexpr int kPmlOnePpcCells = 10;
inline constexpr double kPmlOnePpcShift = 0.04;
// The layer's largest d, (power + 1) c_d ln(1/r0) / (2 width), as Solver::finalize sets it.
inline double pml_d0(double cd, double r0, double power, double width) {
  return -(power + 1) * cd * std::log(r0) / (2 * width);
}
// The least alpha under MUSL and USF at 1 particle per cell: kPmlOnePpcShift sqrt(d0 c_d / h).
inline double pml_one_ppc_alpha(double cd, double r0, double power, double width, double h) {
  return kPmlOnePpcShift * std::sqrt(pml_d0(cd, r0, power, width) * cd / h);
}

// The particles of every band of a solver, with their stretchings and memories (built by
// Solver::finalize; a particle in two bands, at a corner, has both d_x and d_y).
struct PmlLayer {
  BoundaryLayer layer;            // ids and idx of the particles
  double alpha = 0;
  std::vector<double> dx, dy;     // per particle (1/s)
  std::vector<double> pic;        // per particle: the share of the grid's velocity it takes
  std::vector<double> H;          // 4 per particle: du_x/dx, du_y/dx, du_x/dy, du_y/dy
  std::vector<double> u;          // 2 per particle: displacement
  std::vector<double> xi, zeta;   // 4 per particle each: the memories (see solver.cpp)
  std::vector<double> f;          // 6 per particle: this step's explicit loads (4 stresses, 2 per mass)
  double dt_coef = 0;             // dt of the recursion coefficients below
  std::vector<double> cx, cy;     // 3 per particle: e, ca, cb for alpha + d_x, alpha + d_y
  double e_a = 1, ca_a = 0, cb_a = 0;
  // This step's shape functions of each particle (kNodes per particle: node, N, dN/dx, dN/dy),
  // evaluated once when the loads are assembled; the positions do not change before g2p.
  std::vector<long> nodes;
  std::vector<double> N, dNx, dNy;
  // Under MUSL and USF, within a step (pml_pic to pml_damping): 4 per particle, the velocity
  // before its damping and after the damping of that velocity.
  std::vector<double> vd;
  bool active() const { return !layer.ids.empty(); }
};

struct NodalConstraint {
  std::string name;
  std::vector<uint32_t> nodes;
  uint8_t mask = 0;  // bit 0: x, bit 1: y
};

}  // namespace smpm
