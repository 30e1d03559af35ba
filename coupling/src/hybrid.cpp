// MPM-FEM coupled explicit step through shared nodes: see silentmpm/hybrid.hpp.
#include "silentmpm/hybrid.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
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
  for (const SilentBoundary& sl : mpm_.silents)
    if (sl.delayed)
      throw HybridError("hybrid: the MPM region's silent edge \"" + sl.layer.name +
                        "\" has \"edge_velocity\": \"delayed\", which the coupled step does "
                        "not support (its interface nodes take the FE region's velocity); use "
                        "\"remapped\" or \"updated\"");
  if (fe_.degree() != 1)
    throw HybridError("hybrid: the FEM region must use fem.degree 1 (Q1, like the MPM grid), got " +
                      std::to_string(fe_.degree()));
  if (fe_.localized())
    throw HybridError("hybrid: the FEM region is built whole (Hybrid::distribute keeps each rank's "
                      "part of it)");
  const auto& X = fe_.node_x();
  const auto& Y = fe_.node_y();
  const std::size_t nfe = X.size();
  const auto fg = fe_.gravity();
  if (fg[0] != mpm_.opt.gravity_x || fg[1] != mpm_.opt.gravity_y) {
    std::ostringstream o;
    o << "hybrid: the MPM region's gravity (" << mpm_.opt.gravity_x << ", " << mpm_.opt.gravity_y
      << ") m/s^2 differs from the FEM region's (" << fg[0] << ", " << fg[1]
      << "): give both regions the same body force";
    throw HybridError(o.str());
  }
  gx_ = fg[0];
  gy_ = fg[1];

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
  gx0_ = g.x0;
  gy0_ = g.y0;
  gnx_ = g.nx;
  gny_ = g.ny;
  std::vector<double> cell_vol(fe_cell_.size(), 0.0), cell_big(fe_cell_.size(), 0.0);
  const Particles& P = mpm_.p;
  for (std::size_t k = 0; k < P.size(); ++k) {
    const long i = static_cast<long>(std::floor((P.x[k] - g.x0) * g.inv_h));
    const long j = static_cast<long>(std::floor((P.y[k] - g.y0) * g.inv_h));
    if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) continue;
    cell_vol[j * g.nx + i] += P.vol[k];
    cell_big[j * g.nx + i] = std::max(cell_big[j * g.nx + i], P.vol[k]);
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

  // An FE node on an occupied MPM cell, or within a cell of one, must be a grid node (the
  // elements that touch the particles are grid cells, so their nodes and the next row's are).
  for (std::size_t e = 0; e < nfe; ++e) {
    if (grid_of_fe_[e] >= 0) continue;
    const double fx = (X[e] - g.x0) / h, fy = (Y[e] - g.y0) / h;
    const long i = static_cast<long>(std::floor(fx)), j = static_cast<long>(std::floor(fy));
    for (int near = 0; near <= 1; ++near)
      for (long dj = -1 - near; dj <= near; ++dj)
        for (long di = -1 - near; di <= near; ++di) {
          const long ci = i + di, cj = j + dj;
          if (ci < 0 || cj < 0 || ci >= g.nx || cj >= g.ny) continue;
          // The node lies in the closed cell (ci, cj), or (near) within a cell of it?
          const double r = near + 1e-6;
          if (fx < ci - r || fx > ci + 1 + r || fy < cj - r || fy > cj + 1 + r) continue;
          if (cell_vol[cj * g.nx + ci] > 0)
            throw HybridError("hybrid: FE node " + std::to_string(e) + " at " + pt(X[e], Y[e]) +
                              (near ? " lies within a cell of" : " lies on") + " the MPM cell (" +
                              std::to_string(ci) + ", " + std::to_string(cj) +
                              "), which holds particles, but not on a grid node: the FE nodes on "
                              "the interface must coincide with grid nodes (same spacing h = " +
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

  // After the mesh's alignment with the grid: on a grid whose origin is off the mesh's nodes the
  // FE cells are marked on grid cells the particles' edge cells straddle, and the alignment is
  // what is wrong.
  if (const long k = particle_in_fe_cell(true); k >= 0) report_particle_in_fe_cell(k, true);

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

  // A shared node's update is the grid's, which takes no PML or stiffness-damping force of the
  // FE side: such layers must keep off the nodes the regions share.
  {
    const auto ex = fe_.explicit_force_nodes();
    for (const auto& s : shared_)
      if (std::binary_search(ex.begin(), ex.end(), s[0]))
        throw HybridError("hybrid: the FE node at " + pt(X[s[0]], Y[s[0]]) +
                          ", which the FEM region shares with the MPM grid, lies in a perfectly "
                          "matched layer or in a damping layer with beta: keep those layers away "
                          "from the nodes the regions share (the grid's update does not take "
                          "their forces)");
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
      // A particle of a cell side (one per cell, or one per side along an axis): the grid's
      // odd-even pattern, which such particles do not map back (R's eigenvalue 0), takes k + 1
      // times its increment from the mass correction, and the FE nodes take it too: the
      // interface then reflects more than without the correction (docs/physics.md section 7).
      if (coarse_cell_.empty() && cell_big[c] > 0.3 * h * h) {
        std::ostringstream o;
        o << "the MPM cell (" << i << ", " << j << ") at "
          << pt(g.x0 + (i + 0.5) * h, g.y0 + (j + 0.5) * h) << " holds a particle of "
          << cell_big[c] / (h * h) << " h^2";
        coarse_cell_ = o.str();
      }
    }
  check_mass_correction(mpm_);
  if (mpm_.opt.light_node_ratio > 0)
    throw HybridError("scheme.light_nodes",
                      "\"extend\" is not supported with an FEM region (the window's edge "
                      "nodes are the far field's); use \"keep\"");

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

  // What each shared node needs of the FE side (fe_at_ and the copies beside it).
  {
    std::vector<std::int32_t> dash_of(nfe, -1);
    const auto& D = fe_.dashpots();
    for (std::size_t k = 0; k < D.size(); ++k) dash_of[D[k].node] = static_cast<std::int32_t>(k);
    const std::size_t ns = shared_.size();
    const auto& mfe = fe_.mass();
    const auto& v = fe_.velocity();
    fe_at_.resize(ns);
    fe_m_.resize(ns);
    fe_v_.resize(2 * ns);
    fe_c_.assign(3 * ns, 0.0);
    fe_dash_.assign(ns, 0);
    fe_xy_.resize(2 * ns);
    for (std::size_t k = 0; k < ns; ++k) {
      const std::uint32_t e = shared_[k][0];
      fe_at_[k] = e;
      fe_m_[k] = mfe[e];
      fe_v_[2 * k] = v[2 * e];
      fe_v_[2 * k + 1] = v[2 * e + 1];
      fe_xy_[2 * k] = X[e];
      fe_xy_[2 * k + 1] = Y[e];
      if (dash_of[e] < 0) continue;
      const auto& c = D[dash_of[e]];
      fe_dash_[k] = 1;
      fe_c_[3 * k] = c.cxx;
      fe_c_[3 * k + 1] = c.cxy;
      fe_c_[3 * k + 2] = c.cyy;
    }
  }

  fint_.assign(2 * nfe, 0.0);
  fext_.assign(2 * nfe, 0.0);
  mpm_v_.assign(2 * shared_.size(), 0.0);
  sum_v_.assign(2 * shared_.size(), 0.0);
  node_.resize(shared_.size());
  for (std::size_t k = 0; k < shared_.size(); ++k) node_[k] = shared_[k][1];
  fe_own_.assign(shared_.size(), 1);
  mpm_own_.assign(shared_.size(), 1);
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

long Hybrid::particle_in_fe_cell(bool at_setup) const {
  const Grid& g = mpm_.grid;
  const Particles& P = mpm_.p;
  const long n = static_cast<long>(P.size());
  const std::uint8_t* fc = fe_cell_.data();
  if (!at_setup) {
    // The step that moved the particles recorded the rows they occupy, per strip: when none of
    // those rows holds an FE cell (the film: particles above the interface), nothing to check.
    long lo, hi;
    mpm_.occupied_rows(lo, hi);
    if (lo > hi || hi + org_j_ < fe_row_lo_ || lo + org_j_ > fe_row_hi_) return -1;
  }
  // In the whole grid's cells (a rank's window starts elsewhere).
  const double x0 = gx0_, y0 = gy0_;
  const long nx = gnx_, ny = gny_;
  // The one with the lowest id (whatever order the particles are sorted in, on any rank).
  std::uint64_t lowest = std::numeric_limits<std::uint64_t>::max();
#pragma omp parallel for schedule(static) reduction(min : lowest) num_threads(mpm_.thread_count())
  for (long k = 0; k < n; ++k) {
    const long i = static_cast<long>(std::floor((P.x[k] - x0) * g.inv_h));
    const long j = static_cast<long>(std::floor((P.y[k] - y0) * g.inv_h));
    if (i < 0 || j < 0 || i >= nx || j >= ny) continue;  // Solver reports leaving the grid
    if (fc[j * nx + i]) lowest = std::min<std::uint64_t>(lowest, P.id[k]);
  }
  if (lowest == std::numeric_limits<std::uint64_t>::max()) return -1;
  for (long k = 0; k < n; ++k)
    if (P.id[k] == lowest) return k;
  return -1;
}

void Hybrid::report_particle_in_fe_cell(long k, bool at_setup) const {
  const Particles& P = mpm_.p;
  double id = k >= 0 ? static_cast<double>(P.id[k]) : -1, x = 0, y = 0;
  if (k >= 0) {
    x = P.x[k];
    y = P.y[k];
  }
  if (dist_) {  // the lowest id over the ranks, and where it is
    double neg = k >= 0 ? -id : -1e300;
    dist_->max(&neg, 1);
    const bool mine = k >= 0 && -neg == id;
    double where[3] = {mine ? x : 0.0, mine ? y : 0.0, mine ? 1.0 : 0.0};
    dist_->sum(where, 3);
    id = -neg;
    x = where[0] / std::max(1.0, where[2]);
    y = where[1] / std::max(1.0, where[2]);
  }
  std::ostringstream o;
  o << "hybrid: particle " << static_cast<std::uint64_t>(id) << " at " << pt(x, y)
    << " is inside an FE cell";
  if (at_setup) o << " at setup: the MPM bodies overlap the FEM mesh";
  else
    o << " at step " << mpm_.steps << " (t = " << mpm_.t
      << " s): particles may not enter the FEM region; enlarge the MPM region";
  throw HybridError(o.str());
}

void Hybrid::share(std::vector<double>& v) const {
  if (!dist_) return;
  const auto t0 = std::chrono::steady_clock::now();
  dist_->sum(v.data(), static_cast<int>(v.size()));
  share_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  share_values_ += static_cast<double>(v.size());
}

void Hybrid::distribute(Decomposition& d) {
  if (dist_) throw HybridError("hybrid: the coupling is already split over the MPI ranks");
  if (fe_.ranks() != d.size())
    throw HybridError("hybrid: split the FE far field over the same ranks first "
                      "(fem::Solver::distribute)");
  if (fe_.localized())
    throw HybridError("hybrid: the FE far field keeps its part in Hybrid::distribute: split it "
                      "with fem::Solver::distribute only");
  const Grid& g = mpm_.grid;
  const auto org = d.window_origin();
  const auto own = d.own_nodes();
  org_i_ = org[0];
  org_j_ = org[1];
  const long wnnx = gnx_ + 1;
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const long i = static_cast<long>(shared_[k][1]) % wnnx, j = static_cast<long>(shared_[k][1]) / wnnx;
    const long li = i - org_i_, lj = j - org_j_;
    node_[k] = li >= 0 && lj >= 0 && li < g.nnx && lj < g.nny ? lj * g.nnx + li : -1;
    mpm_own_[k] = i >= own[0] && i <= own[1] && j >= own[2] && j <= own[3];
    fe_own_[k] = fe_.node_owner(shared_[k][0]) == d.rank();
  }
  // This rank's part of the far field: its own nodes and those it receives, numbered in the
  // mesh's order; the coupling's arrays by FE node follow that numbering.
  fe_.localize();
  const std::vector<std::uint32_t> glob = fe_.global_nodes();
  std::vector<std::int64_t> grid_of(glob.size());
  std::vector<double> fint(2 * glob.size());
  for (std::size_t l = 0; l < glob.size(); ++l) {
    grid_of[l] = grid_of_fe_[glob[l]];
    fint[2 * l] = fint_[2 * glob[l]];
    fint[2 * l + 1] = fint_[2 * glob[l] + 1];
  }
  grid_of_fe_.swap(grid_of);
  fint_.swap(fint);
  fext_.assign(2 * glob.size(), 0.0);  // written on the loaded nodes before each use
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const auto it = std::lower_bound(glob.begin(), glob.end(), shared_[k][0]);
    fe_at_[k] = it != glob.end() && *it == shared_[k][0] ? it - glob.begin() : -1;
  }
  fe_own_nodes_ = fe_.own_nodes();
  // The FE terms booked so far stay with rank 0 (each rank books its own nodes' from now on).
  if (d.rank() != 0) fe_absorbed_ = fe_work_ = 0;
  dist_ = &d;
}

// ---- the hooks of the coupled step ----------------------------------------------------------

// The mass correction needs 2 or more particles per cell side next to the interface, and its
// increment form (checked at set-up and at every step, for a correction turned on later).
void Hybrid::check_mass_correction(const Solver& S) const {
  if (S.symmetric_correction())
    throw HybridError("scheme.mass_correction_form",
                      "\"symmetric\" is not supported with an FEM region (the far field's "
                      "nodes take the increment's form only); use \"increment\"");
  if (S.opt.mass_correction > 0 && !coarse_cell_.empty())
    throw HybridError("scheme.mass_correction",
                      "needs 2 or more particles per cell side next to the interface, but " +
                          coarse_cell_ +
                      " (with fewer the correction makes the interface reflect more, not less); "
                      "seed more particles per cell, or set scheme.mass_correction to 0");
}

void Hybrid::after_momentum(Solver& S) {
  check_mass_correction(S);
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
  const std::vector<double>& v = fe_.velocity();
  const std::size_t ns = shared_.size();
  // The FE forces of the shared nodes (split: from their FE owners, summed over the ranks),
  // and how many FE owners found an FE load on a shared node that carries MPM mass (a guard).
  force_.assign(2 * ns + 1, 0.0);
  long loaded = -1;  // the first such node of this rank's
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t e = fe_at_[k];
    if (e >= 0) {
      fe_v_[2 * k] = v[2 * e];
      fe_v_[2 * k + 1] = v[2 * e + 1];
    }
    if (!fe_own_[k]) continue;
    if (loaded < 0 && has_mpm_mass_[k] && (fext_[2 * e] != 0 || fext_[2 * e + 1] != 0))
      loaded = static_cast<long>(k);
    force_[2 * k] = fint_[2 * e] + fext_[2 * e];
    force_[2 * k + 1] = fint_[2 * e + 1] + fext_[2 * e + 1];
  }
  force_[2 * ns] = loaded >= 0 ? 1.0 : 0.0;
  share(force_);
  if (force_[2 * ns] > 0) {  // every rank: the first such node over the ranks
    if (dist_) {
      double neg = loaded >= 0 ? -static_cast<double>(loaded) : -1e300;
      dist_->max(&neg, 1);
      loaded = static_cast<long>(-neg);
    }
    throw HybridError("hybrid: an FEM boundary load acts on the interface node at " +
                      pt(fe_xy_[2 * loaded], fe_xy_[2 * loaded + 1]) +
                      ": no external load may act on a node shared with the MPM region");
  }
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t n = node_[k];
    if (n < 0) continue;  // not in this rank's window
    // The particles' own velocity at the node, for their FLIP increment (before_g2p).
    mpm_v_[2 * k] = g.m[n] > 0 ? g.px[n] / g.m[n] : 0.0;
    mpm_v_[2 * k + 1] = g.m[n] > 0 ? g.py[n] / g.m[n] : 0.0;
    const double mfe = fe_m_[k];
    g.m[n] += mfe;
    g.px[n] += mfe * fe_v_[2 * k];
    g.py[n] += mfe * fe_v_[2 * k + 1];
    g.fx[n] += force_[2 * k];
    g.fy[n] += force_[2 * k + 1];
    if (gx_ != 0 || gy_ != 0) {  // the FE mass's weight (the MPM step's covers m_MPM only)
      g.fx[n] += mfe * gx_;
      g.fy[n] += mfe * gy_;
    }
  }
}

