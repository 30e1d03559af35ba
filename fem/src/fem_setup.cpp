// FEM far-field setup with deal.II: mesh in, dofs numbered by node, lumped mass, stiffness in a
// node-block CSR, LK dashpot blocks, traction load vectors, the element bound on the time step,
// probes and snapshots. The time stepping itself is in fem_kernels.cpp (no deal.II).
#include <array>
#include <deal.II/base/exceptions.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/vector.h>
#include <omp.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <fstream>
#include <sstream>
#include <cstring>
#include <unordered_map>

#include "fem_impl.hpp"
#include "silentmpm/dashpot.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/output.hpp"

namespace smpm::fem {

using namespace dealii;

struct Deal {
  Triangulation<2> tria;
  std::unique_ptr<FESystem<2>> fe;
  std::unique_ptr<DoFHandler<2>> dofh;  // (declared after tria: destroyed before it, which it subscribes to)
  MappingQ<2> mapping{1};
  Deal() : dofh(std::make_unique<DoFHandler<2>>(tria)) {}
};

Solver::Impl::Impl() = default;
Solver::Impl::~Impl() = default;

namespace {

std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// The useful part of a deal.II exception message.
std::string deal_message(const std::exception& e) {
  const std::string w = e.what();
  const std::string key = "Additional information:";
  const std::size_t p = w.find(key);
  std::string s = p == std::string::npos ? w : w.substr(p + key.size());
  std::string out;
  bool space = false;
  for (char c : s) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += c;
  }
  const std::size_t stack = out.find("Stacktrace:");
  if (stack != std::string::npos) out = out.substr(0, stack);
  while (!out.empty() && (out.back() == ' ' || out.back() == '-')) out.pop_back();
  return out;
}

// Key of a cell's shape and material: cells with equal keys have equal element matrices.
std::vector<long long> cell_key(const Triangulation<2>::active_cell_iterator& cell) {
  const Point<2> v0 = cell->vertex(0);
  const double d = cell->diameter();
  int ex = 0;
  const double mant = std::frexp(d, &ex);
  std::vector<long long> k = {static_cast<long long>(cell->material_id()), ex,
                              std::llround(mant * 1e10)};
  for (unsigned v = 1; v < 4; ++v)
    for (unsigned c = 0; c < 2; ++c) k.push_back(std::llround((cell->vertex(v)[c] - v0[c]) / d * 1e10));
  return k;
}


}  // namespace

