#pragma once
// Helpers shared by the physics tests: materials of docs/physics.md §2 and the 1D column.
#include <memory>

#include "silentmpm/solver.hpp"

namespace smpm::testing {

inline Material tungsten(Model model = Model::Elastic, double sigma_y = 1.0e9) {
  Material m;
  m.name = "tungsten";
  m.model = model;
  m.E = 411e9; m.nu = 0.28; m.rho = 15000; m.sigma_y = sigma_y;
  m.derive();
  return m;
}

enum class End { Free, Silent, Fixed, KelvinVoigt };

struct ColumnSpec {
  int cells = 100;          // column length in cells
  int height = 4;           // cells across (rollers on top and bottom)
  int ppc_side = 1;         // particles per cell side (1, 2, 3)
  double h = 1e-3;
  double cfl = 0.3;
  bool shear = false;       // S wave: tangential traction, rollers hold vx
  End end = End::Silent;
  SilentForm form = SilentForm::Nodal;
  Scheme scheme = Scheme::MUSL;
  double amplitude = 100e6; // traction magnitude (compressive normal, or tangential)
  TimeFunction fn;          // load history
  double offset = 0;        // shift of the column start inside its first cell (partly filled cells)
  int threads = 1;
  Anchor anchor = Anchor::Boundary;
  ShapeKind shape = ShapeKind::Bilinear;
  int cells_beyond = 4;     // grid cells beyond the column's right end
  double delta = 0;         // End::KelvinVoigt: the spring length delta (m), alpha_n = alpha_t = 1
  double gravity = 0;       // body force along +x (m/s^2), towards the right end
  int damp_cells = 0;       // a damping layer this many cells thick at the right end (r0, power 2)
  double damp_r0 = 1e-3;
  double damp_beta = 0;     // its stiffness-proportional part (s)
  int pml_cells = 0;        // a perfectly matched layer this many cells thick at the right end
  double pml_alpha = 0;
  bool updated_edge = false;  // MUSL: strain with the updated velocity at the end's dashpot nodes
  bool delayed_edge = false;  // MUSL, USF: the delayed closure at the end's dashpot nodes
  int mass_correction = 0;    // MUSL, USF: terms of the consistent-mass correction
  bool symmetric = false;     // its symmetric form (R^-1/2 on the increment and the strain)
  Seeding seeding = Seeding::Uniform;  // the particles at the sub-cells' centres or Gauss points
};

// A column [offset, offset + cells h] x [0, height h] of tungsten loaded on its left end.
inline std::unique_ptr<Solver> make_column(const ColumnSpec& c) {
  auto s = std::make_unique<Solver>();
  s->materials.push_back(tungsten());
  const double L = c.cells * c.h;
  s->grid.init(-2 * c.h, 0.0, c.h, c.cells + 2 + c.cells_beyond, c.height);
  s->seed_rectangle(c.offset, 0, c.offset + L, c.height * c.h, c.ppc_side, 0, 0, 0, 0, c.seeding);
  const double top = c.height * c.h;
  const uint8_t mask = c.shear ? 1 : 2;
  s->constraints.push_back({"bottom", s->nodes_in_box(-1, 0, 1, 0), mask});
  s->constraints.push_back({"top", s->nodes_in_box(-1, top, 1, top), mask});
  TractionLoad tl;
  tl.layer = s->select_layer("left", 0, c.offset, top, c.offset, 0, -1, 0, c.h);
  if (c.shear) tl.tangential = c.amplitude; else tl.normal = -c.amplitude;
  tl.fn = c.fn;
  tl.anchor = c.anchor;
  s->tractions.push_back(tl);
  if (c.end == End::Silent || c.end == End::KelvinVoigt) {
    SilentBoundary sb;
    if (c.end == End::KelvinVoigt) sb.delta = c.delta;
    sb.layer = s->select_layer("right", 0, c.offset + L, 0, c.offset + L, top, 1, 0, c.h);
    sb.form = c.form;
    sb.anchor = c.anchor;
    sb.updated_velocity = c.updated_edge;
    sb.delayed = c.delayed_edge;
    s->silents.push_back(sb);
  } else if (c.end == End::Fixed) {
    const double xr = c.offset + L;
    s->constraints.push_back({"right", s->nodes_in_box(xr - 1e-9, 0, xr + 1e-9, top), 3});
  }
  if (c.damp_cells > 0) {
    DampingLayer dl;
    dl.layer = s->select_layer("damping", 0, c.offset + L, 0, c.offset + L, top, 1, 0,
                               c.damp_cells * c.h);
    dl.r0 = c.damp_r0;
    dl.beta0 = c.damp_beta;
    s->dampers.push_back(dl);
  }
  if (c.pml_cells > 0) {
    PmlBand band;
    band.name = "pml";
    band.body = 0;
    band.axis = 0;
    band.side = 1;
    band.c = c.offset + L;
    band.width = c.pml_cells * c.h;
    band.alpha = c.pml_alpha;
    s->pml_bands.push_back(band);
  }
  s->opt.scheme = c.scheme;
  s->opt.shape = c.shape;
  s->opt.threads = c.threads;
  s->opt.gravity_x = c.gravity;
  s->opt.mass_correction = c.mass_correction;
  s->opt.mass_correction_symmetric = c.symmetric;
  s->dt = c.cfl * c.h / s->materials[0].cd;
  s->finalize();
  return s;
}

inline TimeFunction sin2_pulse(double duration, double ramp) {
  TimeFunction f;
  f.kind = TimeFunction::Kind::Sin2Pulse;
  f.duration = duration;
  f.ramp = ramp;
  return f;
}

}  // namespace smpm::testing
