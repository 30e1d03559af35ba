// MPM-FEM coupled explicit step through shared nodes: see silentmpm/hybrid.hpp.
#include "silentmpm/hybrid.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "silentmpm/dashpot.hpp"
#include "silentmpm/shape.hpp"

namespace smpm {

namespace {
std::string pt(double x, double y) {
  std::ostringstream o;
  o << "(" << x << ", " << y << ")";
  return o.str();
}

// Point (x, y) inside the convex quadrilateral with vertices in deal.II order
// (0,0) (1,0) (0,1) (1,1), i.e. counter-clockwise order 0 1 3 2; strict by `tol`.
bool inside_quad(const double* qx, const double* qy, double x, double y, double tol) {
  const int ord[4] = {0, 1, 3, 2};
  double sgn = 0;
  for (int a = 0; a < 4; ++a) {
    const int i = ord[a], j = ord[(a + 1) % 4];
    const double cr = (qx[j] - qx[i]) * (y - qy[i]) - (qy[j] - qy[i]) * (x - qx[i]);
    const double len = std::hypot(qx[j] - qx[i], qy[j] - qy[i]);
    const double d = cr / len;
    if (std::abs(d) <= tol) return false;  // on an edge: not strictly inside
    if (sgn == 0) sgn = d;
    else if ((d > 0) != (sgn > 0)) return false;
  }
  return true;
}
}  // namespace

Hybrid::Hybrid(Solver& mpm, fem::Solver& fe) : mpm_(mpm), fe_(fe) {
  // Energy enters the MPM region through the interface too: its own account bounds nothing.
  mpm_.opt.energy_bound = 0;
  const Grid& g = mpm_.grid;
  const double h = g.h, tol = 1e-6 * h;
  if (mpm_.opt.shape != ShapeKind::Bilinear)
    throw HybridError(std::string("hybrid: the MPM region must use scheme.shape \"bilinear\" (its "
                                  "grid shares nodes with Q1 elements), got \"") +
                      shape_name(mpm_.opt.shape) + "\"");
  if (fe_.degree() != 1)
    throw HybridError("hybrid: the FEM region must use fem.degree 1 (Q1, like the MPM grid), got " +
                      std::to_string(fe_.degree()));
  const auto& X = fe_.node_x();
  const auto& Y = fe_.node_y();
  const std::size_t nfe = X.size();

  // FE nodes at grid nodes.
  grid_of_fe_.assign(nfe, -1);
  for (std::size_t e = 0; e < nfe; ++e) {
    const double fi = (X[e] - g.x0) / h, fj = (Y[e] - g.y0) / h;
    const long i = std::lround(fi), j = std::lround(fj);
    if (i < 0 || j < 0 || i >= g.nnx || j >= g.nny) continue;
    if (std::abs(X[e] - g.node_x(i)) <= tol && std::abs(Y[e] - g.node_y(j)) <= tol)
      grid_of_fe_[e] = j * g.nnx + i;
  }

  // Grid cells covered by FE cells. An FE cell whose 4 nodes are the corners of one grid cell
  // marks it; any other FE cell marks the grid cells whose centre lies inside it.
  fe_cell_.assign(static_cast<std::size_t>(g.nx) * g.ny, 0);
  const auto& cn = fe_.cell_nodes();
  const std::size_t ncell = cn.size() / 4;
  std::vector<std::uint8_t> unit(ncell, 0);
  for (std::size_t c = 0; c < ncell; ++c) {
    const std::uint32_t* v = &cn[4 * c];
    long gi[4], gj[4];
    bool all = true;
    for (int a = 0; a < 4; ++a) {
      if (grid_of_fe_[v[a]] < 0) { all = false; break; }
      gi[a] = grid_of_fe_[v[a]] % g.nnx;
      gj[a] = grid_of_fe_[v[a]] / g.nnx;
    }
    if (all) {
      const long i0 = *std::min_element(gi, gi + 4), j0 = *std::min_element(gj, gj + 4);
      bool ok = true;
      for (int a = 0; a < 4; ++a) ok = ok && gi[a] - i0 <= 1 && gj[a] - j0 <= 1;
      // Four distinct corners of one cell.
      std::array<int, 4> seen{{0, 0, 0, 0}};
      for (int a = 0; a < 4 && ok; ++a) seen[(gj[a] - j0) * 2 + (gi[a] - i0)]++;
      ok = ok && seen == std::array<int, 4>{{1, 1, 1, 1}};
      if (ok && i0 < g.nx && j0 < g.ny) {
        fe_cell_[j0 * g.nx + i0] = 1;
        unit[c] = 1;
        continue;
      }
    }
    double qx[4], qy[4];
    double bx0 = 1e300, by0 = 1e300, bx1 = -1e300, by1 = -1e300;
    for (int a = 0; a < 4; ++a) {
      qx[a] = X[v[a]]; qy[a] = Y[v[a]];
      bx0 = std::min(bx0, qx[a]); bx1 = std::max(bx1, qx[a]);
      by0 = std::min(by0, qy[a]); by1 = std::max(by1, qy[a]);
    }
    const long i0 = std::max(0L, static_cast<long>(std::floor((bx0 - g.x0) / h)));
    const long i1 = std::min<long>(g.nx - 1, static_cast<long>(std::floor((bx1 - g.x0) / h)));
    const long j0 = std::max(0L, static_cast<long>(std::floor((by0 - g.y0) / h)));
    const long j1 = std::min<long>(g.ny - 1, static_cast<long>(std::floor((by1 - g.y0) / h)));
    for (long j = j0; j <= j1; ++j)
      for (long i = i0; i <= i1; ++i)
        if (inside_quad(qx, qy, g.x0 + (i + 0.5) * h, g.y0 + (j + 0.5) * h, 1e-9 * h))
          fe_cell_[j * g.nx + i] = 1;
  }

  fe_row_lo_ = g.ny;
  fe_row_hi_ = -1;
  for (long j = 0; j < g.ny; ++j)
    for (long i = 0; i < g.nx; ++i)
      if (fe_cell_[j * g.nx + i]) {
        fe_row_lo_ = std::min(fe_row_lo_, j);
        fe_row_hi_ = std::max(fe_row_hi_, j);
      }

  // Particles: none in an FE cell; volume per grid cell.
  check_particles_in_fe_cells(true);
  std::vector<double> cell_vol(fe_cell_.size(), 0.0);
  const Particles& P = mpm_.p;
  for (std::size_t k = 0; k < P.size(); ++k) {
    const long i = static_cast<long>(std::floor((P.x[k] - g.x0) * g.inv_h));
    const long j = static_cast<long>(std::floor((P.y[k] - g.y0) * g.inv_h));
    if (i >= 0 && j >= 0 && i < g.nx && j < g.ny) cell_vol[j * g.nx + i] += P.vol[k];
  }
  // Grid nodes that are a corner of an occupied cell / of a cell not covered by the FE mesh.
  std::vector<std::uint8_t> node_mpm(g.nodes(), 0), node_open(g.nodes(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const long c = static_cast<long>(j) * g.nx + i;
      const long n0 = static_cast<long>(j) * g.nnx + i;
      const long corner[4] = {n0, n0 + 1, n0 + g.nnx, n0 + g.nnx + 1};
      for (long n : corner) {
        if (cell_vol[c] > 0) node_mpm[n] = 1;
        if (!fe_cell_[c]) node_open[n] = 1;
      }
    }

  // An FE node on an occupied MPM cell must be a grid node.
  for (std::size_t e = 0; e < nfe; ++e) {
    if (grid_of_fe_[e] >= 0) continue;
    const double fx = (X[e] - g.x0) / h, fy = (Y[e] - g.y0) / h;
    const long i = static_cast<long>(std::floor(fx)), j = static_cast<long>(std::floor(fy));
    for (long dj = -1; dj <= 0; ++dj)
      for (long di = -1; di <= 0; ++di) {
        const long ci = i + di, cj = j + dj;
        if (ci < 0 || cj < 0 || ci >= g.nx || cj >= g.ny) continue;
        // The node lies in the closed cell (ci, cj)?
        if (fx < ci - 1e-6 || fx > ci + 1 + 1e-6 || fy < cj - 1e-6 || fy > cj + 1 + 1e-6) continue;
        if (cell_vol[cj * g.nx + ci] > 0)
          throw HybridError("hybrid: FE node " + std::to_string(e) + " at " + pt(X[e], Y[e]) +
                            " lies on the MPM cell (" + std::to_string(ci) + ", " +
                            std::to_string(cj) + ") but not on a grid node: the FE nodes on the "
                            "interface must coincide with grid nodes (same spacing h = " +
                            std::to_string(h) + " m, same origin)");
      }
  }
  // An FE cell touching the MPM region must be exactly one grid cell.
  for (std::size_t c = 0; c < ncell; ++c) {
    if (unit[c]) continue;
    for (int a = 0; a < 4; ++a) {
      const std::uint32_t e = cn[4 * c + a];
      if (grid_of_fe_[e] >= 0 && node_mpm[grid_of_fe_[e]])
        throw HybridError("hybrid: the FE cell with a node at " + pt(X[e], Y[e]) +
                          " on the MPM region is not one grid cell: the FE spacing at the "
                          "interface must equal grid.h = " + std::to_string(h) +
                          " m with nodes on grid nodes");
    }
  }

  // Shared nodes.
  const auto& mask = fe_.constraint_mask();
  for (std::size_t e = 0; e < nfe; ++e) {
    const std::int64_t n = grid_of_fe_[e];
    if (n < 0 || !node_open[n]) {
      grid_of_fe_[e] = -1;
      continue;
    }
    shared_.push_back({static_cast<std::uint32_t>(e), static_cast<std::uint32_t>(n)});
    has_mpm_mass_.push_back(node_mpm[n]);
    interface_count_ += node_mpm[n];
    mpm_.grid.fix[n] |= mask[e];  // FE essential conditions hold on the shared node
  }

  if (interface_count_ == 0)
    throw HybridError("hybrid: the FEM mesh does not touch the particles: no FE node coincides (within "
                      "h 1e-6) with a grid node of an MPM cell holding particles; the interface nodes "
                      "must be grid nodes (grid origin + integer multiples of h = " +
                      std::to_string(h) + " m)");

  // MPM cells touching the interface must be full.
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const long c = static_cast<long>(j) * g.nx + i;
      if (fe_cell_[c] || cell_vol[c] <= 0) continue;
      const long n0 = static_cast<long>(j) * g.nnx + i;
      const long corner[4] = {n0, n0 + 1, n0 + g.nnx, n0 + g.nnx + 1};
      bool touches = false;
      for (const auto& s : shared_)
        for (long n : corner) touches = touches || s[1] == static_cast<std::uint32_t>(n);
      if (!touches) continue;
      const double fill = cell_vol[c] / (h * h);
      if (std::abs(fill - 1) > 1e-3) {
        std::ostringstream o;
        o << "hybrid: the MPM cell (" << i << ", " << j << ") at "
          << pt(g.x0 + (i + 0.5) * h, g.y0 + (j + 0.5) * h)
          << " touches the interface but is partly filled (particle volume " << fill
          << " h^2): MPM cells next to the FE region must be full (a half-empty cell is a density "
             "jump that reflects); align the MPM bodies with the grid at the interface";
        throw HybridError(o.str());
      }
    }

  // No MPM traction on an interface node.
  {
    std::vector<std::uint8_t> is_shared(g.nodes(), 0);
    for (const auto& s : shared_) is_shared[s[1]] = 1;
    for (const auto& tl : mpm_.tractions)
      for (std::size_t q = 0; q < tl.layer.idx.size(); ++q) {
        Bilinear sf;
        long nodes[4];
        mpm_.layer_shape(tl.layer, q, tl.anchor, sf, nodes);
        for (int a = 0; a < 4; ++a)
          if (sf.N[a] > 1e-12 && is_shared[nodes[a]])
            throw HybridError("hybrid: the MPM traction \"" + tl.layer.name +
                              "\" loads the interface node at " +
                              pt(g.node_x(nodes[a] % g.nnx), g.node_y(nodes[a] / g.nnx)) +
                              ": no external load may act on a node shared with the FEM region");
      }
  }

  // FE dashpot blocks by node.
  dash_of_fe_.assign(nfe, -1);
  const auto& D = fe_.dashpots();
  for (std::size_t k = 0; k < D.size(); ++k) dash_of_fe_[D[k].node] = static_cast<std::int32_t>(k);

  fint_.assign(2 * nfe, 0.0);
  fext_.assign(2 * nfe, 0.0);
  mpm_v_.assign(2 * shared_.size(), 0.0);
  sum_v_.assign(2 * shared_.size(), 0.0);
  fe_.internal_force(fe_.displacement().data(), fint_.data());
  fe_energies(false);
  fe_initial_ = fe_kinetic_ + fe_elastic_;
  mpm_.update_energies();
  energy = Energies();
  energy.initial = mpm_.energy.initial + fe_initial_;
  update_energies();
  mpm_.attach(this);
}

Hybrid::~Hybrid() { mpm_.detach(this); }

double Hybrid::critical_dt() const { return std::min(mpm_.critical_dt(), fe_.critical_dt()); }

void Hybrid::set_dt(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw HybridError("hybrid: time step must be > 0, got " + std::to_string(dt));
  try {
    fe_.set_dt(dt);
  } catch (const fem::FemError& e) {
    throw HybridError(std::string("hybrid: ") + e.what());
  }
  mpm_.dt = dt;
}

void Hybrid::check_particles_in_fe_cells(bool at_setup) const {
  const Grid& g = mpm_.grid;
  const Particles& P = mpm_.p;
  const long n = static_cast<long>(P.size());
  const std::uint8_t* fc = fe_cell_.data();
  if (!at_setup) {
    // The step that moved the particles recorded the rows they occupy, per strip: when none of
    // those rows holds an FE cell (the film: particles above the interface), nothing to check.
    long lo, hi;
    mpm_.occupied_rows(lo, hi);
    if (lo > hi || hi < fe_row_lo_ || lo > fe_row_hi_) return;
  }
  long first = n;
#pragma omp parallel for schedule(static) reduction(min : first) num_threads(mpm_.thread_count())
  for (long k = 0; k < n; ++k) {
    const long i = static_cast<long>(std::floor((P.x[k] - g.x0) * g.inv_h));
    const long j = static_cast<long>(std::floor((P.y[k] - g.y0) * g.inv_h));
    if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) continue;  // Solver reports leaving the grid
    if (fc[j * g.nx + i] && k < first) first = k;
  }
  if (first == n) return;
  std::ostringstream o;
  o << "hybrid: particle " << P.id[first] << " at " << pt(P.x[first], P.y[first]) << " is inside an "
    << "FE cell";
  if (at_setup) o << " at setup: the MPM bodies overlap the FEM mesh";
  else
    o << " at step " << mpm_.steps << " (t = " << mpm_.t
      << " s): particles may not enter the FEM region; enlarge the MPM region";
  throw HybridError(o.str());
}