namespace {

// A boundary face of a PML's curves: its ends, the centre of its cell, c_d there, its curve.
struct PmlFace {
  double x0, y0, x1, y1, cx, cy, cd;
  int curve;
};

std::string num6(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// One layer: the band of depth `width` inside the line x = c (axis 0) or y = c (axis 1), on the
// side `side` (-1: the mesh lies at coordinates below c), with d = d0 s^power.
struct PmlBand {
  int axis = 0;
  double c = 0, width = 0, d0 = 0, power = 2, parallel = 0;
  int side = -1;
  double at(double x, double y) const {
    const double p = axis == 0 ? x : y;
    const double s = (p - (c - side * width)) * side / width;  // 0 at the inner edge, 1 at c
    if (!(s > 0)) return 0.0;
    return d0 * std::pow(std::min(s, 1.0), power);
  }
};

// The PMLs of `spec` (faces of their curves in `faces`): checks each is one straight edge along
// an axis, then keeps every cell with a quadrature point inside a layer (its shape gradients,
// weights and d_x, d_y there), the nodal terms, and a dashpot block for every node of those cells.
void setup_pml(Solver::Impl& m, Deal& d, const Spec& spec,
               const std::vector<std::vector<PmlFace>>& faces,
               std::map<std::uint32_t, std::array<double, 3>>& cblocks) {
  const std::string& file = spec.mesh.file;
  std::vector<PmlBand> bands;
  bool first = true;
  for (std::size_t b = 0; b < spec.boundaries.size(); ++b) {
    const Boundary& bc = spec.boundaries[b];
    if (bc.kind != Boundary::Kind::Pml || faces[b].empty()) continue;
    if (first) m.pml.alpha = bc.alpha;
    else if (bc.alpha != m.pml.alpha)
      throw FemError("FEM: boundary \"" + bc.name + "\": every pml of a model must have the same "
                     "alpha (" + num6(m.pml.alpha) + " and " + num6(bc.alpha) + " 1/s given)");
    first = false;
    const double span = std::hypot(m.box[2] - m.box[0], m.box[3] - m.box[1]);
    const double tol = 1e-9 * span;
    const PmlFace& f0 = faces[b].front();
    const int axis = std::fabs(f0.x1 - f0.x0) <= tol ? 0 : std::fabs(f0.y1 - f0.y0) <= tol ? 1 : -1;
    const double c = axis == 0 ? f0.x0 : f0.y0;
    for (const PmlFace& f : faces[b]) {
      const bool ok = axis == 0   ? std::fabs(f.x0 - c) <= tol && std::fabs(f.x1 - c) <= tol
                      : axis == 1 ? std::fabs(f.y0 - c) <= tol && std::fabs(f.y1 - c) <= tol
                                  : false;
      if (!ok) {
        const PhysicalGroup* g = spec.mesh.curve(f.curve);
        throw FemError(file + ": boundary \"" + bc.name + "\": a pml needs its curves to form one "
                       "straight edge parallel to the x or the y axis; physical curve " +
                       std::to_string(f.curve) +
                       (g && !g->name.empty() ? " (\"" + g->name + "\")" : std::string()) +
                       " has a face from (" + num6(f.x0) + ", " + num6(f.y0) + ") to (" +
                       num6(f.x1) + ", " + num6(f.y1) + ")");
      }
    }
    PmlBand band;
    band.axis = axis;
    band.c = c;
    band.width = bc.width;
    band.power = bc.power;
    band.parallel = bc.parallel;
    band.side = (axis == 0 ? f0.cx : f0.cy) < c ? 1 : -1;
    const double extent = axis == 0 ? m.box[2] - m.box[0] : m.box[3] - m.box[1];
    if (bc.width > extent * (1 + 1e-12))
      throw FemError(file + ": boundary \"" + bc.name + "\": the pml is " + num6(bc.width) +
                     " m thick, more than the mesh's extent across it (" + num6(extent) + " m)");
    double cd = 0;
    for (const PmlFace& f : faces[b]) cd = std::max(cd, f.cd);
    band.d0 = -(bc.power + 1) * cd * std::log(bc.r0) / (2 * bc.width);
    bands.push_back(band);
  }
  if (bands.empty()) return;
  auto dxy = [&](double x, double y, double& dx, double& dy) {
    dx = dy = 0;
    for (const auto& bd : bands) {  // the normal stretching, and a multi-axial layer's share along
      const double d = bd.at(x, y);
      (bd.axis == 0 ? dx : dy) += d;
      (bd.axis == 0 ? dy : dx) += bd.parallel * d;
    }
  };

  Solver::Impl::Pml& P = m.pml;
  const FiniteElement<2>& fe = *d.fe;
  const unsigned dpc = fe.n_dofs_per_cell();
  const QGauss<2> q(m.degree + 1);
  FEValues<2> fv(d.mapping, fe, q, update_gradients | update_JxW_values | update_quadrature_points);
  std::vector<types::global_dof_index> ld(dpc);
  P.nb = static_cast<int>(dpc / 2);
  P.nq = static_cast<int>(q.size());
  // Each layer cell: its nodes, its shape (cells of the same geometry share one table of shape
  // gradients, as they share their stiffness), and per quadrature point the weights
  // (d_y - d_x) JxW (lambda + 2 mu) and (d_y - d_x) JxW mu and d_x, d_y.
  struct Cell {
    std::uint32_t index;  // among the mesh's cells
    std::vector<std::uint32_t> nodes;
    std::uint32_t shape;
    std::vector<double> kl, km, dx, dy;
  };
  std::vector<Cell> cells;
  std::map<std::vector<long long>, std::uint32_t> shapes;
  std::set<std::uint32_t> touched;
  for (const auto& cell : d.dofh->active_cell_iterators()) {
    fv.reinit(cell);
    Cell c;
    c.index = static_cast<std::uint32_t>(cell->active_cell_index());
    c.dx.resize(q.size());
    c.dy.resize(q.size());
    bool inside = false;
    for (unsigned k = 0; k < q.size(); ++k) {
      const auto p = fv.quadrature_point(k);
      dxy(p[0], p[1], c.dx[k], c.dy[k]);
      inside = inside || c.dx[k] > 0 || c.dy[k] > 0;
    }
    if (!inside) continue;
    const Material& mat = spec.materials[spec.region_material.at(static_cast<int>(cell->material_id()))];
    cell->get_dof_indices(ld);
    std::vector<unsigned> comp0;  // the x dof of each node, in the cell's order
    for (unsigned i = 0; i < dpc; ++i)
      if (fe.system_to_component_index(i).first == 0) comp0.push_back(i);
    for (unsigned i : comp0) {
      c.nodes.push_back(static_cast<std::uint32_t>(ld[i] / 2));
      touched.insert(c.nodes.back());
    }
    const auto key = cell_key(cell);
    auto it = shapes.find(key);
    if (it == shapes.end()) {
      it = shapes.emplace(key, static_cast<std::uint32_t>(shapes.size())).first;
      for (unsigned k = 0; k < q.size(); ++k)
        for (unsigned i : comp0) {
          const Tensor<1, 2> g = fv.shape_grad(i, k);
          P.grad.push_back(g[0]);
          P.grad.push_back(g[1]);
        }
    }
    c.shape = it->second;
    for (unsigned k = 0; k < q.size(); ++k) {
      const double w = (c.dy[k] - c.dx[k]) * fv.JxW(k);
      c.kl.push_back(w * (mat.lambda + 2 * mat.mu));
      c.km.push_back(w * mat.mu);
    }
    cells.push_back(std::move(c));
  }
  // Colours: no two cells of one colour share a node, so each colour's cells add their forces
  // in parallel (greedy, lowest colour free at all of a cell's nodes).
  std::map<std::uint32_t, std::uint64_t> used;  // per node: the colours of its cells so far
  std::vector<int> colour(cells.size());
  int ncolours = 0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    std::uint64_t busy = 0;
    for (const auto n : cells[c].nodes) busy |= used[n];
    int k = 0;
    while (k < 63 && (busy >> k & 1)) ++k;
    colour[c] = k;
    ncolours = std::max(ncolours, k + 1);
    for (const auto n : cells[c].nodes) used[n] |= std::uint64_t{1} << k;
  }
  P.colour_start.assign(1, 0);
  std::map<std::array<double, 4>, std::uint32_t> kinds;  // the distinct kinds of point
  for (int k = 0; k < ncolours; ++k) {
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (colour[c] != k) continue;
      const Cell& e = cells[c];
      P.cell.push_back(e.index);
      P.cell_nodes.insert(P.cell_nodes.end(), e.nodes.begin(), e.nodes.end());
      P.shape.push_back(e.shape);
      for (std::size_t q = 0; q < e.kl.size(); ++q) {
        const std::array<double, 4> key{{e.kl[q], e.km[q], e.dx[q], e.dy[q]}};
        auto it = kinds.find(key);
        if (it == kinds.end()) {
          it = kinds.emplace(key, static_cast<std::uint32_t>(P.kl.size())).first;
          P.kl.push_back(e.kl[q]);
          P.km.push_back(e.km[q]);
          P.dx.push_back(e.dx[q]);
          P.dy.push_back(e.dy[q]);
        }
        P.kind.push_back(it->second);
      }
    }
    P.colour_start.push_back(static_cast<std::uint32_t>(P.shape.size()));
  }
  P.xi.assign(4 * P.kind.size(), 0.0);
  double lam = 0;
  for (const std::uint32_t node : touched) {
    P.touched.push_back(node);
    auto& c = cblocks[node];  // a block for every node of a layer cell (zero where d = 0)
    double dx, dy;
    dxy(m.x[node], m.y[node], dx, dy);
    if (!(dx + dy > 0)) continue;
    c[0] += m.mass[node] * (dx + dy);
    c[2] += m.mass[node] * (dx + dy);
    P.node.push_back(node);
    P.m_sum.push_back(m.mass[node] * (dx + dy));
    P.m_prod.push_back(m.mass[node] * dx * dy);
    lam = std::max(lam, dx * dy);
  }
  P.zeta.assign(4 * P.node.size(), 0.0);
  // The corner term m d_x d_y u is a spring of stiffness d_x d_y per unit mass.
  if (lam > 0 && m.crit_dt > 0) m.crit_dt = 2.0 / std::sqrt(4.0 / (m.crit_dt * m.crit_dt) + lam);
}

