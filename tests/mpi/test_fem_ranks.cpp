// The FE far field split over MPI ranks (fem::Solver::distribute; docs/parallel.md, "The FE far
// field") against the same model on one process, which every rank builds beside it. Run by
// CTest on 1, 2 and 4 ranks.
//   * K u on each rank's own rows equals the one-process K u (bound 1e-14 of max |K u|; a row
//     is summed in the same order, so measured 0), Q1 and Q2; the ranks' own nodes cover the
//     mesh once.
//   * A square with every FE boundary (a traction pulse, PMLs on two sides meeting in a corner
//     with dashpots behind them, a damping band with a stiffness-proportional part in front of
//     Kelvin-Voigt springs, gravity), 300
//     steps: u and v on the own nodes as on one process (bound 1e-14 of their maxima; measured
//     0), the probes within 1e-14 of their maxima, each energy term within 1e-14 of the largest
//     and the balance kinetic + elastic + absorbed - work within 1e-14 of it.
//   * The same square's checkpoint written by the ranks at once (each its own nodes and layer
//     cells) restarts the model on one process: 100 steps on, u and v on every node within
//     1e-14 of the uninterrupted one-process run's maxima (measured 0), energies within 1e-14;
//     a node list naming a node twice is refused.
//   * Each rank keeping only what it steps (fem::Solver::localize), against the same model split
//     whole, the square with every boundary and one without its PMLs and stiffness-proportional
//     band, Q1 and Q2, 300 steps: the probes, the energies and u, v gathered on rank 0 bit for
//     bit (bound 0), and the checkpoint the ranks write at once the same file byte for byte; the
//     largest rank holds at most 3/4 of the nodes on 2 ranks, 1/2 on 4;
//     localize() before distribute() and a probe added after it are refused.
//   * The far field set up from rank 0 (distribute_from_root, the other ranks skeletons): a
//     failure while rank 0 builds the last rank's part, or the last rank finding no room for
//     it, stops every rank with an error (none hangs), rank 0's reason on rank 0; a set-up without
//     fault then steps as the whole split model (energies bit for bit).
//   * The oblique study's measurement, P at 30 degrees on a 10-cell PML and on LK: the
//     reflection coefficients as on one process (1e-12 relative), on 2 ranks.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "../../studies/oblique/oblique.hpp"
#include "fem_common.hpp"
#include "mpi_testing.hpp"
#include "silentmpm/state_io.hpp"
#include "silentmpm/state_write.hpp"

