// `mpirun -np N silentmpm run`: the command line over MPI ranks against one process (label mpi;
// this binary is not an MPI process, it starts mpirun). The pulse plate of the pulse study
// (200 cell rows, 10 000 particles, LK on the right edge, a probe), 1 000 steps:
//   * 1 rank: history.csv and probes.csv byte-identical to the plain run, summary.json equal
//     but for timings and the rank count;
//   * 2 and 4 ranks (slabs, and 2 x 2 blocks): every history column within 1e-10 relative L2 of the plain run (a column
//     normalised by the largest of its kind: the probe's stresses, its velocities, the
//     energies), the same particle count; two runs on 2 ranks byte-identical;
//   * snapshots on 2 ranks: every particle's fields as the plain run's (by id);
//   * the J2-softening film on 2 and 4 ranks within 1e-3 (its thresholds may flip);
//   * a checkpoint of 2 ranks restarts on 1, 2 and 4;
//   * what the ranks cannot share yet is refused before the run (exit 1, one line naming it);
//   * the FE far field on 1-4 ranks, built on rank 0 and each rank holding only its part: its
//     fields to the bit, a checkpoint on 2 restarting on 1 and 4;
//   * the MPM-FEM hybrid on 1-4 ranks (interfaces crossing the ranks' borders) as one process,
//     a checkpoint on 2 restarting on 1 and 3;
//   * a failure on one rank stops every rank (exit 2) and leaves RUN_INCOMPLETE saying why;
//   * an interrupt stops every rank after one step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "silentmpm/history.hpp"
#include "silentmpm/state_io.hpp"

#ifndef SMPM_MPIEXEC
#define SMPM_MPIEXEC "mpirun"
#endif