// Rows of K equal to another's bit for bit share one copy of their values (a structured mesh
// has a handful of kinds of rows: the inside, each side, each corner; the pulse plate's 501 264
// Q1 rows are 18 kinds), when that leaves at most an eighth of the values: the internal force
// then reads the columns and one offset per row instead of 36 values (Q1). The arithmetic is
// the same (the same values in the same order).
void share_equal_rows(Solver::Impl& m) {
  const std::size_t nn = m.rowptr.size() - 1;
  std::vector<std::uint32_t> row_val(nn);
  std::vector<double> kinds;  // the distinct rows' values, one after another
  // Hash of a row's bits -> the offsets (in blocks) and lengths of the distinct rows with it.
  std::unordered_map<std::uint64_t, std::vector<std::pair<std::uint32_t, std::size_t>>> seen;
  for (std::size_t i = 0; i < nn; ++i) {
    const double* r = m.val.data() + 4 * m.rowptr[i];
    const std::size_t n = 4 * (m.rowptr[i + 1] - m.rowptr[i]);
    std::uint64_t h = 1469598103934665603ull ^ n;
    for (std::size_t k = 0; k < n; ++k) {
      std::uint64_t bits;
      std::memcpy(&bits, r + k, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
    }
    auto& list = seen[h];
    bool found = false;
    for (const auto& [off, len] : list) {
      if (len == n &&
          std::memcmp(kinds.data() + 4 * static_cast<std::size_t>(off), r, n * sizeof(double)) == 0) {
        row_val[i] = off;
        found = true;
        break;
      }
    }
    if (found) continue;
    if (kinds.size() + n > m.val.size() / 8) return;  // too many kinds: keep every row's values
    row_val[i] = static_cast<std::uint32_t>(kinds.size() / 4);
    list.emplace_back(row_val[i], n);
    kinds.insert(kinds.end(), r, r + n);
  }
  m.row_val = std::move(row_val);
  m.val = std::move(kinds);
  m.row4.assign(nn / 4, 0);
  for (std::size_t g = 0; g < nn / 4; ++g) {
    const std::size_t i = 4 * g;
    const std::uint64_t n = m.rowptr[i + 1] - m.rowptr[i];
    bool same = true;
    for (std::size_t j = 1; j < 4 && same; ++j) {
      same = m.rowptr[i + j + 1] - m.rowptr[i + j] == n && m.row_val[i + j] == m.row_val[i];
      for (std::uint64_t k = 0; k < n && same; ++k)
        same = m.col[m.rowptr[i + j] + k] == m.col[m.rowptr[i] + k] + j;
    }
    m.row4[g] = same ? 1 : 0;
  }
  if (std::count(m.row4.begin(), m.row4.end(), 1) == 0) m.row4.clear();
}

}  // namespace