// After the one velocity update on the grid (shared nodes included): FE dashpot blocks at shared
// nodes, those nodes redone semi-implicitly with the summed mass.
void Hybrid::after_grid_update(Solver& S) {
  Grid& g = S.grid;
  const double dt = S.dt;
  double absorbed = 0;
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::int64_t n = node_[k];
    if (n < 0 || !fe_dash_[k]) continue;
    const double cxx = fe_c_[3 * k], cxy = fe_c_[3 * k + 1], cyy = fe_c_[3 * k + 2];
    const double vx = g.vx[n], vy = g.vy[n];
    double a, b;
    dashpot_velocity(g.m[n], cxx + g.cxx(n), cxy + g.cxy(n), cyy + g.cyy(n), vx, vy, g.fx[n],
                     g.fy[n], dt, g.fix[n], a, b);
    g.vnx[n] = a;
    g.vny[n] = b;
    // Booked with the velocity this update applied (the mass correction, opt.mass_correction,
    // changes v+ afterwards).
    if (!mpm_own_[k]) continue;  // every copy updates; the owner books
    const double bx = 0.5 * (vx + a), by = 0.5 * (vy + b);
    absorbed += dt * (bx * (cxx * bx + cxy * by) + by * (cxy * bx + cyy * by));
  }
  step_absorbed_ = absorbed;
}

