// The MPM-FEM hybrid split over MPI ranks (Hybrid::distribute; docs/parallel.md): the grid in
// slabs of rows, the far field cut by METIS. The strip's interface is a vertical grid line, so
// it crosses every slab border: its nodes there lie in two ranks' windows, and their FE rows on
// ranks of METIS's choice. Run by CTest on 1, 2 and 4 ranks.
//   * Momentum: particles at 5 m/s run into the elements at rest (no loads, no constraints);
//     the total momentum stays put within 1e-10 of itself over 300 steps, MUSL and USL, without
//     and with two terms of the mass correction, and equals the one-process run's (which every
//     rank also steps) within 1e-12.
//   * The uniform-strain patch across the interface: after 200 steps the stress in both
//     regions is still the uniform one within 2e-11 of sigma_xx and nothing moves (one process
//     measures 1.0e-11 in the elements: the round-off of u = eps x over 200 steps), and every
//     particle's stress (by id) and every FE probe's equal the one-process run's within 1e-13
//     of sigma_xx.
//   * Particles thrown at 2000 m/s into the elements: every rank stops at the same step with
//     the same error as one process (naming the particle with the lowest id inside an FE cell).
//   * An FE load on an interface node: every rank stops at the first step with one process's
//     error, though only the node's FE owner holds it (each rank keeps its part of the far field).
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "mpi_testing.hpp"
#include "silentmpm/distributed.hpp"
#include "test_hybrid_common.hpp"