Solver::Solver(const Spec& spec) : impl_(std::make_unique<Impl>()) {
  // No MPI: the serial triangulation, dofs and matrices do not use it, and MPI_Init (it starts
  // OpenMPI's orted) costs ~0.04 s CPU and ~0.35 s wall; the snapshots are written without it.
  Impl& m = *impl_;
  m.spec = spec;
  m.deal = std::make_unique<Deal>();
  Deal& d = *m.deal;
  const std::string& file = spec.mesh.file;
  if (spec.degree != 1 && spec.degree != 2)
    throw FemError("FEM: degree must be 1 or 2, got " + std::to_string(spec.degree));
  m.degree = spec.degree;
  m.threads = spec.threads > 0 ? spec.threads : omp_get_max_threads();
  for (const auto& mat : spec.materials)
    if (mat.model != Model::Elastic)
      throw FemError("FEM: material \"" + mat.name +
                     "\" is not elastic; the FEM far-field is linear elastic");

  // --- mesh ---
  try {
    GridIn<2> gi;
    gi.attach_triangulation(d.tria);
    std::istringstream in(spec.mesh.msh);
    gi.read_msh(in);
  } catch (const std::exception& e) {
    throw FemError(file + ": deal.II cannot use this mesh: " + deal_message(e));
  }
  m.n_cells = d.tria.n_active_cells();
  for (const auto& cell : d.tria.active_cell_iterators()) {
    const int id = static_cast<int>(cell->material_id());
    if (!spec.region_material.count(id)) {
      const PhysicalGroup* g = spec.mesh.surface(id);
      throw FemError(file + ": physical surface " + std::to_string(id) +
                     (g && !g->name.empty() ? " (\"" + g->name + "\")" : std::string()) +
                     " has no material (add it to fem.regions)");
    }
  }
  {
    const auto& vs = d.tria.get_vertices();
    m.box = {{1e300, 1e300, -1e300, -1e300}};
    for (const auto& p : vs) {
      m.box[0] = std::min(m.box[0], p[0]);
      m.box[1] = std::min(m.box[1], p[1]);
      m.box[2] = std::max(m.box[2], p[0]);
      m.box[3] = std::max(m.box[3], p[1]);
    }
  }

  // --- dofs: Cuthill-McKee, then interleaved by node (dof = 2 node + component) ---
  d.fe = std::make_unique<FESystem<2>>(FE_Q<2>(m.degree), 2);
  const FESystem<2>& fe = *d.fe;
  d.dofh->distribute_dofs(fe);
  DoFRenumbering::Cuthill_McKee(*d.dofh);
  const unsigned dpc = fe.n_dofs_per_cell();
  const unsigned nbase = dpc / 2;
  const std::size_t ndofs = d.dofh->n_dofs();
  {
    std::vector<types::global_dof_index> partner(ndofs, numbers::invalid_dof_index);
    std::vector<types::global_dof_index> ld(dpc);
    for (const auto& cell : d.dofh->active_cell_iterators()) {
      cell->get_dof_indices(ld);
      for (unsigned b = 0; b < nbase; ++b)
        partner[ld[fe.component_to_system_index(0, b)]] = ld[fe.component_to_system_index(1, b)];
    }
    std::vector<types::global_dof_index> renum(ndofs);
    types::global_dof_index k = 0;
    for (std::size_t i = 0; i < ndofs; ++i)
      if (partner[i] != numbers::invalid_dof_index) {
        renum[i] = 2 * k;
        renum[partner[i]] = 2 * k + 1;
        ++k;
      }
    if (2 * k != ndofs) throw FemError(file + ": internal error numbering the nodes");
    d.dofh->renumber_dofs(renum);
  }
  const std::size_t nn = ndofs / 2;
  {  // the reference tables of the snapshots' gradients (Impl::ref_grad, map_grad)
    const FiniteElement<2>& fe0 = fe.base_element(0);
    const FE_Q<2> q1(1);
    const auto& at = fe0.get_unit_support_points();
    for (const auto& p : at) {
      for (unsigned b = 0; b < fe0.n_dofs_per_cell(); ++b) {
        const Tensor<1, 2> g = fe0.shape_grad(b, p);
        m.ref_grad.insert(m.ref_grad.end(), {g[0], g[1]});
      }
      for (unsigned v = 0; v < 4; ++v) {
        const Tensor<1, 2> g = q1.shape_grad(v, p);
        m.map_grad.insert(m.map_grad.end(), {g[0], g[1]});
      }
    }
  }
  {
    std::vector<Point<2>> pts(ndofs);
    DoFTools::map_dofs_to_support_points(d.mapping, *d.dofh, pts);
    m.x.resize(nn);
    m.y.resize(nn);
    for (std::size_t i = 0; i < nn; ++i) {
      m.x[i] = pts[2 * i][0];
      m.y[i] = pts[2 * i][1];
    }
  }

  // --- node-block sparsity ---
  std::vector<types::global_dof_index> ld(dpc);
  {
    std::vector<std::vector<std::uint32_t>> adj(nn);
    std::vector<std::uint32_t> cn(nbase);
    for (const auto& cell : d.dofh->active_cell_iterators()) {
      cell->get_dof_indices(ld);
      for (unsigned b = 0; b < nbase; ++b)
        cn[b] = static_cast<std::uint32_t>(ld[fe.component_to_system_index(0, b)] / 2);
      m.cell_nodes.insert(m.cell_nodes.end(), cn.begin(), cn.end());
      m.cell_region.push_back(static_cast<std::int32_t>(cell->material_id()));
      for (unsigned a = 0; a < nbase; ++a)
        for (unsigned b = 0; b < nbase; ++b) adj[cn[a]].push_back(cn[b]);
    }
    m.rowptr.assign(nn + 1, 0);
    for (std::size_t i = 0; i < nn; ++i) {
      auto& r = adj[i];
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
      m.rowptr[i + 1] = m.rowptr[i] + r.size();
    }
    m.col.resize(m.rowptr[nn]);
    for (std::size_t i = 0; i < nn; ++i) {
      std::copy(adj[i].begin(), adj[i].end(), m.col.begin() + m.rowptr[i]);
      std::vector<std::uint32_t>().swap(adj[i]);
    }
    m.val.assign(4 * m.col.size(), 0.0);
  }

  // --- stiffness, lumped mass, element bound on dt ---
  m.mass.assign(nn, 0.0);
  {
    const QGauss<2> qk(m.degree + 1);
    const QGaussLobatto<2> qm(m.degree + 1);
    FEValues<2> fk(d.mapping, fe, qk, update_gradients | update_JxW_values);
    FEValues<2> fm(d.mapping, fe, qm, update_values | update_JxW_values);
    const FEValuesExtractors::Vector disp(0);
    struct Elem {
      std::vector<double> K, M;
    };
    std::map<std::vector<long long>, Elem> cache;
    double lam_max = 0;
    for (const auto& cell : d.dofh->active_cell_iterators()) {
      const Material& mat = spec.materials[spec.region_material.at(static_cast<int>(cell->material_id()))];
      auto key = cell_key(cell);
      auto it = cache.find(key);
      if (it == cache.end()) {
        Elem e;
        e.K.assign(dpc * dpc, 0.0);
        e.M.assign(dpc, 0.0);
        fk.reinit(cell);
        fm.reinit(cell);
        for (unsigned q = 0; q < qk.size(); ++q)
          for (unsigned i = 0; i < dpc; ++i) {
            const auto ei = fk[disp].symmetric_gradient(i, q);
            const double di = fk[disp].divergence(i, q);
            for (unsigned j = 0; j < dpc; ++j)
              e.K[i * dpc + j] += (mat.lambda * di * fk[disp].divergence(j, q) +
                                   2 * mat.mu * (ei * fk[disp].symmetric_gradient(j, q))) *
                                  fk.JxW(q);
          }
        for (unsigned q = 0; q < qm.size(); ++q)
          for (unsigned i = 0; i < dpc; ++i) {
            const double phi = fm.shape_value(i, q);
            e.M[i] += mat.rho * phi * phi * fm.JxW(q);
          }
        for (unsigned i = 0; i < dpc; ++i)
          if (!(e.M[i] > 0))
            throw FemError(file + ": a cell has a non-positive lumped mass (degenerate or inverted element)");
        std::vector<double> s(dpc * dpc);
        for (unsigned i = 0; i < dpc; ++i)
          for (unsigned j = 0; j < dpc; ++j) s[i * dpc + j] = e.K[i * dpc + j] / std::sqrt(e.M[i] * e.M[j]);
        lam_max = std::max(lam_max, symmetric_max_eigenvalue(s, static_cast<int>(dpc)));
        it = cache.emplace(std::move(key), std::move(e)).first;
      }
      const Elem& e = it->second;
      cell->get_dof_indices(ld);
      for (unsigned i = 0; i < dpc; ++i) {
        const std::size_t ni = ld[i] / 2, ci = ld[i] % 2;
        if (ci == 0) m.mass[ni] += e.M[i];
        const std::uint32_t* b = m.col.data() + m.rowptr[ni];
        const std::uint32_t* en = m.col.data() + m.rowptr[ni + 1];
        for (unsigned j = 0; j < dpc; ++j) {
          const std::uint32_t nj = static_cast<std::uint32_t>(ld[j] / 2);
          const std::size_t cj = ld[j] % 2;
          const std::size_t k = std::lower_bound(b, en, nj) - m.col.data();
          m.val[4 * k + ci + 2 * cj] += e.K[i * dpc + j];
        }
      }
    }
    m.crit_dt = lam_max > 0 ? 2.0 / std::sqrt(lam_max) : 0.0;
  }
  m.inv_mass.resize(nn);
  for (std::size_t i = 0; i < nn; ++i) m.inv_mass[i] = 1.0 / m.mass[i];

  // --- boundary nodes per boundary id ---
  std::set<int> present_ids;
  {
    const unsigned dpf = fe.n_dofs_per_face();
    std::vector<types::global_dof_index> fd(dpf);
    for (const auto& cell : d.dofh->active_cell_iterators())
      for (const auto f : cell->face_indices())
        if (cell->face(f)->at_boundary()) {
          const int id = static_cast<int>(cell->face(f)->boundary_id());
          present_ids.insert(id);
          cell->face(f)->get_dof_indices(fd);
          auto& v = m.curve_nodes[id];
          for (auto g : fd)
            if (g % 2 == 0) v.push_back(static_cast<std::uint32_t>(g / 2));
        }
    for (auto& [id, v] : m.curve_nodes) {
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    }
  }
  for (const auto& bc : spec.boundaries)
    for (int c : bc.curves)
      if (!present_ids.count(c)) {
        const PhysicalGroup* g = spec.mesh.curve(c);
        throw FemError(file + ": boundary \"" + bc.name + "\": physical curve " + std::to_string(c) +
                       (g && !g->name.empty() ? " (\"" + g->name + "\")" : std::string()) +
                       (g ? " is not on the outer boundary of the mesh" : " is not in the mesh"));
      }

  // --- constraints ---
  m.mask.assign(nn, 0);
  for (const auto& bc : spec.boundaries) {
    if (bc.kind != Boundary::Kind::Fixed && bc.kind != Boundary::Kind::Roller) continue;
    const std::uint8_t bit = bc.kind == Boundary::Kind::Fixed ? 3 : (bc.component == 0 ? 1 : 2);
    for (auto n : boundary_nodes(bc.curves)) m.mask[n] |= bit;
  }

  // --- dashpots and tractions: face integrals ---
  std::map<int, const Boundary*> dash_of_id;
  for (const auto& bc : spec.boundaries)
    if (bc.kind == Boundary::Kind::Dashpot)
      for (int c : bc.curves) {
        if (dash_of_id.count(c))
          throw FemError("FEM: physical curve " + std::to_string(c) + " has two dashpot boundaries");
        dash_of_id[c] = &bc;
      }
  {
    const QGaussLobatto<1> ql(m.degree + 1);
    const QGauss<1> qg(m.degree + 1);
    FEFaceValues<2> fl(d.mapping, fe, ql, update_values | update_normal_vectors | update_JxW_values);
    FEFaceValues<2> fg(d.mapping, fe, qg, update_values | update_normal_vectors | update_JxW_values);
    std::map<std::uint32_t, std::array<double, 3>> cblocks, kblocks;
    std::vector<std::map<std::uint32_t, std::array<double, 2>>> loadf(spec.boundaries.size());
    // Damping layers: the boundary segments of their curves and the c_d next to them.
    std::vector<std::vector<std::array<double, 4>>> dseg(spec.boundaries.size());
    std::vector<double> dcd(spec.boundaries.size(), 0.0);
    std::vector<std::vector<PmlFace>> pml_faces(spec.boundaries.size());
    for (const auto& cell : d.dofh->active_cell_iterators()) {
      const Material& mat = spec.materials[spec.region_material.at(static_cast<int>(cell->material_id()))];
      for (const auto f : cell->face_indices()) {
        if (!cell->face(f)->at_boundary()) continue;
        const int id = static_cast<int>(cell->face(f)->boundary_id());
        for (std::size_t b = 0; b < spec.boundaries.size(); ++b) {
          const Boundary& bc = spec.boundaries[b];
          if (bc.kind == Boundary::Kind::Pml &&
              std::find(bc.curves.begin(), bc.curves.end(), id) != bc.curves.end()) {
            const auto v0 = cell->face(f)->vertex(0), v1 = cell->face(f)->vertex(1);
            const auto cc = cell->center();
            pml_faces[b].push_back({v0[0], v0[1], v1[0], v1[1], cc[0], cc[1], mat.cd, id});
          }
          if (bc.kind != Boundary::Kind::Damping) continue;
          if (std::find(bc.curves.begin(), bc.curves.end(), id) == bc.curves.end()) continue;
          const auto v0 = cell->face(f)->vertex(0), v1 = cell->face(f)->vertex(1);
          dseg[b].push_back({{v0[0], v0[1], v1[0], v1[1]}});
          dcd[b] = std::max(dcd[b], mat.cd);
        }
        auto dit = dash_of_id.find(id);
        if (dit != dash_of_id.end()) {
          const Boundary& bc = *dit->second;
          fl.reinit(cell, f);
          cell->get_dof_indices(ld);
          for (unsigned q = 0; q < ql.size(); ++q) {
            const Tensor<1, 2> n = fl.normal_vector(q);
            const double l = fl.JxW(q);
            const double ca = mat.rho * l * bc.a * mat.cd, cb = mat.rho * l * bc.b * mat.cs;
            for (unsigned i = 0; i < dpc; ++i) {
              if (fe.system_to_component_index(i).first != 0) continue;
              if (std::fabs(fl.shape_value(i, q) - 1.0) > 1e-8) continue;
              auto& c = cblocks[static_cast<std::uint32_t>(ld[i] / 2)];
              double bxx, bxy, byy;
              lk_block(ca, cb, n[0], n[1], bxx, bxy, byy);
              c[0] += bxx;
              c[1] += bxy;
              c[2] += byy;
              if (!(bc.delta > 0)) continue;
              // Kelvin-Voigt springs: the same block form with k_n and k_t.
              auto& k = kblocks[static_cast<std::uint32_t>(ld[i] / 2)];
              lk_block(mat.rho * l * bc.alpha_n * mat.cd * mat.cd / bc.delta,
                       mat.rho * l * bc.alpha_t * mat.cs * mat.cs / bc.delta, n[0], n[1], bxx, bxy,
                       byy);
              k[0] += bxx;
              k[1] += bxy;
              k[2] += byy;
            }
          }
        }
        for (std::size_t b = 0; b < spec.boundaries.size(); ++b) {
          const Boundary& bc = spec.boundaries[b];
          if (bc.kind != Boundary::Kind::Traction) continue;
          if (std::find(bc.curves.begin(), bc.curves.end(), id) == bc.curves.end()) continue;
          fg.reinit(cell, f);
          cell->get_dof_indices(ld);
          for (unsigned q = 0; q < qg.size(); ++q) {
            const Tensor<1, 2> n = fg.normal_vector(q);
            const double tx = bc.normal * n[0] - bc.tangential * n[1] + bc.vx;
            const double ty = bc.normal * n[1] + bc.tangential * n[0] + bc.vy;
            for (unsigned i = 0; i < dpc; ++i) {
              const unsigned c = fe.system_to_component_index(i).first;
              const double phi = fg.shape_value(i, q);
              if (phi == 0) continue;
              loadf[b][static_cast<std::uint32_t>(ld[i] / 2)][c] += phi * (c == 0 ? tx : ty) * fg.JxW(q);
            }
          }
        }
      }
    }
    // Damping layers: C_i += alpha(x_i) m_i I at every node within `width` of the curves, and
    // their stiffness-proportional parts beta_i (summed over the layers).
    std::map<std::uint32_t, double> betas;
    for (std::size_t b = 0; b < spec.boundaries.size(); ++b) {
      const Boundary& bc = spec.boundaries[b];
      if (bc.kind != Boundary::Kind::Damping || dseg[b].empty()) continue;
      const double a0 = -(bc.power + 1) * dcd[b] * std::log(bc.r0) / bc.width;
      for (std::size_t i = 0; i < nn; ++i) {
        double dist = std::numeric_limits<double>::infinity();
        for (const auto& sg : dseg[b]) {  // distance from node i to the segment
          const double ex = sg[2] - sg[0], ey = sg[3] - sg[1];
          const double l2 = ex * ex + ey * ey;
          double t = l2 > 0 ? ((m.x[i] - sg[0]) * ex + (m.y[i] - sg[1]) * ey) / l2 : 0.0;
          t = std::clamp(t, 0.0, 1.0);
          dist = std::min(dist, std::hypot(m.x[i] - sg[0] - t * ex, m.y[i] - sg[1] - t * ey));
        }
        if (!(dist < bc.width)) continue;
        const double ramp = std::pow(1.0 - dist / bc.width, bc.power);
        if (bc.beta > 0 && bc.beta * ramp > 0) {
          betas[static_cast<std::uint32_t>(i)] += bc.beta * ramp;
          cblocks[static_cast<std::uint32_t>(i)];  // the force enters through a block
        }
        const double alpha = a0 * ramp;
        if (alpha == 0) continue;
        auto& c = cblocks[static_cast<std::uint32_t>(i)];
        c[0] += alpha * m.mass[i];
        c[2] += alpha * m.mass[i];
      }
    }
    double beta_max = 0;
    m.visc = Impl::Viscous();
    for (const auto& [node, beta] : betas) {
      m.visc.node.push_back(node);
      m.visc.root_beta.push_back(std::sqrt(beta));
      beta_max = std::max(beta_max, beta);
    }
    // Perfectly matched layers: the cells that reach into a layer, and the nodal damping
    // m_i (d_x + d_y) in the dashpot blocks (every node of such a cell gets a block, through
    // which the layer's other forces enter).
    setup_pml(m, d, spec, pml_faces, cblocks);

    // Springs into the stiffness's diagonal blocks. With M lumped, the largest eigenvalue of
    // M^-1 (K + S) is at most that of M^-1 K plus max_i lambda_max(S_i) / m_i: the critical
    // time step shrinks accordingly.
    double lam_springs = 0;
    for (const auto& [node, k] : kblocks) {
      const std::uint32_t* b = m.col.data() + m.rowptr[node];
      const std::uint32_t* en = m.col.data() + m.rowptr[node + 1];
      const std::size_t j = std::lower_bound(b, en, node) - m.col.data();
      m.val[4 * j] += k[0];      // xx
      m.val[4 * j + 1] += k[1];  // yx
      m.val[4 * j + 2] += k[1];  // xy
      m.val[4 * j + 3] += k[2];  // yy
      const double mean = 0.5 * (k[0] + k[2]), dev = 0.5 * (k[0] - k[2]);
      lam_springs = std::max(lam_springs, (mean + std::sqrt(dev * dev + k[1] * k[1])) / m.mass[node]);
    }
    if (lam_springs > 0 && m.crit_dt > 0)
      m.crit_dt = 2.0 / std::sqrt(4.0 / (m.crit_dt * m.crit_dt) + lam_springs);
    // The stiffness-proportional damping, explicit: a mode of frequency w is damped at most as
    // by beta_max K (its Rayleigh quotient is at most beta_max w^2), and central differences with
    // the lagged velocity are stable for dt <= (2 / w)(sqrt(1 + xi^2) - xi), xi = beta w / 2.
    if (beta_max > 0 && m.crit_dt > 0) {
      const double xi = beta_max / m.crit_dt;  // w_max = 2 / crit_dt
      m.crit_dt *= std::sqrt(1 + xi * xi) - xi;
    }
    if (m.visc.active()) {
      m.visc.w.assign(2 * nn, 0.0);
      m.visc.kw.assign(2 * nn, 0.0);
      for (std::size_t r = 0; r < m.visc.node.size(); ++r) {
        m.visc.rows.push_back(static_cast<std::uint32_t>(r));
        m.visc.row_node.push_back(m.visc.node[r]);
      }
    }
    if (spec.share_rows) share_equal_rows(m);
    m.dash_of_node.assign(nn, -1);
    for (const auto& [node, c] : cblocks) {
      m.dash_of_node[node] = static_cast<std::int32_t>(m.dash.size());
      m.dash.push_back({node, c[0], c[1], c[2]});
    }
    m.dash_force.assign(2 * m.dash.size(), 0.0);
    for (std::size_t b = 0; b < spec.boundaries.size(); ++b) {
      if (spec.boundaries[b].kind != Boundary::Kind::Traction) continue;
      Impl::Load l;
      l.fn = spec.boundaries[b].fn;
      for (const auto& [node, f] : loadf[b]) {
        l.nodes.push_back(node);
        l.f.push_back(f[0]);
        l.f.push_back(f[1]);
      }
      m.loads.push_back(std::move(l));
    }
  }

  m.u.assign(ndofs, 0.0);
  m.v.assign(ndofs, 0.0);
  m.ku.assign(ndofs, 0.0);
  m.fext.assign(ndofs, 0.0);
  m.ku_valid = true;  // u = 0
}