// The mass correction's product at the shared nodes: their FE lumped mass, beside the
// particles' consistent mass. R = M^-1 (M_c + M_FE) there, so that the velocity the particles
// and the FE node map back next step, (p_MPM + m_FE v_FE) / m, moves by R times the increment
// both took (docs/physics.md section 7).
void Hybrid::add_mass_product(Solver&, const double* tx, const double* ty, double* ax,
                              double* ay) {
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::int64_t n = node_[k];
    if (n < 0) continue;  // not in this rank's window
    ax[n] += fe_m_[k] * tx[n];
    ay[n] += fe_m_[k] * ty[n];
  }
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
  // The summed velocity and v+ of every shared node (split: from their MPM owners).
  const std::size_t ns = shared_.size();
  vel_.assign(4 * ns, 0.0);
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t n = node_[k];
    if (n < 0) continue;
    if (mpm_own_[k]) {
      vel_[4 * k] = g.vx[n];
      vel_[4 * k + 1] = g.vy[n];
      // USL with the mass correction: the particles take its extra increment beyond v+, and
      // so does the FE node's velocity (its displacement advances with v+, as theirs do).
      const double ex = S.correction_extra_x(n), ey = S.correction_extra_y(n);
      vel_[4 * k + 2] = ex != 0 ? g.vnx[n] + ex : g.vnx[n];
      vel_[4 * k + 3] = ey != 0 ? g.vny[n] + ey : g.vny[n];
    }
    if (!(g.fix[n] & 1)) g.vx[n] = mpm_v_[2 * k];
    if (!(g.fix[n] & 2)) g.vy[n] = mpm_v_[2 * k + 1];
  }
  share(vel_);
  for (std::size_t k = 0; k < ns; ++k) {
    sum_v_[2 * k] = vel_[4 * k];
    sum_v_[2 * k + 1] = vel_[4 * k + 1];
  }

  // FE nodes not shared: their own update in the fem library (lumped mass, semi-implicit
  // dashpots, constraints; u^{n+1} = u^n + dt v+ there, USL and MUSL alike: MUSL's re-mapped
  // velocity differs from v+ only at nodes with particle mass, the shared ones, done below).
  fe_.advance_free_nodes(grid_of_fe_.data(), fint_.data(), fext_.data(), dt, fe_work_, absorbed);
  // Shared nodes take the grid velocity; FE loads there (FE-only nodes) do work with it.
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t e = fe_at_[k];
    const double vnx = vel_[4 * k + 2], vny = vel_[4 * k + 3];
    if (fe_own_[k])
      fe_work_ += dt * (fext_[2 * e] * 0.5 * (sum_v_[2 * k] + vnx) +
                        fext_[2 * e + 1] * 0.5 * (sum_v_[2 * k + 1] + vny));
    fe_v_[2 * k] = vnx;
    fe_v_[2 * k + 1] = vny;
    if (e < 0) continue;  // not in this rank's part of the far field
    v[2 * e] = vnx;
    v[2 * e + 1] = vny;
  }
  fe_absorbed_ += absorbed;
}