namespace smpm::cli_testing {
namespace {

namespace fs = std::filesystem;

const std::string kCase = source_file("studies/pulse/cases/compressive_silent.json");
const std::string kShort = " --set time.end=4e-5 --set output.snapshots=0 -q";
// The FE far field: a 40 x 40-cell square with every kind of FE boundary (fem_square.json).
const std::string kFem = source_file("tests/mpi_cli/fem_square.json") + " -q";

std::string mpirun(int np) {
  return std::string("OMP_NUM_THREADS=1 ") + SMPM_MPIEXEC +
         " --allow-run-as-root --oversubscribe -np " + std::to_string(np) + " ";
}

fs::path out_dir(const std::string& tag) {
  const fs::path d = case_testing::scratch() / tag;
  fs::remove_all(d);
  return d;
}

// The error lines in a run's stderr (rank 0 alone prints a case's error).
std::size_t error_lines(const std::string& err) {
  std::size_t n = 0;
  for (std::size_t at = err.find("silentmpm: error"); at != std::string::npos;
       at = err.find("silentmpm: error", at + 1))
    ++n;
  return n;
}

Proc run(int np, const std::string& args, const std::string& tag) {
  const std::string cmd = (np > 0 ? mpirun(np) : std::string("OMP_NUM_THREADS=1 ")) + SMPM_CLI +
                          " run " + args;
  return run_shell(cmd, tag);
}

// Per column: ||a - b|| / the largest ||b|| among the columns of its kind.
std::map<std::string, double> differences(const fs::path& a, const fs::path& b) {
  const History ha = read_history((a / "history.csv").string());
  const History hb = read_history((b / "history.csv").string());
  EXPECT_EQ(ha.columns, hb.columns);
  EXPECT_EQ(ha.time.size(), hb.time.size());
  auto kind = [](const std::string& c) {
    if (c.rfind("energy.", 0) == 0) return std::string("energy");
    const auto dot = c.find('.');
    const std::string f = c.substr(dot + 1);
    return c.substr(0, dot) + (f == "vx" || f == "vy" ? ".v" : ".s");
  };
  std::map<std::string, double> scale, diff, norm;
  for (std::size_t q = 0; q < hb.columns.size(); ++q) {
    double d = 0, n = 0;
    for (std::size_t r = 0; r < std::min(ha.time.size(), hb.time.size()); ++r) {
      const double x = ha.data[q][r], y = hb.data[q][r];
      d += (x - y) * (x - y);
      n += y * y;
    }
    diff[hb.columns[q]] = std::sqrt(d);
    norm[hb.columns[q]] = std::sqrt(n);
    double& s = scale[kind(hb.columns[q])];
    s = std::max(s, std::sqrt(n));
  }
  std::map<std::string, double> rel;
  for (const auto& [c, d] : diff) rel[c] = scale[kind(c)] > 0 ? d / scale[kind(c)] : d;
  return rel;
}

// Every dataset of HDF5 file b against a's: the largest difference over the largest value of
// a's dataset, at most `bound` (0: equal to the bit). With by_id, the snapshot groups' rows are
// matched through their "id" dataset (a run on several ranks writes them in another order).
// The exit status says whether they agree; the output names the count and the worst.
Proc compare_h5(const fs::path& a, const fs::path& b, bool by_id, double bound,
                const std::string& tag) {
  const std::string py =
      "import sys, h5py, numpy as np\n"
      "a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2]); by_id = sys.argv[3] == '1'\n"
      "bound = float(sys.argv[4]); names = []; worst = 0.0\n"
      "a.visit(lambda n: names.append(n) if isinstance(a[n], h5py.Dataset) else None)\n"
      "for n in names:\n"
      "  g = n.rsplit('/', 1)[0] if '/' in n else ''\n"
      "  x, y = a[n][()], b[n][()]\n"
      "  if by_id and g.startswith('step_'):\n"
      "    assert a[g].attrs['time'] == b[g].attrs['time'], g\n"
      "    x, y = x[np.argsort(a[g]['id'][()])], y[np.argsort(b[g]['id'][()])]\n"
      "  x, y = x.astype(float), y.astype(float)\n"
      "  worst = max(worst, np.abs(x - y).max() / max(np.abs(x).max(), 1e-300))\n"
      "print(len(names), 'datasets, worst', worst)\n"
      "sys.exit(0 if names and worst <= bound else 1)\n";
  const fs::path script = case_testing::write_file(tag + ".py", py);
  char bound_text[32];
  std::snprintf(bound_text, sizeof bound_text, "%.17g", bound);
  return run_shell("/usr/bin/python3 " + script.string() + " " + a.string() + " " + b.string() +
                       (by_id ? " 1 " : " 0 ") + bound_text,
                   tag);
}

nlohmann::json summary(const fs::path& dir) {
  return nlohmann::json::parse(case_testing::read_file(dir / "summary.json"));
}

TEST(MpiCli, OneRankBitIdenticalOnEveryOutput) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path a = out_dir("plain1"), b = out_dir("np1");
  const std::string args = kCase + " --set time.end=2e-5 --set output.snapshots=3 -q --out ";
  ASSERT_EQ(run(0, args + a.string(), "plain1").status, 0);
  const Proc p = run(1, args + b.string(), "np1");
  ASSERT_EQ(p.status, 0) << p.err;
  for (const char* f : {"history.csv", "probes.csv", "particles.xdmf"})
    EXPECT_EQ(case_testing::read_file(a / f), case_testing::read_file(b / f)) << f;
  // The snapshots' datasets (HDF5 stamps each object with its creation time, so the files'
  // bytes differ between any two runs).
  const Proc h = compare_h5(a / "particles.h5", b / "particles.h5", false, 0.0, "np1_h5");
  EXPECT_EQ(h.status, 0) << h.out << h.err;
  nlohmann::json sa = summary(a), sb = summary(b);
  EXPECT_EQ(sb["mpi_ranks"], 1);
  for (auto* j : {&sa, &sb})
    for (const char* k : {"wall_seconds", "step_seconds", "particle_updates_per_second", "mpi_ranks", "mpi_ranks_across", "mpi"})
      j->erase(k);
  EXPECT_EQ(sa, sb);
}

TEST(MpiCli, TwoAndFourRanksMatchOneProcess) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path a = out_dir("plain");
  ASSERT_EQ(run(0, kCase + kShort + " --out " + a.string(), "plain").status, 0);
  // 2 and 4 ranks in the layout the program picks (slabs on this tall plate), 4 as 2 x 2 blocks.
  for (const auto& [np, across] : std::vector<std::pair<int, int>>{{2, 0}, {4, 0}, {4, 2}}) {
    const std::string tag = "np" + std::to_string(np) + (across ? "x" + std::to_string(across) : "");
    const fs::path b = out_dir(tag);
    const Proc p = run(np, kCase + kShort + " --ranks-across " + std::to_string(across) +
                               " --out " + b.string(), tag);
    ASSERT_EQ(p.status, 0) << p.err;
    double worst = 0;
    for (const auto& [c, d] : differences(b, a)) {
      EXPECT_LE(d, 1e-10) << tag << ", column " << c;
      worst = std::max(worst, d);
    }
    const nlohmann::json sa = summary(a), sb = summary(b);
    std::printf("%d ranks, %d across: history within %.1e of one process\n", np,
                sb["mpi_ranks_across"].get<int>(), worst);
    EXPECT_EQ(sb["mpi_ranks"], np);
    EXPECT_EQ(sb["mpi_ranks_across"], across ? across : 1);
    EXPECT_EQ(sb["particles"], sa["particles"]);
    EXPECT_EQ(sb["grid"], sa["grid"]);
    EXPECT_EQ(sb["silent_boundaries"], sa["silent_boundaries"]);
    EXPECT_EQ(sb["bodies"], sa["bodies"]);
    for (const char* e : {"kinetic", "elastic", "absorbed", "external_work"})
      EXPECT_NEAR(sb["energy"][e].get<double>(), sa["energy"][e].get<double>(),
                  1e-10 * sa["energy"]["external_work"].get<double>())
          << e;
    EXPECT_FALSE(fs::exists(b / "RUN_INCOMPLETE"));
  }
  const fs::path c = out_dir("np2_again");
  ASSERT_EQ(run(2, kCase + kShort + " --out " + c.string(), "np2_again").status, 0);
  EXPECT_EQ(case_testing::read_file(c / "history.csv"),
            case_testing::read_file(case_testing::scratch() / "np2" / "history.csv"));
}