Solver::~Solver() = default;

std::vector<std::uint32_t> partition_cells(Solver::Impl& m, unsigned parts) {
  Triangulation<2>& tria = m.deal->tria;
  try {
    GridTools::partition_triangulation(parts, tria, SparsityTools::Partitioner::metis);
  } catch (const std::exception& e) {
    throw FemError("FEM: cutting the mesh into " + std::to_string(parts) + " parts (METIS): " +
                   deal_message(e));
  }
  std::vector<std::uint32_t> out(tria.n_active_cells());
  for (const auto& cell : tria.active_cell_iterators())
    out[cell->active_cell_index()] = static_cast<std::uint32_t>(cell->subdomain_id());
  return out;
}

int Solver::add_probe(double x, double y) {
  Impl& m = *impl_;
  if (localized()) throw FemError("FEM: probes are added before the model is localized");
  Deal& d = *m.deal;
  // Outside the mesh's bounding box: not in the mesh (deal.II's search below builds its vertex
  // maps on every call; a hybrid asks for every probe, most of them in the MPM region).
  const double tol = 1e-9 * std::hypot(m.box[2] - m.box[0], m.box[3] - m.box[1]);
  if (x < m.box[0] - tol || x > m.box[2] + tol || y < m.box[1] - tol || y > m.box[3] + tol)
    return -1;
  const Point<2> p(x, y);
  using CellPoint = std::pair<DoFHandler<2>::active_cell_iterator, Point<2>>;
  std::vector<CellPoint> found;
  try {
    // Tolerance in reference coordinates: a point on an edge or a node belongs to every cell
    // that shares it.
    found = GridTools::find_all_active_cells_around_point(d.mapping, *d.dofh, p, 1e-9);
  } catch (...) {
    return -1;
  }
  if (found.empty() || found.front().first == d.dofh->end()) return -1;
  const unsigned dpc = d.fe->n_dofs_per_cell();
  std::vector<types::global_dof_index> ld(dpc);
  Impl::Probe pr;
  pr.x = x;
  pr.y = y;
  for (const auto& [cell, ref] : found) {
    const Point<2> unit = GeometryInfo<2>::project_to_unit_cell(ref);
    const Quadrature<2> q(std::vector<Point<2>>{unit}, std::vector<double>{1.0});
    FEValues<2> fv(d.mapping, *d.fe, q, update_values | update_gradients);
    fv.reinit(cell);
    cell->get_dof_indices(ld);
    Impl::ProbePart part;
    part.cell = static_cast<std::uint32_t>(cell->active_cell_index());
    for (unsigned i = 0; i < dpc; ++i) {
      part.dofs.push_back(static_cast<std::uint32_t>(ld[i]));
      part.comp.push_back(static_cast<std::uint8_t>(d.fe->system_to_component_index(i).first));
      part.N.push_back(fv.shape_value(i, 0));
      const Tensor<1, 2> g = fv.shape_grad(i, 0);
      part.dx.push_back(g[0]);
      part.dy.push_back(g[1]);
    }
    const Material& mat =
        m.spec.materials[m.spec.region_material.at(static_cast<int>(cell->material_id()))];
    part.lambda = mat.lambda;
    part.mu = mat.mu;
    pr.parts.push_back(std::move(part));
  }
  pr.w = 1.0 / static_cast<double>(pr.parts.size());
  m.probes.push_back(std::move(pr));
  return static_cast<int>(m.probes.size()) - 1;
}