// MUSL strains the particles with the re-mapped velocity q / m; at a shared node the FE nodes'
// momentum is part of q, and the FE displacement there advances with the same re-mapped velocity
// (end_of_step), so both sides of the interface see one displacement increment (advancing the FE
// with v+ instead reflects about twice as much: 1.5 % vs 0.8 % for a 20-cell pulse).
void Hybrid::after_remap(Solver& S) {
  Grid& g = S.grid;
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    const std::int64_t n = node_[k];
    if (n < 0) continue;
    g.qx[n] += fe_m_[k] * fe_v_[2 * k];
    g.qy[n] += fe_m_[k] * fe_v_[2 * k + 1];
  }
}

// The shared nodes' displacements advance with the velocity that strains the particles (MUSL:
// the re-mapped q / m, USL: v+); split, from their MPM owners, in one sum with the particle
// check's verdict.
void Hybrid::end_of_step(Solver& S) {
  Grid& g = S.grid;
  const bool musl = S.opt.scheme == Scheme::MUSL;
  const std::vector<double>& wx = musl ? g.qx : g.vnx;
  const std::vector<double>& wy = musl ? g.qy : g.vny;
  const std::size_t ns = shared_.size();
  const long bad = particle_in_fe_cell(false);
  disp_.assign(2 * ns + 1, 0.0);
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t n = node_[k];
    if (n < 0 || !mpm_own_[k]) continue;
    disp_[2 * k] = wx[n];
    disp_[2 * k + 1] = wy[n];
  }
  disp_[2 * ns] = bad >= 0 ? 1.0 : 0.0;
  share(disp_);
  double* u = fe_.displacement().data();
  const double dt = S.dt;
  for (std::size_t k = 0; k < ns; ++k) {
    const std::int64_t e = fe_at_[k];
    if (e < 0) continue;  // not in this rank's part of the far field
    u[2 * e] += dt * disp_[2 * k];
    u[2 * e + 1] += dt * disp_[2 * k + 1];
  }
  fe_.t = S.t;
  ++fe_.steps;
  if (disp_[2 * ns] > 0) report_particle_in_fe_cell(bad, false);
}