// ---- the hooks of the coupled step ----------------------------------------------------------

void Hybrid::after_momentum(Solver& S) {
  if (S.contact.multi())
    throw HybridError("hybrid: multi-velocity-field contact is not supported with an FEM region");
  if (S.opt.scheme == Scheme::USF)
    throw HybridError("hybrid: the coupled step supports the USL and MUSL schemes, not USF");
}

// After the MPM p2g and particle-carried loads: FE forces at u^n, then their share, the FE
// masses and momenta at the shared nodes.
void Hybrid::after_forces(Solver& S) {
  Grid& g = S.grid;
  if (fe_.dt != S.dt) set_dt(S.dt);
  fe_.internal_force(fe_.displacement().data(), fint_.data());
  fe_.refresh_external_force(S.t, fext_.data());
  const auto& mfe = fe_.mass();
  const std::vector<double>& v = fe_.velocity();
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::uint32_t e = shared_[k][0], n = shared_[k][1];
    // The particles' own velocity at the node, for their FLIP increment (before_g2p).
    mpm_v_[2 * k] = g.m[n] > 0 ? g.px[n] / g.m[n] : 0.0;
    mpm_v_[2 * k + 1] = g.m[n] > 0 ? g.py[n] / g.m[n] : 0.0;
    if (has_mpm_mass_[k] && (fext_[2 * e] != 0 || fext_[2 * e + 1] != 0))
      throw HybridError("hybrid: an FEM boundary load acts on the interface node at " +
                        pt(fe_.node_x()[e], fe_.node_y()[e]) +
                        ": no external load may act on a node shared with the MPM region");
    g.m[n] += mfe[e];
    g.px[n] += mfe[e] * v[2 * e];
    g.py[n] += mfe[e] * v[2 * e + 1];
    g.fx[n] += fint_[2 * e] + fext_[2 * e];
    g.fy[n] += fint_[2 * e + 1] + fext_[2 * e + 1];
  }
}