std::vector<std::string> Solver::describe() const {
  const Impl& m = *impl_;
  if (!m.glob.empty()) return m.described;
  std::vector<std::string> out;
  out.push_back("FEM mesh " + m.spec.mesh.file + ": " + std::to_string(m.n_cells) + " quads, Q" +
                std::to_string(m.degree) + ", " + std::to_string(nodes()) + " nodes, " +
                std::to_string(dofs()) + " dofs, critical dt " + fmt(m.crit_dt) + " s");
  for (const auto& [tag, mi] : m.spec.region_material) {
    const PhysicalGroup* g = m.spec.mesh.surface(tag);
    out.push_back("FEM region " + std::to_string(tag) + (g ? " \"" + g->name + "\"" : std::string()) +
                  ": " + m.spec.materials[mi].name);
  }
  if (m.spec.gravity_x != 0 || m.spec.gravity_y != 0)
    out.push_back("FEM gravity (" + fmt(m.spec.gravity_x) + ", " + fmt(m.spec.gravity_y) + ") m/s^2");
  for (const auto& bc : m.spec.boundaries) {
    std::string s = "FEM boundary \"" + bc.name + "\" on curves";
    for (int c : bc.curves) s += " " + std::to_string(c);
    const std::size_t n = boundary_nodes(bc.curves).size();
    s += " (" + std::to_string(n) + " nodes): ";
    switch (bc.kind) {
      case Boundary::Kind::Dashpot:
        s += "LK dashpot a = " + fmt(bc.a) + ", b = " + fmt(bc.b);
        if (bc.delta > 0)
          s += ", Kelvin-Voigt springs alpha_n = " + fmt(bc.alpha_n) + ", alpha_t = " +
               fmt(bc.alpha_t) + ", delta = " + fmt(bc.delta) + " m";
        break;
      case Boundary::Kind::Fixed: s += "fixed"; break;
      case Boundary::Kind::Damping:
        s += "damping layer " + fmt(bc.width) + " m thick, r0 = " + fmt(bc.r0) + ", power " + fmt(bc.power);
        if (bc.beta > 0) s += ", beta " + fmt(bc.beta) + " s";
        break;
      case Boundary::Kind::Pml:
        s += "perfectly matched layer " + fmt(bc.width) + " m thick, r0 = " + fmt(bc.r0) +
             ", power " + fmt(bc.power) + ", alpha " + fmt(bc.alpha) + " 1/s";
        if (bc.parallel > 0) s += ", multi-axial share " + fmt(bc.parallel);
        break;
      case Boundary::Kind::Roller: s += std::string("roller, ") + (bc.component ? "y" : "x") + " held"; break;
      case Boundary::Kind::Traction:
        s += "traction normal " + fmt(bc.normal) + " Pa, tangential " + fmt(bc.tangential) +
             " Pa, vector (" + fmt(bc.vx) + ", " + fmt(bc.vy) + ") Pa x " + bc.fn.describe();
        break;
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace smpm::fem