TEST(MpiCli, RefusesWhatRanksCannotShareYet) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  struct Bad {
    std::string args, message;
  };
  const fs::path o = out_dir("refused");
  const std::vector<Bad> bad = {
      {kCase + kShort + " --ranks-across 3",
       "2 MPI ranks cannot form blocks 3 ranks across"},
      // (Its probes read the corrected nodal velocity of one window.)
      {kCase + kShort + " --set bodies.0.particles_per_cell=4 --set scheme.mass_correction=1"
                        " --set scheme.mass_correction_form=symmetric",
       "scheme.mass_correction_form \"symmetric\" runs on one process"},
      {kCase + kShort + " --set scheme.light_nodes=extend",
       "scheme.light_nodes \"extend\" runs on one process"},
      {kFem + " --set fem.size=0.04", "FEM: fewer cells (1) than MPI ranks (2)"},
      // The far field is set up from rank 0: its checks are rank 0's, and every rank's error.
      {kFem + " --set probes.1.at=[0.5,0.5]", "outside the FEM mesh"},
      {kFem + " --set 'time={\"end\": 2e-5, \"dt\": 1e-5}'", "above the FEM stability limit"},
      {kFem + " --ranks-across 2", "--ranks-across 2 lays out the blocks of an MPM grid; an FE "
                                   "case's mesh is cut by METIS"}};
  int k = 0;
  for (const Bad& b : bad) {
    const Proc p = run(2, b.args + " --out " + o.string(), "refused" + std::to_string(k++));
    EXPECT_EQ(p.status, 1) << b.args << "\n" << p.err;
    EXPECT_NE(p.err.find(b.message), std::string::npos) << b.args << "\n" << p.err;
    EXPECT_EQ(error_lines(p.err), 1u) << p.err << "one line from rank 0, not one per rank";
    EXPECT_FALSE(fs::exists(o)) << "refused before the output folder is made";
  }
}

// Rank 0 alone reads a case's gmsh geometry and FE mesh and sends them to the others (the
// pulse plate above is a gmsh geometry, so its agreement with one process covers what is sent).
// A file it cannot read is every rank's error: one line, rank 0's, the same as one process's,
// exit 1, before the output folder.
TEST(MpiCli, UnreadableGeometryOrMeshIsOneProcessError) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path o = out_dir("unreadable");
  for (const std::string& args : {kCase + kShort + " --set geometry.file=nothere.geo",
                                  kFem + " --set fem.mesh=nothere.geo"}) {
    const Proc one = run(0, args + " --out " + o.string(), "unreadable1");
    const Proc two = run(2, args + " --out " + o.string(), "unreadable2");
    EXPECT_EQ(one.status, 1) << one.err;
    EXPECT_EQ(two.status, 1) << two.err;
    const std::string line = one.err.substr(0, one.err.find('\n'));
    EXPECT_NE(line.find("nothere.geo"), std::string::npos) << line;
    EXPECT_EQ(two.err.substr(0, two.err.find('\n')), line);
    EXPECT_EQ(error_lines(two.err), 1u) << two.err;
    EXPECT_FALSE(fs::exists(o));
  }
}

// Rank 0 alone builds the whole case (the others its skeleton, without particles), so the
// checks that need the particles run there: a probe in no body, a body off the grid. Its error
// is every rank's: one line, the same as one process's, exit 1, before the output folder.
TEST(MpiCli, ParticleChecksOfRankZeroAreEveryRanksError) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path o = out_dir("particle_checks");
  for (const std::string& args : {kCase + kShort + " --set probes.0.at=[0.052,0.2]",
                                  kCase + kShort + " --set grid.size=[0.03,0.204]"}) {
    const Proc one = run(0, args + " --out " + o.string(), "checks1");
    const Proc two = run(2, args + " --out " + o.string(), "checks2");
    EXPECT_EQ(one.status, 1) << one.err;
    EXPECT_EQ(two.status, 1) << two.err;
    const std::string line = one.err.substr(0, one.err.find('\n'));
    EXPECT_EQ(two.err.substr(0, two.err.find('\n')), line) << two.err;
    EXPECT_EQ(error_lines(two.err), 1u) << two.err;
    EXPECT_FALSE(fs::exists(o));
  }
}

