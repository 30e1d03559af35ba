// The MPM step over MPI ranks (slabs; parallel/) against the same case on one process. Run by
// CTest on 1, 2 and 4 ranks: every rank builds the serial solver too and compares with it.
//   * 1 rank: bit-identical to the serial solver.
//   * 2 and 4 ranks: per-particle fields by id within 1e-12 of each field's maximum, energies
//     within 1e-12 of the largest term (a node on a rank border sums its parts in another
//     order); two runs bit-identical; the nodal mass on the ranks' own nodes equals the
//     particles' mass to 1e-14; particles crossing borders keep their ids and count, and their
//     boundary-layer entries.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "mpi_testing.hpp"
#include "silentmpm/distributed.hpp"
#include "silentmpm/solver.hpp"

namespace smpm::testing {
namespace {

int ranks() { return mpi_testing::world_size(); }

// The layouts every test runs: slabs of rows (1 across), columns (every rank across), and on
// 4 ranks 2 x 2 blocks.
std::vector<int> layouts() {
  const int P = ranks();
  if (P == 1) return {1};
  if (P == 4) return {1, 2, 4};
  return {1, P};
}
std::string layout_name(int across) {
  const int P = ranks();
  return across == 1 ? "slabs" : across == P ? "columns" : std::to_string(across) + " x " +
                                                               std::to_string(P / across);
}

struct PlateSpec {
  int nx = 24, ny = 40;        // plate cells
  int ppc = 2;
  Scheme scheme = Scheme::MUSL;
  ShapeKind shape = ShapeKind::Bilinear;
  double vy0 = 0;              // initial upward velocity of the whole plate (m/s)
  double spin = 0;             // initial rigid rotation about the plate's centre (rad/s)
  bool springs = true;         // Kelvin-Voigt springs on the bottom layer
  double lk = 1;               // the LK coefficients a = b of the silent layers
  double spring_alpha = 1;     // alpha_n = alpha_t of the springs
  // Instead: a damping band on the left edge, a PML band on the bottom, the right edge's LK in
  // the particle form, and gravity.
  bool other_layers = false;
  bool updated = false;        // MUSL, USF: the LK edges strained with the updated velocity
  bool delayed = false;        // MUSL, USF: the LK edges with the delayed closure (1 ppc)
  bool skeleton = false;       // the case without its particles (Solver::seed_nothing)
  int mass_correction = 0;     // MUSL, USF: terms of the consistent-mass correction
};

// A tungsten plate on a grid with margins: a sin^2 pressure pulse on its top edge, LK silent
// layers on its left and right edges (every slab border crosses them) and a silent layer with
// Kelvin-Voigt springs on its bottom edge.
std::unique_ptr<Solver> make_plate(const PlateSpec& c) {
  const double h = 1e-3;
  auto s = std::make_unique<Solver>();
  s->materials.push_back(tungsten());
  s->grid.init(-3 * h, -3 * h, h, c.nx + 6, c.ny + 6);
  const double W = c.nx * h, H = c.ny * h;
  s->seed_nothing = c.skeleton;
  s->seed_rectangle(0, 0, W, H, c.ppc, 0, 0, 0, c.vy0);
  if (c.spin != 0)
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      s->p.vx[k] = -c.spin * (s->p.y[k] - 0.5 * H);
      s->p.vy[k] = c.vy0 + c.spin * (s->p.x[k] - 0.5 * W);
    }
  TractionLoad tl;
  tl.layer = s->select_layer("top", 0, W, H, 0, H, 0, 1, h);
  tl.normal = -100e6;
  const double dur = 16 * h / s->materials[0].cd;
  tl.fn = sin2_pulse(dur, 0.5 * dur);
  s->tractions.push_back(tl);
  if (c.other_layers) {
    DampingLayer dl;
    dl.layer = s->select_layer("band", 0, 0, H, 0, 0, -1, 0, 5 * h);
    dl.beta0 = 0.3 * h / s->materials[0].cd;  // a stiffness-proportional part too
    s->dampers.push_back(dl);
    PmlBand band;
    band.name = "pml";
    band.body = 0;
    band.axis = 1;
    band.side = -1;
    band.c = 0;
    band.width = 5 * h;
    s->pml_bands.push_back(band);
    SilentBoundary sb;
    sb.form = SilentForm::Particle;
    sb.layer = s->select_layer("right", 0, W, 0, W, H, 1, 0, h);
    s->silents.push_back(sb);
    s->opt.gravity_y = -1e5;
  }
  for (int side = 0; side < 2 && !c.other_layers; ++side) {
    SilentBoundary sb;
    sb.a = sb.b = c.lk;
    const double x = side ? W : 0;
    sb.layer = s->select_layer(side ? "right" : "left", 0, x, side ? 0 : H, x, side ? H : 0,
                               side ? 1 : -1, 0, h);
    sb.updated_velocity = c.updated;
    sb.delayed = c.delayed;
    s->silents.push_back(sb);
  }
  SilentBoundary kv;
  kv.a = kv.b = c.lk;
  kv.alpha_n = kv.alpha_t = c.spring_alpha;
  kv.layer = s->select_layer("bottom", 0, 0, 0, W, 0, 0, -1, h);
  kv.updated_velocity = c.updated;
  kv.delayed = c.delayed && !c.springs;
  if (c.springs) kv.delta = 10 * h;
  if (!c.other_layers) s->silents.push_back(kv);
  s->opt.scheme = c.scheme;
  s->opt.shape = c.shape;
  s->opt.mass_correction = c.mass_correction;
  s->opt.threads = 1;
  s->dt = 0.3 * h / s->materials[0].cd;
  s->finalize();
  return s;
}

// Every rank's particles, by id, on every rank.
struct Fields {
  std::vector<std::array<double, 8>> v;  // x, y, vx, vy, sxx, syy, sxy, vol
};
Fields gather(const Solver& s) {
  std::vector<double> mine;
  for (std::size_t k = 0; k < s.p.size(); ++k)
    for (double f : {static_cast<double>(s.p.id[k]), s.p.x[k], s.p.y[k], s.p.vx[k], s.p.vy[k],
                     s.p.sxx[k], s.p.syy[k], s.p.sxy[k], s.p.vol[k]})
      mine.push_back(f);
  const int P = ranks();
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(P), disp(P);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  int total = 0;
  for (int r = 0; r < P; ++r) disp[r] = total, total += counts[r];
  std::vector<double> all(total);
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), disp.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  Fields f;
  f.v.assign(all.size() / 9, {});
  std::vector<int> seen(f.v.size(), 0);
  for (std::size_t r = 0; r + 8 < all.size(); r += 9) {
    const auto id = static_cast<std::size_t>(all[r]);
    EXPECT_LT(id, f.v.size()) << "a particle id outside 0 .. n - 1";
    if (id >= f.v.size()) continue;
    ++seen[id];
    for (int q = 0; q < 8; ++q) f.v[id][q] = all[r + 1 + q];
  }
  for (std::size_t id = 0; id < seen.size(); ++id)
    EXPECT_EQ(seen[id], 1) << "particle " << id << " held by " << seen[id] << " ranks";
  return f;
}
Fields gather_serial(const Solver& s) {
  Fields f;
  f.v.assign(s.p.size(), {});
  for (std::size_t k = 0; k < s.p.size(); ++k)
    f.v[s.p.id[k]] = {s.p.x[k], s.p.y[k], s.p.vx[k], s.p.vy[k], s.p.sxx[k], s.p.syy[k],
                      s.p.sxy[k], s.p.vol[k]};
  return f;
}