// After the one velocity update on the grid (shared nodes included): FE dashpot blocks at shared
// nodes, those nodes redone semi-implicitly with the summed mass.
void Hybrid::after_grid_update(Solver& S) {
  Grid& g = S.grid;
  const double dt = S.dt;
  const auto& D = fe_.dashpots();
  double absorbed = 0;
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::uint32_t e = shared_[k][0], n = shared_[k][1];
    if (dash_of_fe_[e] < 0) continue;
    const auto& c = D[dash_of_fe_[e]];
    const double vx = g.vx[n], vy = g.vy[n];
    double a, b;
    dashpot_velocity(g.m[n], c.cxx + g.cxx[n], c.cxy + g.cxy[n], c.cyy + g.cyy[n], vx, vy, g.fx[n],
                     g.fy[n], dt, g.fix[n], a, b);
    g.vnx[n] = a;
    g.vny[n] = b;
    const double bx = 0.5 * (vx + a), by = 0.5 * (vy + b);
    absorbed += dt * (bx * (c.cxx * bx + c.cxy * by) + by * (c.cxy * bx + c.cyy * by));
  }
  step_absorbed_ = absorbed;
}

// After the MPM boundary work is booked, before the particles take their velocities.
void Hybrid::before_g2p(Solver& S) {
  Grid& g = S.grid;
  const double dt = S.dt;
  std::vector<double>& v = fe_.velocity();
  double absorbed = step_absorbed_;
  // FLIP increments of the particles use, at a shared node, the particles' own projected
  // velocity as the old one: Sum_p m_p dv_p + m_FE dv_FE = m v+ - p_MPM - m_FE v_FE = dt f, so the
  // total momentum changes only by the external forces. (The summed velocity (p_MPM + m_FE v_FE)/m
  // would leave m_FE m_MPM / m (v_MPM - v_FE) unbalanced at every shared node.)
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::uint32_t n = shared_[k][1];
    sum_v_[2 * k] = g.vx[n];
    sum_v_[2 * k + 1] = g.vy[n];
    if (!(g.fix[n] & 1)) g.vx[n] = mpm_v_[2 * k];
    if (!(g.fix[n] & 2)) g.vy[n] = mpm_v_[2 * k + 1];
  }

  // FE nodes not shared: their own update in the fem library (lumped mass, semi-implicit
  // dashpots, constraints; u^{n+1} = u^n + dt v+ there, USL and MUSL alike: MUSL's re-mapped
  // velocity differs from v+ only at nodes with particle mass, the shared ones, done below).
  fe_.advance_free_nodes(grid_of_fe_.data(), fint_.data(), fext_.data(), dt, fe_work_, absorbed);
  // Shared nodes take the grid velocity; FE loads there (FE-only nodes) do work with it.
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::uint32_t e = shared_[k][0], n = shared_[k][1];
    fe_work_ += dt * (fext_[2 * e] * 0.5 * (sum_v_[2 * k] + g.vnx[n]) +
                      fext_[2 * e + 1] * 0.5 * (sum_v_[2 * k + 1] + g.vny[n]));
    v[2 * e] = g.vnx[n];
    v[2 * e + 1] = g.vny[n];
  }
  fe_absorbed_ += absorbed;
}