namespace smpm::fem_testing {
namespace {

using mpi_testing::max_over_ranks;
using mpi_testing::world_size;
bool root() { return mpi_testing::world_rank() == 0; }

// A 40 x 40-cell steel square (1 mm cells) with every kind of FE boundary, or a plain one.
fem::Spec square(int degree, bool boundaries) {
  fem::Spec s = steel_rectangle("ranks_square", 40, 40, degree);
  const double h = 1e-3;
  if (!boundaries) return s;
  s.gravity_y = -2000;
  fem::Boundary top = bc(fem::Boundary::Kind::Traction, 14, "pulse");
  top.normal = -1e8;
  top.tangential = 3e7;
  top.fn = sin2_bell(4e-6);
  s.boundaries.push_back(top);
  for (const int curve : {12, 13}) {
    fem::Boundary p = bc(fem::Boundary::Kind::Pml, curve, "pml");
    p.width = 10 * h;
    p.r0 = 1e-2;
    s.boundaries.push_back(p);
    s.boundaries.push_back(bc(fem::Boundary::Kind::Dashpot, curve, "lk"));
  }
  fem::Boundary band = bc(fem::Boundary::Kind::Damping, 11, "band");
  band.width = 8 * h;
  band.r0 = 0.1;
  band.beta = 0.2 * h / 5900;  // a stiffness-proportional part too
  s.boundaries.push_back(band);
  fem::Boundary kv = bc(fem::Boundary::Kind::Dashpot, 11, "kv");
  kv.delta = 40 * h;
  s.boundaries.push_back(kv);
  return s;
}

// The square without its PMLs and the band's stiffness part: a traction pulse on the top, LK
// dashpots on the right and the bottom, a mass-proportional band in front of Kelvin-Voigt springs
// on the left, gravity.
fem::Spec square_local(int degree) {
  fem::Spec s = square(degree, true);
  std::vector<fem::Boundary> keep;
  for (fem::Boundary b : s.boundaries) {
    if (b.kind == fem::Boundary::Kind::Pml) continue;
    b.beta = 0;
    keep.push_back(b);
  }
  s.boundaries = keep;
  return s;
}

// The mesh is read on rank 0 only: the other ranks ask for a file that does not exist and
// receive rank 0's mesh, the same text on every rank; a file rank 0 cannot read is every rank's
// error, with rank 0's message.
TEST(FemRanks, MeshReadOnRankZeroOnly) {
  const bool zero = mpi_testing::world_rank() == 0;
  const std::string good = rectangle_geo("ranks_mesh_zero", 0.01, 0.005, 1e-3);
  const std::string file = zero ? good : std::string("/nonexistent/elsewhere.geo");
  const fem::Mesh m = fem::load_mesh(file, 1e-3);
  std::vector<char> zeros_file(good.begin(), good.end());  // rank 0's path (each rank has its own)
  int n = static_cast<int>(zeros_file.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  zeros_file.resize(static_cast<std::size_t>(n));
  MPI_Bcast(zeros_file.data(), n, MPI_CHAR, 0, MPI_COMM_WORLD);
  EXPECT_EQ(m.file, std::string(zeros_file.begin(), zeros_file.end()));
  EXPECT_EQ(m.quads, 50u);
  EXPECT_FALSE(m.surfaces.empty());
  EXPECT_EQ(m.curves.size(), 4u);
  // The same text everywhere: its length and a checksum, largest and smallest over the ranks.
  double sum = 0;
  for (std::size_t k = 0; k < m.msh.size(); ++k) sum += static_cast<unsigned char>(m.msh[k]) * (k % 97 + 1);
  const double len = static_cast<double>(m.msh.size());
  EXPECT_EQ(max_over_ranks(sum), -max_over_ranks(-sum));
  EXPECT_EQ(max_over_ranks(len), -max_over_ranks(-len));
  // An error on rank 0 is every rank's.
  std::string why;
  try {
    fem::load_mesh(zero ? std::string("/nonexistent/rank0.geo") : good, 1e-3);
  } catch (const fem::FemError& e) {
    why = e.what();
  }
  EXPECT_EQ(why, "/nonexistent/rank0.geo: mesh file not found");
}

TEST(FemRanks, InternalForceOnOwnRowsAsOneProcess) {
  for (const int degree : {1, 2}) {
    fem::Solver one(square(degree, false)), split(square(degree, false));
    split.distribute();
    ASSERT_EQ(split.ranks(), world_size());
    const std::size_t n = one.nodes();
    // The own nodes cover the mesh once.
    const std::vector<std::uint32_t> own = split.own_nodes();
    std::vector<double> count(n, 0.0);
    for (const auto i : own) count[i] += 1;
    MPI_Allreduce(MPI_IN_PLACE, count.data(), static_cast<int>(n), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    EXPECT_EQ(*std::min_element(count.begin(), count.end()), 1.0);
    EXPECT_EQ(*std::max_element(count.begin(), count.end()), 1.0);
    // A smooth field with every mode in it.
    std::vector<double> u(2 * n), f1(2 * n, 0.0), f2(2 * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const double x = one.node_x()[i] * 157.0, y = one.node_y()[i] * 211.0;
      u[2 * i] = 1e-6 * std::sin(x + 0.3) * std::cos(0.7 * y);
      u[2 * i + 1] = 1e-6 * std::cos(1.3 * x) * std::sin(y + 0.1);
    }
    one.internal_force(u.data(), f1.data());
    split.internal_force(u.data(), f2.data());
    double worst = 0, scale = 0;
    for (const auto i : own)
      for (int c = 0; c < 2; ++c) {
        worst = std::max(worst, std::fabs(f2[2 * i + c] - f1[2 * i + c]));
        scale = std::max(scale, std::fabs(f1[2 * i + c]));
      }
    worst = max_over_ranks(worst);
    scale = max_over_ranks(scale);
    if (root()) std::printf("  Q%d on %d rank(s): max |K u| %.3e, largest difference %.3e\n", degree,
                world_size(), scale, worst);
    EXPECT_GT(scale, 0.0);
    EXPECT_LE(worst, 1e-14 * scale);
  }
}

TEST(FemRanks, SquareWithEveryBoundaryAsOneProcess) {
  fem::Solver one(square(1, true)), split(square(1, true));
  split.distribute();
  for (fem::Solver* s : {&one, &split}) {
    s->set_dt(0.5 * s->critical_dt());
    ASSERT_EQ(s->add_probe(0.02, 0.02), 0);      // on a node: four cells' mean
    ASSERT_EQ(s->add_probe(0.0335, 0.0065), 1);  // in the layers' corner
  }
  double worst_probe = 0, probe_scale = 0;
  for (int n = 0; n < 300; ++n) {
    one.step();
    split.step();
    const auto a = one.sample(), b = split.sample();
    for (std::size_t p = 0; p < a.size(); ++p)
      for (const auto& [x, y] : {std::pair{a[p].sxx, b[p].sxx}, {a[p].syy, b[p].syy},
                                 {a[p].sxy, b[p].sxy}}) {
        worst_probe = std::max(worst_probe, std::fabs(x - y));
        probe_scale = std::max(probe_scale, std::fabs(x));
      }
  }
  double worst = 0, scale = 0;
  for (const auto i : split.own_nodes())
    for (int c = 0; c < 2; ++c) {
      worst = std::max({worst, std::fabs(split.displacement()[2 * i + c] - one.displacement()[2 * i + c]),
                        std::fabs(split.velocity()[2 * i + c] - one.velocity()[2 * i + c])});
      scale = std::max({scale, std::fabs(one.displacement()[2 * i + c]),
                        std::fabs(one.velocity()[2 * i + c])});
    }
  worst = max_over_ranks(worst);
  scale = max_over_ranks(scale);
  // The displacement gathered on rank 0 in messages of 7 values (a gather in pieces, so that a
  // whole of more than 2^31 - 1 values goes too): the same bits as in one message, and each
  // node where one process has it.
  const std::vector<double> whole = split.gathered(split.displacement());
  fem::Solver::set_gather_piece(7);
  const std::vector<double> pieces = split.gathered(split.displacement());
  fem::Solver::set_gather_piece(std::size_t{1} << 30);
  if (root()) {
    EXPECT_EQ(pieces, whole);
    ASSERT_EQ(pieces.size(), one.displacement().size());
    double off = 0;
    for (std::size_t k = 0; k < pieces.size(); ++k)
      off = std::max(off, std::fabs(pieces[k] - one.displacement()[k]));
    EXPECT_LE(off, 1e-14 * scale) << "gathered in pieces";
  }
  one.update_energies();
  split.update_energies();
  const Energies& e1 = one.energy;
  const Energies& e2 = split.energy;
  const double big = std::max({std::fabs(e1.kinetic), std::fabs(e1.elastic), std::fabs(e1.absorbed),
                               std::fabs(e1.external_work)});
  const double energy_diff =
      std::max({std::fabs(e2.kinetic - e1.kinetic), std::fabs(e2.elastic - e1.elastic),
                std::fabs(e2.absorbed - e1.absorbed), std::fabs(e2.external_work - e1.external_work)});
  const double balance = e2.kinetic + e2.elastic + e2.absorbed - e2.external_work;
  if (root()) std::printf("  %d rank(s): u, v %.3e of %.3e; probes %.3e of %.3e; energies %.3e of %.3e, "
              "balance %.3e (absorbed %.3e)\n",
              world_size(), worst, scale, worst_probe, probe_scale, energy_diff, big, balance,
              e2.absorbed);
  EXPECT_GT(scale, 0.0);
  EXPECT_LE(worst, 1e-14 * scale);
  EXPECT_LE(worst_probe, 1e-14 * probe_scale);
  EXPECT_GT(e2.absorbed, 0.05 * big);  // the layers took part
  EXPECT_LE(energy_diff, 1e-14 * big);
  EXPECT_LE(std::fabs(balance), 1e-14 * big);
}

TEST(FemRanks, LocalModelStepsAsTheWholeSplit) {
  for (const bool layers : {false, true})
  for (const int degree : {1, 2}) {
    const auto spec = [&] { return layers ? square(degree, true) : square_local(degree); };
    fem::Solver whole(spec()), part(spec());
    EXPECT_THROW(part.localize(), fem::FemError);  // not split yet
    for (fem::Solver* s : {&whole, &part}) {
      s->set_dt(0.5 * s->critical_dt());
      ASSERT_EQ(s->add_probe(0.02, 0.02), 0);       // on a node: four cells' mean
      ASSERT_EQ(s->add_probe(0.0335, 0.0065), 1);   // near the corner of two dashpot edges
      ASSERT_EQ(s->add_probe(0.0105, 0.0395), 2);   // under the load
      s->distribute();
    }
    const std::size_t nodes = part.nodes();
    ASSERT_TRUE(part.localize());
    EXPECT_TRUE(part.localized());
    EXPECT_THROW(part.add_probe(0.01, 0.01), fem::FemError);
    EXPECT_EQ(part.nodes(), nodes);
    EXPECT_EQ(part.dashpot_count(), whole.dashpot_count());
    EXPECT_EQ(part.describe(), whole.describe());
    const double held = static_cast<double>(part.traffic().held_nodes);
    bool same_probes = true;
    for (int n = 0; n < 300; ++n) {
      whole.step();
      part.step();
      const auto a = whole.sample(), b = part.sample();
      for (std::size_t p = 0; p < a.size(); ++p)
        same_probes = same_probes && a[p].sxx == b[p].sxx && a[p].syy == b[p].syy &&
                      a[p].sxy == b[p].sxy && a[p].vx == b[p].vx && a[p].vy == b[p].vy;
    }
    whole.update_energies();
    part.update_energies();
    EXPECT_TRUE(same_probes) << "Q" << degree;
    EXPECT_EQ(whole.energy.kinetic, part.energy.kinetic);
    EXPECT_EQ(whole.energy.elastic, part.energy.elastic);
    EXPECT_EQ(whole.energy.absorbed, part.energy.absorbed);
    EXPECT_EQ(whole.energy.external_work, part.energy.external_work);
    const std::vector<double> u1 = whole.gathered(whole.displacement()),
                              u2 = part.gathered(part.displacement());
    const std::vector<double> v1 = whole.gathered(whole.velocity()),
                              v2 = part.gathered(part.velocity());
    if (root()) {
      EXPECT_EQ(u1, u2);
      EXPECT_EQ(v1, v2);
      EXPECT_GT(*std::max_element(u1.begin(), u1.end()), 0.0);
      std::printf("  Q%d%s on %d rank(s): the largest rank holds %.0f of %zu nodes; absorbed "
                  "%.3e, work %.3e\n", degree, layers ? " with PMLs and a beta band" : "",
                  world_size(), held, nodes, part.energy.absorbed, part.energy.external_work);
    }
    // Their checkpoints, written by the ranks at once, are the same file byte for byte (every
    // rank puts the same blocks, a rank whose part has no layer cell too).
    namespace fs = std::filesystem;
    const fs::path dir = mpi_testing::scratch_folder("fem_ranks", "local_checkpoint");
    std::string bytes[2];
    for (int k = 0; k < 2; ++k) {
      StateWriter w;
      (k == 0 ? whole : part).save_state(w, "fem.");
      const fs::path file = dir / ("state" + std::to_string(k) + ".smpm");
      write_state_collectively(w, file.string(), MPI_COMM_WORLD);
      std::ifstream in(file, std::ios::binary);
      std::stringstream s;
      s << in.rdbuf();
      bytes[k] = s.str();
    }
    EXPECT_FALSE(bytes[0].empty());
    EXPECT_TRUE(bytes[0] == bytes[1]) << "Q" << degree << (layers ? " with layers" : "");
    if (world_size() == 2) {
      EXPECT_LE(held, 0.75 * static_cast<double>(nodes));
    }
    if (world_size() == 4) {
      EXPECT_LE(held, 0.5 * static_cast<double>(nodes));
    }
    EXPECT_GT(part.energy.absorbed, 0.0);
  }
}

TEST(FemRanks, PartsFromRankZeroFailOnEveryRankOrStepAsTheWhole) {
  const int P = world_size(), last = P - 1;
  if (P < 2) GTEST_SKIP() << "one rank: no part is sent";
  auto build = [&] {
    return root() ? std::make_unique<fem::Solver>(square(1, true))
                  : std::make_unique<fem::Solver>(square(1, true), fem::Solver::Skeleton{});
  };
  for (const int fault : {last, -last - 1}) {
    auto s = build();
    if (root()) s->set_dt(0.5 * s->critical_dt());
    fem::Solver::set_part_fault(fault);
    std::string why;
    try {
      s->distribute_from_root();
    } catch (const fem::FemError& e) {
      why = e.what();
    }
    fem::Solver::set_part_fault(0);
    EXPECT_FALSE(why.empty()) << "rank " << mpi_testing::world_rank() << ", fault " << fault;
    const bool at = fault > 0 ? root() : mpi_testing::world_rank() == last;
    if (at) {
      EXPECT_NE(why.find("a fault set by a test"), std::string::npos) << why;
    }
    if (root()) std::printf("  fault %d: rank 0 says \"%s\"\n", fault, why.c_str());
  }
  // Without a fault: the parts step as the whole model split on every rank.
  auto s = build();
  fem::Solver whole(square(1, true));
  whole.set_dt(0.5 * whole.critical_dt());
  if (root()) s->set_dt(whole.dt);
  s->distribute_from_root();
  whole.distribute();
  EXPECT_EQ(s->dt, whole.dt);
  EXPECT_EQ(s->nodes(), whole.nodes());
  for (int n = 0; n < 100; ++n) {
    s->step();
    whole.step();
  }
  s->update_energies();
  whole.update_energies();
  EXPECT_EQ(s->energy.kinetic, whole.energy.kinetic);
  EXPECT_EQ(s->energy.elastic, whole.energy.elastic);
  EXPECT_EQ(s->energy.absorbed, whole.energy.absorbed);
  EXPECT_GT(whole.energy.kinetic, 0.0);
}

TEST(FemRanks, CheckpointFromTheRanksRestartsOneProcess) {
  namespace fs = std::filesystem;
  fem::Solver one(square(1, true)), split(square(1, true)), restarted(square(1, true));
  split.distribute();
  for (fem::Solver* s : {&one, &split, &restarted}) s->set_dt(0.5 * s->critical_dt());
  for (int n = 0; n < 200; ++n) {
    one.step();
    split.step();
  }
  const fs::path file = mpi_testing::scratch_folder("fem_ranks", "checkpoint") / "state.smpm";
  StateWriter w;
  split.save_state(w, "fem.");
  write_state_collectively(w, file.string(), MPI_COMM_WORLD);
  std::ifstream in(file, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  const StateReader r(bytes.str(), file.string());
  EXPECT_TRUE(r.has("fem.nodes")) << "parts with their nodes' numbers";
  {  // a node named twice (edited behind a recomputed checksum) is refused
    std::string b = bytes.str();
    const std::size_t at = b.find("fem.nodes") + std::string("fem.nodes").size() + 12;
    std::memcpy(&b[at + 4], &b[at], 4);  // the second node's number := the first's
    const std::uint64_t sum = state_hash(b.data(), b.size() - 8);
    std::memcpy(&b[b.size() - 8], &sum, 8);
    fem::Solver edited(square(1, true));
    edited.set_dt(0.5 * edited.critical_dt());
    try {
      edited.load_state(StateReader(b, "edited"), "fem.");
      ADD_FAILURE() << "an edited node list was read";
    } catch (const StateError& e) {
      EXPECT_NE(std::string(e.what()).find("'fem.nodes' does not name every item once"),
                std::string::npos) << e.what();
    }
  }
  restarted.load_state(r, "fem.");
  for (int n = 0; n < 100; ++n) {
    one.step();
    restarted.step();
  }
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < one.displacement().size(); ++k) {
    worst = std::max({worst, std::fabs(restarted.displacement()[k] - one.displacement()[k]),
                      std::fabs(restarted.velocity()[k] - one.velocity()[k])});
    scale = std::max({scale, std::fabs(one.displacement()[k]), std::fabs(one.velocity()[k])});
  }
  one.update_energies();
  restarted.update_energies();
  const Energies &a = one.energy, &b = restarted.energy;
  const double big = std::max({std::fabs(a.kinetic), std::fabs(a.absorbed), std::fabs(a.external_work)});
  const double de = std::max({std::fabs(a.kinetic - b.kinetic), std::fabs(a.elastic - b.elastic),
                              std::fabs(a.absorbed - b.absorbed),
                              std::fabs(a.external_work - b.external_work)});
  if (root()) std::printf("  restarted from %d rank(s): u, v %.3e of %.3e; energies %.3e of %.3e\n",
                          world_size(), worst, scale, de, big);
  EXPECT_GT(scale, 0.0);
  EXPECT_GT(a.absorbed, 0.05 * big);  // the layers took part
  EXPECT_LE(worst, 1e-14 * scale);
  EXPECT_LE(de, 1e-14 * big);
}

TEST(FemRanks, ObliqueReflectionAsOneProcess) {
  if (world_size() != 2) GTEST_SKIP() << "the oblique measurement runs on 2 ranks only (its cost)";
  for (const std::string boundary : {"pml", "lk"}) {
    oblique::Setup s;
    s.angle_deg = 30;
    s.threads = 1;
    s.boundary = boundary;
    s.band = 10;
    const oblique::Result a = oblique::measure(s);
    s.distributed = true;
    const oblique::Result b = oblique::measure(s);
    if (root()) std::printf("  %s, P at 30 deg: |R_PP| %.6f / %.6f, |R_PS| %.6f / %.6f (one process / 2 ranks)\n",
                boundary.c_str(), a.r_same, b.r_same, a.r_conv, b.r_conv);
    EXPECT_NEAR(b.r_same, a.r_same, 1e-12 * a.r_same);
    EXPECT_NEAR(b.r_conv, a.r_conv, 1e-12 * a.r_conv);
    EXPECT_NEAR(b.incident, a.incident, 1e-12 * a.incident);
  }
}

}  // namespace
}  // namespace smpm::fem_testing