// max |a - b| over particles, per field, over max |b|.
std::array<double, 8> differences(const Fields& a, const Fields& b) {
  std::array<double, 8> d{}, m{};
  for (std::size_t k = 0; k < b.v.size(); ++k)
    for (int q = 0; q < 8; ++q) {
      d[q] = std::max(d[q], std::abs(a.v[k][q] - b.v[k][q]));
      m[q] = std::max(m[q], std::abs(b.v[k][q]));
    }
  for (int q = 0; q < 8; ++q) d[q] = m[q] > 0 ? d[q] / m[q] : d[q];
  return d;
}

double energy_difference(const Energies& a, const Energies& b) {
  const double ta[] = {a.kinetic, a.elastic, a.dissipated, a.absorbed, a.external_work, a.initial};
  const double tb[] = {b.kinetic, b.elastic, b.dissipated, b.absorbed, b.external_work, b.initial};
  double d = 0, m = 0;
  for (int q = 0; q < 6; ++q) {
    d = std::max(d, std::abs(ta[q] - tb[q]));
    m = std::max(m, std::abs(tb[q]));
  }
  return d / m;
}

std::size_t layer_entries(const Solver& s) {
  std::size_t n = 0;
  for (const auto& t : s.tractions) n += t.layer.ids.size();
  for (const auto& t : s.silents) n += t.layer.ids.size();
  return n;
}