// MUSL strains the particles with the re-mapped velocity q / m; at a shared node the FE nodes'
// momentum is part of q, and the FE displacement there advances with the same re-mapped velocity
// (end_of_step), so both sides of the interface see one displacement increment (advancing the FE
// with v+ instead reflects about twice as much: 1.5 % vs 0.8 % for a 20-cell pulse).
void Hybrid::after_remap(Solver& S) {
  Grid& g = S.grid;
  const auto& mfe = fe_.mass();
  const std::vector<double>& v = fe_.velocity();
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::uint32_t e = shared_[k][0], n = shared_[k][1];
    g.qx[n] += mfe[e] * v[2 * e];
    g.qy[n] += mfe[e] * v[2 * e + 1];
  }
}

void Hybrid::end_of_step(Solver& S) {
  Grid& g = S.grid;
  if (S.opt.scheme == Scheme::MUSL) advance_shared_displacement(g.qx, g.qy);
  else advance_shared_displacement(g.vnx, g.vny);
  fe_.t = S.t;
  ++fe_.steps;
  check_particles_in_fe_cells(false);
}

// u^{n+1} = u^n + dt w at the shared nodes, w the grid velocity that strains the particles.
void Hybrid::advance_shared_displacement(const std::vector<double>& wx, const std::vector<double>& wy) {
  double* u = fe_.displacement().data();
  const double dt = mpm_.dt;
  for (const auto& s : shared_) {
    u[2 * s[0]] += dt * wx[s[1]];
    u[2 * s[0] + 1] += dt * wy[s[1]];
  }
}