// FE energies: kinetic 1/2 v M v; elastic 1/2 u^n K u^{n+1} (fint_ = -K u^n of the last step) or
// 1/2 u K u before the first step.
// Split over ranks: this rank's own nodes' shares.
void Hybrid::fe_energies(bool) {
  const auto& m = fe_.mass();
  const auto& v = fe_.velocity();
  const auto& u = fe_.displacement();
  const bool split = dist_ != nullptr;
  const std::size_t n = split ? fe_own_nodes_.size() : m.size();
  double kin = 0, el = 0;
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = split ? fe_own_nodes_[r] : r;
    kin += 0.5 * m[i] * (v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1]);
    el -= 0.5 * (fint_[2 * i] * u[2 * i] + fint_[2 * i + 1] * u[2 * i + 1]);
  }
  fe_kinetic_ = kin;
  fe_elastic_ = el;
}

void Hybrid::update_energies() {
  mpm_.update_energies();
  fe_energies(true);
  double fe[4] = {fe_kinetic_, fe_elastic_, fe_absorbed_, fe_work_};
  if (dist_) dist_->sum(fe, 4);
  fe_.energy.kinetic = fe[0];
  fe_.energy.elastic = fe[1];
  fe_.energy.absorbed = fe[2];
  fe_.energy.external_work = fe[3];
  fe_.energy.initial = fe_initial_;
  mpm_total_ = mpm_.total_energy();
  const Energies& a = mpm_total_;
  energy.kinetic = a.kinetic + fe[0];
  energy.elastic = a.elastic + fe[1];
  energy.dissipated = a.dissipated;
  energy.absorbed = a.absorbed + fe[2];
  energy.external_work = a.external_work + fe[3];
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
  const std::size_t n = dist_ ? fe_own_nodes_.size() : m.size();
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = dist_ ? fe_own_nodes_[r] : r;
    mx += m[i] * v[2 * i];
    my += m[i] * v[2 * i + 1];
  }
  double sum[2] = {mx, my};
  if (dist_) dist_->sum(sum, 2);
  return {sum[0], sum[1]};
}

}  // namespace smpm

