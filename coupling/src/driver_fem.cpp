// Run loop of a case with an FEM region (no MPM bodies): the same outputs as the MPM driver —
// history.csv (probe fields, then the energy terms), summary.json (written last), and HDF5 + XDMF
// snapshots through deal.II's DataOut (fem_NNNNN.h5 + fem.xdmf).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "case_fem.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double field(const fem::Sample& s, const std::string& f) {
  if (f == "sxx") return s.sxx;
  if (f == "syy") return s.syy;
  if (f == "szz") return s.szz;
  if (f == "sxy") return s.sxy;
  if (f == "J2") return s.j2;
  if (f == "vx") return s.vx;
  if (f == "vy") return s.vy;
  if (f == "div") return s.div;
  if (f == "curl") return s.curl;
  throw std::runtime_error("unknown probe field " + f);
}
}  // namespace

RunResult run_fem_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  fem::Solver& s = *c.fem;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create output directory: " + ec.message());
  const fs::path dir(out_dir);
  fs::remove(dir / "summary.json", ec);

  std::vector<std::string> cols;
  for (const auto& pr : c.probes)
    for (const auto& f : pr.fields) cols.push_back(pr.name + "." + f);
  for (const char* e : {"kinetic", "elastic", "dissipated", "absorbed", "external_work", "imbalance"})
    cols.push_back(std::string("energy.") + e);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    const auto samples = s.sample();
    s.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c.probes.size(); ++q)
      for (const auto& f : c.probes[q].fields) row[k++] = field(samples[q], f);
    const Energies& e = s.energy;
    for (double v : {e.kinetic, e.elastic, e.dissipated, e.absorbed, e.external_work, e.imbalance()})
      row[k++] = v;
    if (!std::isfinite(e.kinetic) || !std::isfinite(e.elastic))
      throw std::runtime_error("the FEM run diverged at step " + std::to_string(s.steps) +
                               ": energy is not finite");
    hist.row(s.t, row);
  };

  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / s.dt - 1e-9)));
  long snap_every = 0;
  if (c.output.snapshots > 0) snap_every = std::max(1L, nsteps / c.output.snapshots);
  for (const auto& old : {"fem.xdmf"}) fs::remove(dir / old, ec);
  const long hist_every = std::max(1L, c.output.history_every);
  const bool tty = isatty(2);

  const auto t_start = Clock::now();
  double step_seconds = 0, last_print = 0;
  record();
  if (snap_every) s.write_snapshot(out_dir, "fem");
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    s.step();
    step_seconds += since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) s.write_snapshot(out_dir, "fem");
    if (c.output.progress) {
      const double el = since(t_start);
      if (el > 2.0 && (el - last_print >= (tty ? 0.5 : 5.0) || n == nsteps)) {
        last_print = el;
        std::fprintf(stderr, "%s  %5.1f%%  step %ld/%ld  %.0f steps/s%s", tty ? "\r" : "",
                     100.0 * n / nsteps, n, nsteps, n / el, tty ? "   " : "\n");
        if (n == nsteps && tty) std::fprintf(stderr, "\n");
      }
    }
  }
  hist.close();
  s.update_energies();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = since(t_start);
  r.dofs = s.dofs();
  r.dof_updates_per_second = static_cast<double>(s.dofs()) * nsteps / std::max(step_seconds, 1e-12);

  nlohmann::ordered_json j;
  j["title"] = c.title;
  j["case"] = c.source;
  j["steps"] = r.steps;
  j["dt"] = s.dt;
  j["t_end"] = s.t;
  j["cfl"] = s.dt / s.critical_dt();
  j["wall_seconds"] = r.wall_seconds;
  j["step_seconds"] = step_seconds;
  j["particles"] = 0;
  j["particle_updates_per_second"] = 0;
  j["dofs"] = r.dofs;
  j["dof_updates_per_second"] = r.dof_updates_per_second;
  j["threads"] = s.thread_count();
  j["fem"] = {{"nodes", s.nodes()},
              {"cells", s.cells()},
              {"degree", s.degree()},
              {"critical_dt", s.critical_dt()},
              {"dashpot_nodes", s.dashpots().size()}};
  const Energies& e = s.energy;
  const double scale = std::max({std::abs(e.initial) + std::abs(e.external_work), 1e-300});
  j["energy"] = {{"kinetic", e.kinetic},
                 {"elastic", e.elastic},
                 {"dissipated", e.dissipated},
                 {"absorbed", e.absorbed},
                 {"external_work", e.external_work},
                 {"initial", e.initial},
                 {"imbalance", e.imbalance()},
                 {"relative_imbalance", e.imbalance() / scale}};
  j["model"] = c.notes;
  j["outputs"] = {{"history", "history.csv"},
                  {"snapshots", s.snapshot_count()},
                  {"xdmf", snap_every ? "fem.xdmf" : ""}};
  const fs::path tmp = dir / "summary.json.tmp";
  {
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error((dir / "summary.json").string() + ": cannot write");
    f << std::setw(2) << j << "\n";
  }
  fs::rename(tmp, dir / "summary.json");
  return r;
}

}  // namespace smpm::detail