// The FE far field (fem_square.json: a traction pulse, PMLs on two sides meeting in a corner,
// dashpots, a damping band (mass and stiffness parts) before Kelvin-Voigt springs, gravity; Q1
// and Q2) on 1, 2, 3 and 4
// ranks. Each rank steps its own nodes' rows in the order one process sums them, so every
// node's displacement and velocity, and the stresses from them, are those of one process to the
// bit: fem.h5, which every rank writes its share of at once (Q2 deflated), equal dataset by
// dataset (bound 0), and fem.xdmf byte-identical. history.csv: on
// 1 rank byte-identical; on more, sums over ranks (energies, a probe's cells on two ranks) are
// added in another order: every column within 1e-13 of the largest of its kind. Rank 0 builds
// the far field and sends each rank its part: the largest rank holds at most 3/4 of the mesh's
// nodes on 2 ranks and 1/2 on 3 and 4 (measured below).
TEST(MpiCli, FarFieldOnOneToFourRanksAsOneProcess) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  struct Run {
    int np;
    std::string set;
  };
  for (const Run& r : {Run{1, ""}, Run{2, ""}, Run{4, ""},
                       Run{3, " --set fem.degree=2 --set output.compression=4"}}) {
    const std::string q = r.set.empty() ? "q1" : "q2";
    const fs::path a = case_testing::scratch() / ("fem_plain_" + q);
    const fs::path b = out_dir("fem_np" + std::to_string(r.np));
    if (r.np == 1 || r.np == 3) {  // the plain run of each degree, once
      fs::remove_all(a);
      ASSERT_EQ(run(0, kFem + r.set + " --out " + a.string(), "fem_plain").status, 0);
    }
    const Proc p = run(r.np, kFem + r.set + " --out " + b.string(), "fem_np");
    ASSERT_EQ(p.status, 0) << p.err;
    const Proc h = compare_h5(a / "fem.h5", b / "fem.h5", false, 0.0, "fem_h5");
    EXPECT_EQ(h.status, 0) << r.np << " ranks: " << h.out << h.err;
    EXPECT_TRUE(case_testing::read_file(a / "fem.xdmf") == case_testing::read_file(b / "fem.xdmf"));
    if (r.np == 1) {
      EXPECT_TRUE(case_testing::read_file(a / "history.csv") ==
                  case_testing::read_file(b / "history.csv"));
    }
    double worst = 0;
    for (const auto& [c, d] : differences(b, a)) {
      EXPECT_LE(d, 1e-13) << r.np << " ranks, column " << c;
      worst = std::max(worst, d);
    }
    const nlohmann::json sb = summary(b);
    EXPECT_EQ(sb["mpi_ranks"], r.np);
    EXPECT_EQ(sb["dofs"], summary(a)["dofs"]);
    const double nodes = sb["fem"]["nodes"].get<double>();
    const double held = sb["mpi"]["held_nodes_most"].get<double>();
    EXPECT_EQ(sb["fem"]["dashpot_nodes"], summary(a)["fem"]["dashpot_nodes"]);
    if (r.np > 1) {
      EXPECT_GT(sb["mpi"]["ghost_bytes_per_step"].get<double>(), 0);
      EXPECT_LE(held, (r.np == 2 ? 0.75 : 0.5) * nodes) << r.np << " ranks";
    }
    std::printf("FE far field, %s on %d rank(s): history within %.1e; the largest rank holds "
                "%.0f of %.0f nodes; fields: %s",
                q.c_str(), r.np, worst, held, nodes, h.out.c_str());
  }
}