// FE energies: kinetic 1/2 v M v; elastic 1/2 u^n K u^{n+1} (fint_ = -K u^n of the last step) or
// 1/2 u K u before the first step.
void Hybrid::fe_energies(bool) {
  const auto& m = fe_.mass();
  const auto& v = fe_.velocity();
  const auto& u = fe_.displacement();
  double kin = 0, el = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    kin += 0.5 * m[i] * (v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1]);
    el -= 0.5 * (fint_[2 * i] * u[2 * i] + fint_[2 * i + 1] * u[2 * i + 1]);
  }
  fe_kinetic_ = kin;
  fe_elastic_ = el;
}

void Hybrid::update_energies() {
  mpm_.update_energies();
  fe_energies(true);
  fe_.energy.kinetic = fe_kinetic_;
  fe_.energy.elastic = fe_elastic_;
  fe_.energy.absorbed = fe_absorbed_;
  fe_.energy.external_work = fe_work_;
  fe_.energy.initial = fe_initial_;
  const Energies& a = mpm_.energy;
  energy.kinetic = a.kinetic + fe_kinetic_;
  energy.elastic = a.elastic + fe_elastic_;
  energy.dissipated = a.dissipated;
  energy.absorbed = a.absorbed + fe_absorbed_;
  energy.external_work = a.external_work + fe_work_;
}