namespace smpm::hybrid_testing {
namespace {

using mpi_testing::max_over_ranks;
using mpi_testing::world_size;

// Cuts the coupled model over the ranks: the grid into slabs, the mesh by METIS, the interface.
std::unique_ptr<Distributed> split(HybRun& m) {
  auto d = std::make_unique<Distributed>(*m.mpm, MPI_COMM_WORLD, 1);
  m.fe->distribute();
  m.hyb->distribute(*d);
  return d;
}

// The HybridError that stops r within `steps` steps ("" if none).
std::string error_within(HybRun& r, int steps) {
  try {
    for (int k = 0; k < steps; ++k) r.step();
  } catch (const HybridError& e) {
    return e.what();
  }
  return "";
}

TEST(HybridRanks, MomentumExactAcrossRankBorders) {
  Strip c = free_strip(16);
  c.v0 = 5.0;
  for (int mc : {0, 2})
  for (Scheme sc : {Scheme::MUSL, Scheme::USL}) {
    c.scheme = sc;
    c.mass_correction = mc;
    HybRun one = make_strip(c), m = make_strip(c);
    const auto d = split(m);
    ASSERT_EQ(d->across(), 1);
    const auto p0 = m.hyb->momentum();
    const double ref = std::abs(p0[0]);
    ASSERT_GT(ref, 0);
    double drift = 0;
    for (int k = 0; k < 300; ++k) {
      m.step();
      one.step();
      const auto p = m.hyb->momentum();
      drift = std::max({drift, std::abs(p[0] - p0[0]) / ref, std::abs(p[1] - p0[1]) / ref});
    }
    const auto p = m.hyb->momentum(), q = one.hyb->momentum();
    const double apart = std::max(std::abs(p[0] - q[0]), std::abs(p[1] - q[1])) / ref;
    // Something happened: the FE region took up momentum (its own nodes', summed).
    double pfe = 0;
    for (const auto i : m.fe->own_nodes()) pfe += m.fe->mass()[i] * m.fe->velocity()[2 * i];
    MPI_Allreduce(MPI_IN_PLACE, &pfe, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    if (mpi_testing::world_rank() == 0)
      std::printf("%s, mass correction %d, on %d ranks: momentum drift %.3e, against one "
                  "process %.3e, FE share %.3f\n",
                  scheme_name(sc), mc, world_size(), drift, apart, pfe / ref);
    EXPECT_GT(pfe / ref, 0.02);
    EXPECT_LT(drift, 1e-10);
    EXPECT_LT(apart, 1e-12);
  }
}

TEST(HybridRanks, UniformStrainPatchAcrossRankBorders) {
  const Material mat = smpm::testing::tungsten();
  const double eps = -1e-4;
  const double sxx = mat.lambda * eps + 2 * mat.mu * eps, syy = mat.lambda * eps;
  Strip c;
  c.height = 16;
  HybRun m = make_uniform_strain_patch(c, eps), one = make_uniform_strain_patch(c, eps);
  for (double x : {13.3, 17.5, 22.25, 29.9})
    for (double y : {0.5, 4.0, 8.0, 15.7}) {
      ASSERT_GE(m.fe->add_probe(x * c.h, y * c.h), 0);
      ASSERT_GE(one.fe->add_probe(x * c.h, y * c.h), 0);
    }
  const auto d = split(m);  // the far field's part is kept: probes are added before
  for (int k = 0; k < 200; ++k) {
    m.step();
    one.step();
  }
  // Against one process: particles by id, probes one by one.
  std::map<std::uint32_t, std::size_t> at;
  for (std::size_t k = 0; k < one.mpm->p.size(); ++k) at[one.mpm->p.id[k]] = k;
  double apart = 0;
  for (std::size_t k = 0; k < m.mpm->p.size(); ++k) {
    const std::size_t q = at.at(m.mpm->p.id[k]);
    const Particles &a = m.mpm->p, &b = one.mpm->p;
    apart = std::max({apart, std::abs(a.sxx[k] - b.sxx[q]), std::abs(a.syy[k] - b.syy[q]),
                      std::abs(a.sxy[k] - b.sxy[q])});
  }
  const auto fm = m.fe->sample(), fo = one.fe->sample();
  for (std::size_t q = 0; q < fm.size(); ++q)
    apart = std::max({apart, std::abs(fm[q].sxx - fo[q].sxx), std::abs(fm[q].syy - fo[q].syy),
                      std::abs(fm[q].sxy - fo[q].sxy)});
  apart = max_over_ranks(apart);
  double dm = 0, df = 0, vmax = 0;
  const Solver& s = *m.mpm;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    dm = std::max({dm, std::abs(s.p.sxx[k] - sxx), std::abs(s.p.syy[k] - syy), std::abs(s.p.sxy[k])});
    vmax = std::max(vmax, std::hypot(s.p.vx[k], s.p.vy[k]));
  }
  for (const auto& q : fm)
    df = std::max({df, std::abs(q.sxx - sxx), std::abs(q.syy - syy), std::abs(q.sxy)});
  dm = max_over_ranks(dm);
  vmax = max_over_ranks(vmax);
  if (mpi_testing::world_rank() == 0)
    std::printf("patch on %d ranks: MPM stress error %.3e, FE %.3e (of |sxx|), max speed %.3e, "
                "against one process %.3e\n",
                world_size(), dm / std::abs(sxx), df / std::abs(sxx), vmax, apart / std::abs(sxx));
  EXPECT_LT(dm / std::abs(sxx), 2e-11);
  EXPECT_LT(df / std::abs(sxx), 2e-11);
  EXPECT_LT(vmax, 2e-11 * std::abs(sxx) / (mat.rho * mat.cd));
  EXPECT_LT(apart / std::abs(sxx), 1e-13);
}

TEST(HybridRanks, ParticleEnteringAnElementStopsEveryRankAtOneStep) {
  Strip c = free_strip(16);
  c.v0 = 2000;
  HybRun one = make_strip(c), m = make_strip(c);
  const auto d = split(m);
  const std::string alone = error_within(one, 200), split_run = error_within(m, 200);
  EXPECT_NE(alone.find("is inside an FE cell at step"), std::string::npos) << alone;
  EXPECT_EQ(split_run, alone);
  EXPECT_EQ(m.mpm->steps, one.mpm->steps);
  if (mpi_testing::world_rank() == 0) std::printf("%s\n", split_run.c_str());
}

// An FE traction on the far field's top edge loads the interface node at its corner, which
// carries MPM mass. Each rank keeps only its part of the far field, so only that node's FE
// owner sees the load: every rank must still stop at the first step with one process's error
// (the owners' verdicts travel in the interface's first sum).
TEST(HybridRanks, FemLoadOnAnInterfaceNodeStopsEveryRank) {
  const double h = 1e-3, H = 16 * h;
  const auto build = [&] {
    HybRun m;
    m.mpm = std::make_unique<Solver>();
    Solver& s = *m.mpm;
    s.materials.push_back(smpm::testing::tungsten());
    s.grid.init(-2 * h, 0.0, h, 34, 16);
    s.seed_rectangle(0, 0, 20 * h, H, 1, 0, 0, 0, 0);
    s.opt.threads = 1;
    s.dt = 0.3 * h / s.materials[0].cd;
    s.finalize();
    fem::Spec spec;
    spec.mesh = fem::load_mesh(box_geo("ranks_fe_load", 20 * h, 0, 30 * h, H, h), h);
    spec.materials = {smpm::testing::tungsten()};
    spec.region_material = {{1, 0}};
    spec.threads = 1;
    auto top = fe_bc(fem::Boundary::Kind::Traction, 14, "top");
    top.normal = -1e6;
    spec.boundaries.push_back(top);
    m.fe = std::make_unique<fem::Solver>(spec);
    m.hyb = std::make_unique<Hybrid>(s, *m.fe);
    m.hyb->set_dt(s.dt);
    return m;
  };
  HybRun one = build(), m = build();
  const auto d = split(m);
  const std::string alone = error_within(one, 5), split_run = error_within(m, 5);
  EXPECT_NE(alone.find("FEM boundary load acts on the interface node at (0.02, 0.016)"),
            std::string::npos)
      << alone;
  EXPECT_EQ(split_run, alone);
  EXPECT_EQ(m.mpm->steps, 0);
  // The far field's part: a rank holds no more than its share and the nodes it receives.
  const double held = static_cast<double>(m.fe->traffic().held_nodes);
  if (world_size() > 1) {
    EXPECT_LE(held, 0.75 * static_cast<double>(m.fe->nodes()));
  }
}

}  // namespace
}  // namespace smpm::hybrid_testing