// The MPM-FEM hybrid over ranks: the grid in blocks, the far field cut by METIS, the interface
// summed over the ranks. The pulse plate's interface is a vertical grid line (it crosses every
// slab border), the film's a horizontal one (4 ranks across: every block border crosses it).
// On 1 rank history.csv is byte-identical to the plain run; on more, every column within 1e-10
// of the largest of its kind, both snapshot files dataset by dataset (particles by id) within
// 1e-10 of their largest values, the counts of summary.json equal and each energy term within
// 1e-10 of the work done; the interface's sums carry 8 values a shared node and step, and two
// guards' verdicts. Each rank keeps only its part of the far field: the largest holds at most
// 3/4 of the mesh's nodes on 2 ranks, 1/2 on 3 and 4.
TEST(MpiCli, HybridOnOneToFourRanksAsOneProcess) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const std::string pulse = source_file("studies/hybrid/cases/pulse_hybrid_dashpot.json") +
                            " --set time.end=1e-5 --set output.snapshots=2 -q";
  const std::string film = source_file("studies/hybrid/cases/film_hybrid_fixed_elastic.json") +
                           " --set time.end=2e-9 --set output.snapshots=2 -q";
  struct Run {
    std::string tag, args;
    int np, across;
  };
  const std::vector<Run> runs = {{"pulse", pulse, 1, 0},
                                 {"pulse", pulse, 2, 0},
                                 {"pulse", pulse, 4, 2},
                                 {"pulse_usl", pulse + " --set scheme.update=USL", 3, 0},
                                 {"film", film, 4, 4}};
  for (const Run& r : runs) {
    const fs::path a = case_testing::scratch() / ("hyb_plain_" + r.tag);
    if (!fs::exists(a / "summary.json")) {
      fs::remove_all(a);
      ASSERT_EQ(run(0, r.args + " --out " + a.string(), "hyb_plain").status, 0);
    }
    const std::string tag = "hyb_" + r.tag + "_np" + std::to_string(r.np);
    const fs::path b = out_dir(tag);
    const Proc p = run(r.np, r.args + " --ranks-across " + std::to_string(r.across) + " --out " +
                                 b.string(), tag);
    ASSERT_EQ(p.status, 0) << p.err;
    if (r.np == 1) {
      EXPECT_TRUE(case_testing::read_file(a / "history.csv") ==
                  case_testing::read_file(b / "history.csv"));
    }
    double worst = 0;
    for (const auto& [c, d] : differences(b, a)) {
      EXPECT_LE(d, 1e-10) << tag << ", column " << c;
      worst = std::max(worst, d);
    }
    const Proc hp = compare_h5(a / "particles.h5", b / "particles.h5", true, 1e-10, tag + "_p");
    EXPECT_EQ(hp.status, 0) << tag << ": " << hp.out << hp.err;
    const Proc hf = compare_h5(a / "fem.h5", b / "fem.h5", false, 1e-10, tag + "_f");
    EXPECT_EQ(hf.status, 0) << tag << ": " << hf.out << hf.err;
    const nlohmann::json sa = summary(a), sb = summary(b);
    EXPECT_EQ(sb["mpi_ranks"], r.np);
    // The interface's three sums: 2 + 4 + 2 values a shared node, and the guards' verdicts (an
    // FE load on a shared node, a particle in an FE cell).
    EXPECT_EQ(sb["mpi"]["interface_values_per_step"].get<double>(),
              8.0 * sa["hybrid"]["shared_nodes"].get<double>() + 2)
        << tag;
    const double nodes = sa["fem"]["nodes"].get<double>();
    const double held = r.np > 1 ? sb["mpi"]["fem"]["held_nodes_most"].get<double>() : nodes;
    if (r.np > 1) {
      EXPECT_LE(held, (r.np == 2 ? 0.75 : 0.5) * nodes) << tag;
    }
    for (const char* k : {"particles", "dofs", "hybrid", "bodies", "fem", "outputs"})
      EXPECT_EQ(sb[k], sa[k]) << tag << " " << k;
    for (const char* e : {"kinetic", "elastic", "absorbed", "external_work"})
      EXPECT_NEAR(sb["energy"][e].get<double>(), sa["energy"][e].get<double>(),
                  1e-10 * sa["energy"]["external_work"].get<double>())
          << tag << " " << e;
    std::printf("hybrid %s on %d ranks (%d across): history within %.1e; the largest rank "
                "holds %.0f of %.0f FE nodes; particles %s; FE %s",
                r.tag.c_str(), r.np, sb["mpi_ranks_across"].get<int>(), worst, held, nodes,
                hp.out.c_str(), hf.out.c_str());
  }
}

// A run on 2 ranks writing a checkpoint every `every` steps (args: the case and its settings), and
// its restart on each of `restarts` rank counts (0: one plain process) in a copy of its folder:
// each ends as the plain run does, every history column within `bound` of the largest of its
// kind, each energy term within `bound` of the work; it restarts from the last checkpoint.
void expect_checkpoint_restarts(const std::string& args, const std::string& tag, long every,
                                std::initializer_list<int> restarts, double bound) {
  const std::string ck =
      args + " --set output.snapshots=0 --set output.checkpoint_every=" + std::to_string(every);
  const fs::path a = out_dir(tag + "_plain"), b = out_dir(tag + "_np2");
  ASSERT_EQ(run(0, ck + " --out " + a.string(), tag + "_plain").status, 0);
  const Proc p = run(2, ck + " --out " + b.string(), tag + "_np2");
  ASSERT_EQ(p.status, 0) << p.err;
  ASSERT_TRUE(fs::exists(b / "checkpoint.smpm"));
  const long steps = summary(a)["steps"].get<long>();
  EXPECT_GT(steps, 2 * every) << tag;
  for (int np : restarts) {
    const std::string t = tag + "_restart" + std::to_string(np);
    const fs::path r = out_dir(t);
    fs::copy(b, r, fs::copy_options::recursive);
    fs::remove(r / "summary.json");
    const Proc q = run(np, ck + " --out " + r.string() + " --restart " +
                               (r / "checkpoint.smpm").string(), t);
    ASSERT_EQ(q.status, 0) << q.err;
    EXPECT_EQ(summary(r)["restart"]["from_step"].get<long>(), (steps - 1) / every * every) << t;
    for (const auto& [c, d] : differences(r, a)) EXPECT_LE(d, bound) << t << ", column " << c;
    // The per-step traffic is over the steps the restart made: on 2 ranks the halo's bytes per
    // step are the full run's, to the sums of the silent edges' dashpot solve, whose iterations
    // vary from step to step (Solver::consistent_dashpots; measured 0.3 % on the pulse plate).
    if (np == 2 && summary(b).contains("mpi")) {
      const double full = summary(b)["mpi"]["halo_bytes_per_step"].get<double>();
      EXPECT_NEAR(summary(r)["mpi"]["halo_bytes_per_step"].get<double>(), full, 1e-2 * full) << t;
    }
    for (const char* e : {"kinetic", "elastic", "absorbed", "external_work"})
      EXPECT_NEAR(summary(r)["energy"][e].get<double>(), summary(a)["energy"][e].get<double>(),
                  bound * summary(a)["energy"]["external_work"].get<double>())
          << t << " " << e;
  }
}