namespace smpm {

// Checkpoints: both regions' states and the coupling's own accounts (the FE region's energy
// terms as the coupled step books them) and work arrays.
// Split over ranks (every rank calls it; the ranks write one process's checkpoint at once): the
// particles and the FE nodes as every rank's parts (each node's from its owner), the booked
// terms summed.
// (mpm_v and sum_v live within a step; they are saved as this rank holds them.)
void Hybrid::save_state(StateWriter& w) const {
  if (dist_) mpm_.save_state_parts(w, "mpm.");
  else mpm_.save_state(w, "mpm.");
  fe_.save_state(w, "fem.");
  w.put("hybrid.energy", energy);
  std::vector<double> terms{step_absorbed_, fe_kinetic_, fe_elastic_, fe_absorbed_, fe_work_};
  if (dist_) dist_->sum(terms.data(), static_cast<int>(terms.size()));
  terms.push_back(fe_initial_);
  w.put("hybrid.fe_terms", terms);
  fe_.put_nodes(w, "hybrid.fint", fint_);
  w.put("hybrid.mpm_v", mpm_v_);
  w.put("hybrid.sum_v", sum_v_);
}

// Reads one process's checkpoint into an unsplit coupling (distribute() after it).
bool Hybrid::load_state(const StateReader& r) {
  if (dist_) throw HybridError("hybrid: a checkpoint is read before the coupling is split over ranks");
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
  fe_.get_nodes(r, "fem.", "hybrid.fint", fint_);
  const std::vector<double>& v = fe_.velocity();  // the shared nodes' FE velocities with it
  for (std::size_t k = 0; k < shared_.size(); ++k) {
    fe_v_[2 * k] = v[2 * fe_at_[k]];
    fe_v_[2 * k + 1] = v[2 * fe_at_[k] + 1];
  }
  r.get("hybrid.mpm_v", mpm_v_, mpm_v_.size());
  r.get("hybrid.sum_v", sum_v_, sum_v_.size());
  return same_order;
}

}  // namespace smpm