struct Outcome {
  Fields f;
  Energies e;
  long sent = 0;
  std::size_t entries = 0;
};

Outcome run_distributed(const PlateSpec& c, int steps, int across) {
  auto s = make_plate(c);
  Distributed d(*s, MPI_COMM_WORLD, across);
  for (int n = 0; n < steps; ++n) s->step();
  s->update_energies();
  Outcome r;
  r.f = gather(*s);
  r.e = s->total_energy();
  long sent = d.sent();
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  r.sent = sent;
  unsigned long e = layer_entries(*s);
  MPI_Allreduce(MPI_IN_PLACE, &e, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
  r.entries = e;
  return r;
}

Outcome run_serial(const PlateSpec& c, int steps) {
  auto s = make_plate(c);
  for (int n = 0; n < steps; ++n) s->step();
  s->update_energies();
  return {gather_serial(*s), s->energy, 0, layer_entries(*s)};
}

void expect_agreement(const Outcome& d, const Outcome& s, const std::string& what,
                      double bound = 1e-12) {
  const auto diff = differences(d.f, s.f);
  const double de = energy_difference(d.e, s.e);
  if (ranks() == 1) {  // the same operations in the same order
    for (int q = 0; q < 8; ++q) EXPECT_EQ(diff[q], 0.0) << what << ": field " << q;
    EXPECT_EQ(de, 0.0) << what << ": energies";
    return;
  }
  for (int q = 0; q < 8; ++q) EXPECT_LE(diff[q], bound) << what << ": field " << q;
  EXPECT_LE(de, bound) << what << ": energies";
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("%s on %d ranks: fields within %.1e of their maxima, energies within %.1e\n",
                what.c_str(), ranks(), *std::max_element(diff.begin(), diff.end()), de);
}

// `steps` steps of the plate `c` on one process and on every layout of the ranks: fields and
// energies agree (expect_agreement); returns the one process's outcome.
Outcome expect_layouts_agree(const PlateSpec& c, int steps, const std::string& what) {
  const Outcome s = run_serial(c, steps);
  for (int a : layouts()) expect_agreement(run_distributed(c, steps, a), s, what + ", " + layout_name(a));
  return s;
}

// The pulse crosses the slab borders and reaches the silent layers; every scheme.
TEST(Ranks, PulsePlateAgreesWithOneProcessEveryScheme) {
  for (Scheme sc : {Scheme::MUSL, Scheme::USL, Scheme::USF}) {
    PlateSpec c;
    c.scheme = sc;
    const Outcome s = expect_layouts_agree(c, 200, scheme_name(sc));
    EXPECT_GT(s.e.absorbed, 0.01 * s.e.external_work) << "the pulse reached the silent layers";
  }
  // MUSL and USF with the updated velocity at the layers' dashpot nodes: which nodes take it
  // depends on the impedance summed over the halo (USF: the last step's, kept per node).
  for (Scheme sc : {Scheme::MUSL, Scheme::USF}) {
    PlateSpec c;
    c.scheme = sc;
    c.updated = true;
    expect_layouts_agree(c, 200, std::string(scheme_name(sc)) + ", updated edges");
  }
  // The delayed closure at 1 ppc: each edge node's ring of start velocities and forces, kept by
  // every rank that holds the node (from the sums over the halo), and its delay from the
  // impedance and weight summed over the halo.
  for (Scheme sc : {Scheme::MUSL, Scheme::USF}) {
    PlateSpec c;
    c.scheme = sc;
    c.ppc = 1;
    c.springs = false;
    c.delayed = true;
    const Outcome s = expect_layouts_agree(c, 200, std::string(scheme_name(sc)) + ", delayed edges");
    EXPECT_GT(s.e.absorbed, 0.01 * s.e.external_work) << "the pulse reached the silent layers";
  }
}

// The consistent-mass correction: each term's product summed over the halo before the nodes
// divide it by their mass (two terms, the LK and Kelvin-Voigt edges, MUSL, USF and USL).
TEST(Ranks, MassCorrectionAgreesWithOneProcess) {
  for (Scheme sc : {Scheme::MUSL, Scheme::USF, Scheme::USL}) {
    PlateSpec c;
    c.scheme = sc;
    c.mass_correction = 2;
    const Outcome s = expect_layouts_agree(c, 200, std::string(scheme_name(sc)) + ", mass correction");
    EXPECT_GT(s.e.absorbed, 0.01 * s.e.external_work) << "the pulse reached the silent layers";
  }
}

// The correction's symmetric form runs on one process (its probes read the corrected nodal
// velocity of one window): refused before the ranks split the grid.
// The ranks' set-up refuses solver s with an error that names `what`.
void expect_ranks_refuse(Solver& s, const std::string& what) {
  try {
    Distributed d(s, MPI_COMM_WORLD, 1);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(Ranks, SymmetricMassCorrectionIsRefused) {
  PlateSpec c;
  c.mass_correction = 1;
  auto s = make_plate(c);
  s->opt.mass_correction_symmetric = true;
  expect_ranks_refuse(*s, "\"symmetric\" runs on one process");
}

// The light nodes' extension runs on one process (a light node and the nodes it reads may lie
// in two windows): refused before the ranks split the grid.
TEST(Ranks, LightNodesAreRefused) {
  PlateSpec c;
  auto s = make_plate(c);
  s->opt.light_node_ratio = 0.15;
  expect_ranks_refuse(*s, "\"extend\" runs on one process");
}

TEST(Ranks, WiderStencilsAgreeWithOneProcess) {
  for (ShapeKind sh : {ShapeKind::UGimp, ShapeKind::BSpline2}) {
    PlateSpec c;
    c.shape = sh;
    expect_layouts_agree(c, 150, sh == ShapeKind::UGimp ? "GIMP" : "B-spline");
  }
}

// A damping band and a PML band (every border crosses the band; the PML lies in the lowest
// slab), LK in the particle form, gravity.
TEST(Ranks, BandPmlAndGravityAgreeWithOneProcess) {
  for (Scheme sc : {Scheme::USL, Scheme::MUSL}) {
    PlateSpec c;
    c.other_layers = true;
    c.scheme = sc;
    expect_layouts_agree(c, 200, std::string("band, PML, gravity, ") + scheme_name(sc));
  }
}

// Two runs on the same ranks: the same bits (the halo sums in a fixed order).
TEST(Ranks, TwoRunsBitIdentical) {
  PlateSpec c;
  for (int l : layouts()) {
    const Outcome a = run_distributed(c, 120, l), b = run_distributed(c, 120, l);
    const auto diff = differences(a.f, b.f);
    for (int q = 0; q < 8; ++q) EXPECT_EQ(diff[q], 0.0) << layout_name(l) << ", field " << q;
    EXPECT_EQ(energy_difference(a.e, b.e), 0.0) << layout_name(l);
  }
}

// After a step the grid holds the particles' mass: summed over each rank's own nodes, the nodal
// mass is the particles' mass (partition of unity) to round-off.
TEST(Ranks, NodalMassEqualsParticleMass) {
  for (int l : layouts()) {
  PlateSpec c;
  auto s = make_plate(c);
  const int nnx = s->grid.nnx, nny = s->grid.nny;
  Distributed d(*s, MPI_COMM_WORLD, l);
  for (int n = 0; n < 5; ++n) s->step();
  // This rank's nodes in its window: its block's cells' lower-left nodes, and the grid's last
  // column and row where the block ends there.
  const int a = d.rank() % d.across(), b = d.rank() / d.across();
  const int i0 = d.columns()[a] - d.window_column0(), j0 = d.rows()[b] - d.window_row0();
  const int i1 = (a + 2 == static_cast<int>(d.columns().size()) ? nnx : d.columns()[a + 1]) -
                 d.window_column0();
  const int j1 = (b + 2 == static_cast<int>(d.rows().size()) ? nny : d.rows()[b + 1]) -
                 d.window_row0();
  // Sums in extended precision: a plain sum of 10^3-10^4 terms alone errs by 1e-14.
  long double nodal = 0, particles = 0;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) nodal += s->grid.m[static_cast<long>(j) * s->grid.nnx + i];
  for (double m : s->p.mass) particles += m;
  double v[2] = {static_cast<double>(nodal), static_cast<double>(particles)};
  MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_NEAR(v[0], v[1], 1e-14 * v[1]) << layout_name(l);
  }
}

// A spinning plate: particles cross the borders every step, with their layer entries (the
// traction's, and the silent layers' with their springs' displacements); nothing is lost or
// doubled. The silent layers are weak (a hundredth of LK, springs 1e-4 of the usual) so that
// they do not stop the rotation.
TEST(Ranks, MigrationKeepsIdsCountsAndLayers) {
  PlateSpec c;
  c.nx = 20;
  c.ny = 20;
  c.spin = 2e4;  // the plate's edges at 200 m/s: 0.012 cells per step (c_d 5.2 km/s, dt 58 ns)
  c.lk = 0.01;
  c.spring_alpha = 1e-4;
  for (Scheme sc : {Scheme::MUSL, Scheme::USF}) {
    c.scheme = sc;
    const Outcome s = run_serial(c, 300);
    for (int a : layouts()) {
      const Outcome d = run_distributed(c, 300, a);
      const std::string what = std::string("migration, ") + scheme_name(sc) + ", " + layout_name(a);
      expect_agreement(d, s, what);
      EXPECT_EQ(d.entries, s.entries);
      if (ranks() > 1) {
        EXPECT_GT(d.sent, 50) << what << ": particles crossed the borders";
        int rank = 0;
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        if (rank == 0) std::printf("%s: %ld particles moved between ranks\n", what.c_str(), d.sent);
      }
    }
  }
}

// Multi-field contact with friction: a block thrown down and sideways onto a plate; the
// contact nodes lie on and across the borders (their bodies' fields are summed over the halo,
// their impulses counted by the nodes' owners). Against one process within 1e-10 (fields and
// energies), and the contact force on the block (a region probe of body 1) within 1e-10 of its
// largest value. The bound is wider than the plate's: at a contact node the lighter body often
// holds a sliver of mass, whose velocity p / m magnifies the order of the additions; measured
// (fields) up to 1.6e-13 under MUSL, 2.1e-13 under USF and 9e-15 under USL, with two terms of
// the mass correction 9.5e-13 under MUSL and 9e-15 under USL.
// `shared`: both bodies of material 0, so that the contact set-up splits its group by body;
// `skeleton`: the case without its particles (set-up from rank 0).
std::unique_ptr<Solver> make_contact(Scheme sc, bool shared = false, bool skeleton = false,
                                     int mass_correction = 0) {
  const double h = 1e-3;
  auto s = std::make_unique<Solver>();
  s->materials.push_back(tungsten());
  s->materials.push_back(tungsten());
  s->seed_nothing = skeleton;
  s->grid.init(-3 * h, -3 * h, h, 36, 36);
  s->seed_rectangle(0, 0, 30 * h, 12 * h, 2, 0, 0, 0, 0);
  s->seed_rectangle(8 * h, 12.25 * h, 22 * h, 26 * h, 2, shared ? 0 : 1, 1, 20, -100);
  s->contact.type = ContactType::Multi;
  s->contact.friction = 0.3;
  s->opt.scheme = sc;
  s->opt.mass_correction = mass_correction;
  s->opt.threads = 1;
  s->dt = 0.3 * h / s->materials[0].cd;
  s->finalize();
  return s;
}

// Steps of the contact runs: under USL 120, as this 100 m/s impact at 4 ppc goes unstable there
// from about step 160 (with and without the mass correction) (USL strains the particles with the updated velocity of the nodes that
// hold a sliver of mass at the free surfaces; the contact's gap check engages a quarter of a
// cell earlier than before it took the particles' reach into account, which moved that from
// step 255).
int contact_steps(Scheme sc) { return sc == Scheme::USL ? 120 : 250; }

// Also with two terms of the mass correction on each body's field (MUSL, USL).
TEST(Ranks, MultiFieldContactAgreesWithOneProcess) {
  const std::pair<Scheme, int> runs[] = {{Scheme::MUSL, 0}, {Scheme::USL, 0}, {Scheme::USF, 0},
                                         {Scheme::MUSL, 2}, {Scheme::USL, 2}};
  for (const auto& [sc, mc] : runs) {
    const int steps = contact_steps(sc);
    auto ref = make_contact(sc, false, false, mc);
    double fmax = 0;
    std::vector<std::array<double, 2>> fs;
    for (int n = 0; n < steps; ++n) {
      ref->step();
      const ProbeSample q = ref->region_mean(-1, -1, 1, 1, 1);
      fs.push_back({q.fcx, q.fcy});
      fmax = std::max({fmax, std::abs(q.fcx), std::abs(q.fcy)});
    }
    ref->update_energies();
    const Outcome s{gather_serial(*ref), ref->energy, 0, 0};
    EXPECT_GT(fmax, 0) << "the bodies met";
    for (int a : layouts()) {
      auto d = make_contact(sc, false, false, mc);
      Distributed dist(*d, MPI_COMM_WORLD, a);
      double df = 0;
      for (int n = 0; n < steps; ++n) {
        d->step();
        const ProbeSample q = d->region_mean(-1, -1, 1, 1, 1);
        df = std::max({df, std::abs(q.fcx - fs[n][0]), std::abs(q.fcy - fs[n][1])});
      }
      d->update_energies();
      const Outcome o{gather(*d), d->total_energy(), 0, 0};
      const std::string what = std::string("contact, ") + scheme_name(sc) + ", mass correction " +
                               std::to_string(mc) + ", " + layout_name(a);
      expect_agreement(o, s, what, 1e-10);
      EXPECT_LE(df, 1e-10 * fmax) << what << ": contact force";
    }
  }
}

// The particles of `a` whose every array (position, velocity, mass, volume, stress, group,
// body) equals, bit for bit, that of the particle of `b` with the same id.
long same_by_id(const Particles& a, const Particles& b) {
  std::map<std::uint32_t, std::size_t> at;
  for (std::size_t q = 0; q < b.size(); ++q) at[b.id[q]] = q;
  long same = 0;
  for (std::size_t q = 0; q < a.size(); ++q) {
    const auto it = at.find(a.id[q]);
    if (it == at.end()) continue;
    const std::size_t r = it->second;
    same += a.x[q] == b.x[r] && a.y[q] == b.y[r] && a.vx[q] == b.vx[r] && a.vy[q] == b.vy[r] &&
            a.mass[q] == b.mass[r] && a.vol[q] == b.vol[r] && a.sxx[q] == b.sxx[r] &&
            a.group[q] == b.group[r] && a.body[q] == b.body[r];
  }
  return same;
}

// Set-up from rank 0 (docs/parallel.md "Set-up"): rank 0 builds the whole plate, the others its
// skeleton, and the split sends each rank its block. Each rank then holds what the split of the
// plate built whole on every rank gives it: the same particles, every array bit for bit by id,
// and the same layer entries with every per-entry value (normals, widths, impedances, springs,
// band and PML coefficients), in the same order: 200 steps on, the two are bit-identical.
TEST(Ranks, SetUpFromRankZeroAsTheWholeCaseSplit) {
  for (const bool other : {false, true})
    for (int l : layouts()) {
      PlateSpec c;
      c.other_layers = other;
      c.scheme = other ? Scheme::USL : Scheme::MUSL;
      auto whole = make_plate(c);
      Distributed dw(*whole, MPI_COMM_WORLD, l);
      PlateSpec k = c;
      k.skeleton = mpi_testing::world_rank() != 0;
      auto sent = make_plate(k);
      Distributed ds(*sent, MPI_COMM_WORLD, l, true);
      const std::string what = std::string(other ? "band, PML, particle LK" : "LK, springs") +
                               ", " + layout_name(l);
      ASSERT_EQ(sent->p.size(), whole->p.size()) << what;
      EXPECT_EQ(same_by_id(whole->p, sent->p), static_cast<long>(whole->p.size())) << what;
      // Every layer entry by its particle's id, with its values.
      auto entries = [](const Solver& s) {
        std::map<std::pair<int, std::uint32_t>, std::vector<double>> e;
        int n = 0;
        auto put = [&](const BoundaryLayer& L, std::initializer_list<const std::vector<double>*> v) {
          for (std::size_t q = 0; q < L.ids.size(); ++q) {
            std::vector<double>& row = e[{n, L.ids[q]}];
            row = {L.nx[q], L.ny[q], L.d[q], L.w[q]};
            for (const auto* a : v) row.push_back(a->empty() ? 0.0 : (*a)[q]);
          }
          ++n;
        };
        for (const auto& t : s.tractions) put(t.layer, {});
        for (const auto& l : s.silents) put(l.layer, {&l.zn, &l.zt, &l.kn, &l.kt, &l.ux, &l.uy});
        for (const auto& d : s.dampers) put(d.layer, {&d.alpha, &d.beta});
        for (std::size_t q = 0; q < s.pml.layer.ids.size(); ++q)
          e[{n, s.pml.layer.ids[q]}] = {s.pml.dx[q], s.pml.dy[q], s.pml.pic[q]};
        return e;
      };
      const auto ew = entries(*whole), es = entries(*sent);
      EXPECT_EQ(es.size(), ew.size()) << what;
      EXPECT_TRUE(es == ew) << what << ": layer entries";
      EXPECT_EQ(sent->dt, whole->dt) << what;
      EXPECT_EQ(sent->critical_dt(), whole->critical_dt()) << what;
      // On: both as one process.
      for (int n = 0; n < 200; ++n) {
        whole->step();
        sent->step();
      }
      whole->update_energies();
      sent->update_energies();
      const Outcome a{gather(*whole), whole->total_energy(), 0, 0};
      const Outcome b{gather(*sent), sent->total_energy(), 0, 0};
      expect_agreement(b, a, "set-up from rank 0 against the split whole case, " + what, 0.0);
    }
}

// Set-up from rank 0 with multi-field contact: rank 0's contact set-up splits the material
// group both bodies share (one group per body); the other ranks, which built the case without
// its particles, take that split with their particles. Each rank then holds the material groups
// and the particles of the whole case split, every array bit for bit by id, and 250 steps (USL:
// 120) on the fields, the energies and the contact force on the block are the same bits.
TEST(Ranks, SetUpFromRankZeroWithMultiFieldContact) {
  for (Scheme sc : {Scheme::MUSL, Scheme::USL})
    for (int l : layouts()) {
      auto whole = make_contact(sc, true);
      Distributed dw(*whole, MPI_COMM_WORLD, l);
      auto sent = make_contact(sc, true, mpi_testing::world_rank() != 0);
      Distributed ds(*sent, MPI_COMM_WORLD, l, true);
      const std::string what = std::string("contact, ") + scheme_name(sc) + ", " + layout_name(l);
      ASSERT_EQ(whole->materials.size(), 3u) << what << ": the shared group split by body";
      ASSERT_EQ(sent->materials.size(), whole->materials.size()) << what;
      ASSERT_EQ(sent->p.size(), whole->p.size()) << what;
      EXPECT_EQ(same_by_id(whole->p, sent->p), static_cast<long>(whole->p.size())) << what;
      double fmax = 0, df = 0;
      for (int n = 0; n < contact_steps(sc); ++n) {
        whole->step();
        sent->step();
        const ProbeSample a = whole->region_mean(-1, -1, 1, 1, 1);
        const ProbeSample b = sent->region_mean(-1, -1, 1, 1, 1);
        fmax = std::max({fmax, std::abs(a.fcx), std::abs(a.fcy)});
        df = std::max({df, std::abs(a.fcx - b.fcx), std::abs(a.fcy - b.fcy)});
      }
      EXPECT_GT(fmax, 0) << what << ": the bodies met";
      EXPECT_EQ(df, 0.0) << what << ": contact force";
      whole->update_energies();
      sent->update_energies();
      const Outcome a{gather(*whole), whole->total_energy(), 0, 0};
      const Outcome b{gather(*sent), sent->total_energy(), 0, 0};
      expect_agreement(b, a, "set-up from rank 0 against the split whole case, " + what, 0.0);
    }
}

TEST(Ranks, TooManyRanksForTheGridIsAnError) {
  if (ranks() == 1) GTEST_SKIP() << "one rank takes any grid";
  PlateSpec c;
  c.ny = 2 * ranks() - 7;  // the grid has ny + 6 rows: one fewer than 2 per rank
  c.ny = std::max(c.ny, 1);
  auto s = make_plate(c);
  if (s->grid.ny >= 2 * ranks()) GTEST_SKIP() << "the plate's margins alone are enough rows";
  try {
    Distributed d(*s, MPI_COMM_WORLD, 1);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("need a grid of at least"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace smpm::testing

int main(int argc, char** argv) {
  smpm::parallel_init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {  // one report: rank 0's (every rank checks the same gathered values)
    auto& l = ::testing::UnitTest::GetInstance()->listeners();
    delete l.Release(l.default_result_printer());
  }
  int failed = RUN_ALL_TESTS();
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  smpm::parallel_finalize();
  return failed;
}