// A hybrid checkpoint written on 2 ranks is one process's: a restart on 1 process and on 3
// ranks ends as the plain run does (history within 1e-10 of the largest of a column's kind,
// energies within 1e-10 of the work).
TEST(MpiCli, HybridCheckpointOnTwoRanksRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(source_file("studies/hybrid/cases/pulse_hybrid_dashpot.json") +
                                 " --set time.end=1e-5 -q",
                             "hybck", 100, {0, 3}, 1e-10);
}

// A far-field checkpoint written on 2 ranks holds the whole mesh's state: a restart on 1
// process and on 4 ranks ends as the plain run does (history and energies within 1e-13).
TEST(MpiCli, FarFieldCheckpointOnTwoRanksRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(kFem, "femck", 100, {0, 4}, 1e-13);
}

// Snapshots on 2 ranks, and on 4 as 2 x 2 blocks with deflated datasets: every rank writes its
// particles into the one file, rank by rank, and its own nodes' projection into grid.h5 (a
// block of rows of the whole grid's); every dataset of every snapshot against the plain run's,
// row by row through the ids, within 1e-10 of its largest value. The grid's projection
// (output.grid) node by node within 1e-10, its XDMF byte-identical.
TEST(MpiCli, SnapshotsOnTwoRanksHoldEveryParticle) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path a = out_dir("snap_plain"), b = out_dir("snap_np2");
  const std::string args =
      kCase + " --set time.end=2e-5 --set output.snapshots=3 --set output.grid=true -q --out ";
  ASSERT_EQ(run(0, args + a.string(), "snap_plain").status, 0);
  const Proc p = run(2, args + b.string(), "snap_np2");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(summary(b)["outputs"]["snapshots"], summary(a)["outputs"]["snapshots"]);
  const Proc h = compare_h5(a / "particles.h5", b / "particles.h5", true, 1e-10, "snap_h5");
  EXPECT_EQ(h.status, 0) << h.out << h.err;
  std::printf("snapshots on 2 ranks: %s", h.out.c_str());
  // The grid's projection (output.grid): every node's fields, in the same order.
  const Proc g = compare_h5(a / "grid.h5", b / "grid.h5", false, 1e-10, "snap_grid");
  EXPECT_EQ(g.status, 0) << g.out << g.err;
  EXPECT_EQ(case_testing::read_file(a / "grid.xdmf"), case_testing::read_file(b / "grid.xdmf"));
  std::printf("grid snapshots on 2 ranks: %s", g.out.c_str());
  const fs::path c = out_dir("snap_np4");
  const Proc q = run(4, args + c.string() + " --ranks-across 2 --set output.compression=3",
                     "snap_np4");
  ASSERT_EQ(q.status, 0) << q.err;
  const Proc h4 = compare_h5(a / "particles.h5", c / "particles.h5", true, 1e-10, "snap4_h5");
  EXPECT_EQ(h4.status, 0) << h4.out << h4.err;
  const Proc g4 = compare_h5(a / "grid.h5", c / "grid.h5", false, 1e-10, "snap4_grid");
  EXPECT_EQ(g4.status, 0) << g4.out << g4.err;
  EXPECT_EQ(case_testing::read_file(a / "grid.xdmf"), case_testing::read_file(c / "grid.xdmf"));
  EXPECT_EQ(case_testing::read_file(a / "particles.xdmf"),
            case_testing::read_file(c / "particles.xdmf"));
  std::printf("on 2 x 2 ranks, deflated: particles %sgrid %s", h4.out.c_str(), g4.out.c_str());
}

// The impact study with multi-field contact and friction on 2 ranks: every history column
// (probes, energies) within 1e-10 of the plain run's.
TEST(MpiCli, MultiFieldContactImpactOnTwoRanks) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const std::string args = source_file("studies/impact/cases/silent.json") +
                           " --set time.end=4.5e-6 --set output.snapshots=0 -q"
                           " --set 'contact={\"type\":\"multi\",\"friction\":0.2}' --out ";
  const fs::path a = out_dir("impact_plain"), b = out_dir("impact_np2");
  ASSERT_EQ(run(0, args + a.string(), "impact_plain").status, 0);
  const Proc p = run(2, args + b.string(), "impact_np2");
  ASSERT_EQ(p.status, 0) << p.err;
  double worst = 0;
  for (const auto& [c, d] : differences(b, a)) {
    EXPECT_LE(d, 1e-10) << "column " << c;
    worst = std::max(worst, d);
  }
  std::printf("impact with multi-field contact on 2 ranks: history within %.1e\n", worst);
}