std::array<double, 2> Hybrid::momentum() const {
  const Particles& P = mpm_.p;
  double mx = 0, my = 0;
  for (std::size_t k = 0; k < P.size(); ++k) {
    mx += P.mass[k] * P.vx[k];
    my += P.mass[k] * P.vy[k];
  }
  const auto& m = fe_.mass();
  const auto& v = fe_.velocity();
  for (std::size_t i = 0; i < m.size(); ++i) {
    mx += m[i] * v[2 * i];
    my += m[i] * v[2 * i + 1];
  }
  return {mx, my};
}

}  // namespace smpm

namespace smpm {

// Checkpoints: both regions' states and the coupling's own accounts (the FE region's energy
// terms as the coupled step books them) and work arrays.
void Hybrid::save_state(StateWriter& w) const {
  mpm_.save_state(w, "mpm.");
  fe_.save_state(w, "fem.");
  w.put("hybrid.energy", energy);
  w.put("hybrid.fe_terms", std::vector<double>{step_absorbed_, fe_kinetic_, fe_elastic_,
                                               fe_absorbed_, fe_work_, fe_initial_});
  w.put("hybrid.fint", fint_);
  w.put("hybrid.fext", fext_);
  w.put("hybrid.mpm_v", mpm_v_);
  w.put("hybrid.sum_v", sum_v_);
}

bool Hybrid::load_state(const StateReader& r) {
  const bool same_order = mpm_.load_state(r, "mpm.");
  fe_.load_state(r, "fem.");
  energy = r.get<Energies>("hybrid.energy");
  std::vector<double> terms;
  r.get("hybrid.fe_terms", terms, 6);
  step_absorbed_ = terms[0];
  fe_kinetic_ = terms[1];
  fe_elastic_ = terms[2];
  fe_absorbed_ = terms[3];
  fe_work_ = terms[4];
  fe_initial_ = terms[5];
  r.get("hybrid.fint", fint_, fint_.size());
  r.get("hybrid.fext", fext_, fext_.size());
  r.get("hybrid.mpm_v", mpm_v_, mpm_v_.size());
  r.get("hybrid.sum_v", sum_v_, sum_v_.size());
  return same_order;
}

}  // namespace smpm