// The J2-softening film (the film study at CI size, 3.2 ns: the film yields) on 2 ranks and 4:
// its threshold decisions (yield, bifurcation, decohesion) may flip with the order of additions,
// so the bound is 1e-3 for every history column (against the largest of its kind) and for the
// dissipated energy; the energy account stays as closed as the plain run's.
TEST(MpiCli, SofteningFilmOnTwoAndFourRanks) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const std::string args = source_file("studies/film/cases/silent.json") +
                           " --set time.end=3.2e-9 --set output.snapshots=0 -q --out ";
  const fs::path a = out_dir("film_plain");
  ASSERT_EQ(run(0, args + a.string(), "film_plain").status, 0);
  const nlohmann::json ea = summary(a)["energy"];
  ASSERT_GT(ea["dissipated"].get<double>(), 0) << "the film yields";
  for (int np : {2, 4}) {
    const std::string tag = "film_np" + std::to_string(np);
    const fs::path b = out_dir(tag);
    const Proc p = run(np, args + b.string(), tag);
    ASSERT_EQ(p.status, 0) << p.err;
    double worst = 0;
    for (const auto& [c, d] : differences(b, a)) {
      EXPECT_LE(d, 1e-3) << tag << ", column " << c;
      worst = std::max(worst, d);
    }
    const nlohmann::json eb = summary(b)["energy"];
    const double da = ea["dissipated"].get<double>(), db = eb["dissipated"].get<double>();
    EXPECT_NEAR(db, da, 1e-3 * da) << tag;
    EXPECT_LE(std::abs(eb["relative_imbalance"].get<double>()),
              std::abs(ea["relative_imbalance"].get<double>()) + 1e-6)
        << tag;
    std::printf("film on %d ranks: history within %.1e, dissipated %.3e against %.3e\n", np,
                worst, db, da);
  }
}

// A checkpoint written on 2 ranks is the whole body's: a restart from it on 1 process, on 2 and
// on 4 ranks continues the run, every history column within 1e-10 of the plain run's.
TEST(MpiCli, CheckpointOnTwoRanksRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(kCase + kShort, "ck", 300, {0, 2, 4}, 1e-10);
}

// USF with the updated velocity at the silent edge: the last step's v+ at the edge's dashpot
// nodes is state, gathered from each node's owner; restarts on 1 process and on 4 ranks.
TEST(MpiCli, UsfUpdatedEdgeCheckpointOnTwoRanksRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(
      kCase + kShort + " --set scheme.update=USF --set boundaries.1.edge_velocity=updated",
      "ckusf", 300, {0, 4}, 1e-10);
}

// Point probes on a grid line (the half-space example's surface receivers lie on the node
// lines x = 0.12 and 0.15): each rank finds a probe's cell from the whole grid's origin, so every
// rank sums the same four nodes. (From a window's own origin, x0 + i0 h, round-off put the
// point in the next cell on one rank and the receivers' histories came out wrong by up to
// their full amplitude on 2 ranks, while the energies agreed to the bit.) 2 and 4 ranks, every
// column within 1e-12 of one process's.
TEST(MpiCli, ProbesOnGridLinesAsOneProcess) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const std::string hs = source_file("examples/half-space.json") +
                         " --set time.end=1e-5 --set output.snapshots=0 -q";
  const fs::path a = out_dir("hs_plain");
  ASSERT_EQ(run(0, hs + " --out " + a.string(), "hs_plain").status, 0);
  for (const int np : {2, 4}) {
    const std::string tag = "hs_np" + std::to_string(np);
    const fs::path b = out_dir(tag);
    const Proc p = run(np, hs + " --out " + b.string(), tag);
    ASSERT_EQ(p.status, 0) << p.err;
    for (const auto& [c, d] : differences(b, a)) EXPECT_LE(d, 1e-12) << tag << ", column " << c;
  }
}

// The delayed closure at the silent edge (MUSL, 1 ppc): the ring of each edge node is state,
// kept on every rank that holds the node and checkpointed by its owner; the ranks other than 0
// start as skeletons, so the ring's length must not depend on a rank's particles. Plain on 2
// ranks and restarts on 1 process and on 4 ranks against the plain run.
TEST(MpiCli, DelayedEdgeOnRanksAndRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(kCase + kShort + " --set boundaries.1.edge_velocity=delayed",
                             "ckdelayed", 300, {0, 4}, 1e-10);
}

// The particle PML under MUSL (4 ppc; its particles take the layer's damping and their re-mapped
// momenta lose what they lost before the halo's sum, docs/physics.md section 9.3): plain on 2
// ranks and restarts on 1 process and on 3 ranks against the plain run.
TEST(MpiCli, MuslPmlOnRanksAndRestartsOnAnyCount) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  expect_checkpoint_restarts(
      kCase + " --set time.end=1.6e-5 -q --set bodies.0.particles_per_cell=4 --set "
              "'boundaries.2={\"type\": \"pml\", \"body\": \"plate\", \"curve\": \"right\", "
              "\"width\": 0.005, \"r0\": 0.01}'",
      "ckmuslpml", 150, {0, 3}, 1e-10);
}

// A restart on several ranks: rank 0 reads the whole checkpoint and the others what is not the
// particles', so rank 0's verdict is every rank's. A checkpoint with a corrupt byte, and one
// whose particle lies off the grid behind a recomputed checksum (which rank 0 alone sees), are
// each one error line on 2 ranks, the same as one process's, exit 1.
TEST(MpiCli, UnusableCheckpointIsOneProcessErrorOnRanks) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const std::string ck = kCase + kShort + " --set output.checkpoint_every=100";
  const fs::path a = out_dir("bad_ck");
  ASSERT_EQ(run(2, ck + " --out " + a.string(), "bad_ck").status, 0);
  const std::string bytes = case_testing::read_file(a / "checkpoint.smpm");
  auto write = [&](const std::string& b, const std::string& name) {
    const fs::path f = a / name;
    std::ofstream(f, std::ios::binary) << b;
    return f;
  };
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  std::string far = bytes;
  const std::string block = "mpm.p.x";
  const std::size_t at = far.find(block);
  ASSERT_NE(at, std::string::npos);
  const double x = 1e9;
  std::memcpy(&far[at + block.size() + 12], &x, 8);
  const std::uint64_t sum = state_hash(far.data(), far.size() - 8);
  std::memcpy(&far[far.size() - 8], &sum, 8);
  for (const auto& [file, message] :
       {std::pair{write(flipped, "flipped.smpm"), std::string("checksum mismatch")},
        std::pair{write(far, "far.smpm"), std::string("is not on the grid")}}) {
    const fs::path o = out_dir("bad_ck_run");
    const std::string args = ck + " --out " + o.string() + " --restart " + file.string();
    const Proc one = run(0, args, "bad_ck1");
    const Proc two = run(2, args, "bad_ck2");
    EXPECT_EQ(one.status, 1) << one.err;
    EXPECT_EQ(two.status, 1) << two.err;
    const std::string line = one.err.substr(0, one.err.find('\n'));
    EXPECT_NE(line.find(message), std::string::npos) << line;
    EXPECT_EQ(two.err.substr(0, two.err.find('\n')), line) << two.err;
    EXPECT_EQ(error_lines(two.err), 1u) << two.err;
  }
}

// The plate thrown upwards: its top rows leave the grid on the top rank only (20 steps); that
// rank's error ends both.
TEST(MpiCli, FailureOnOneRankStopsAllWithItsReason) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path o = out_dir("failed");
  const Proc p = run(2, kCase + kShort + " --set bodies.0.velocity=[0,3000] --out " + o.string(),
                     "failed");
  EXPECT_EQ(p.status, 2) << p.err;
  EXPECT_NE(p.err.find("silentmpm: error (rank 1 of 2): particle"), std::string::npos) << p.err;
  EXPECT_NE(case_testing::read_file(o / "RUN_INCOMPLETE").find("failed on rank 1 of 2: particle"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(o / "summary.json"));
}

// SIGTERM to mpirun, which passes it on to the ranks once the run is under way (history.csv has
// rows): every rank stops after the same step and the checkpoint is written, RUN_INCOMPLETE says
// how to continue, no summary.json. (The ranks' message may not get through mpirun, which is
// being signalled itself.)
TEST(MpiCli, InterruptStopsEveryRankAtOneStep) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path o = out_dir("interrupted");
  const std::string hist = (o / "history.csv").string();
  const std::string cmd =
      mpirun(2) + SMPM_CLI + " run " + kCase + " --set time.end=1e-3 --set output.snapshots=0 -q" +
      " --out " + o.string() + " & P=$!; for i in $(seq 600); do [ -f " + hist + " ] && [ $(wc -l < " +
      hist + ") -ge 4 ] && break; sleep 0.1; done; kill -TERM $P; wait $P";
  const Proc p = run_shell(cmd, "interrupted");
  const std::string why = case_testing::read_file(o / "RUN_INCOMPLETE");
  EXPECT_NE(why.find("interrupted by SIGTERM after step"), std::string::npos) << why << p.err;
  EXPECT_NE(why.find("continue with: mpirun -np 2"), std::string::npos) << why;
  EXPECT_TRUE(fs::exists(o / "checkpoint.smpm"));
  EXPECT_FALSE(fs::exists(o / "summary.json"));
}

}  // namespace
}  // namespace smpm::cli_testing
