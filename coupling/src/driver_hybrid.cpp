// Run loop of a hybrid (MPM + FEM) case: the outputs of the MPM and FEM drivers in one run —
// history.csv (probe fields, each probe read from the region holding its point, then the energy
// terms of both regions summed), particle snapshots (particles.h5/.xdmf), FEM snapshots
// (fem_NNNNN.h5 + fem.xdmf), summary.json (written last).
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

double mpm_field(const ProbeSample& s, const std::string& f) {
  if (f == "sxx") return s.sxx;
  if (f == "syy") return s.syy;
  if (f == "szz") return s.szz;
  if (f == "sxy") return s.sxy;
  if (f == "J2") return s.j2;
  if (f == "vx") return s.vx;
  if (f == "vy") return s.vy;
  throw std::runtime_error("unknown probe field " + f);
}

double fem_field(const fem::Sample& s, const std::string& f) {
  if (f == "div") return s.div;
  if (f == "curl") return s.curl;
  ProbeSample p;
  p.sxx = s.sxx; p.syy = s.syy; p.szz = s.szz; p.sxy = s.sxy; p.j2 = s.j2; p.vx = s.vx; p.vy = s.vy;
  return mpm_field(p, f);
}
}  // namespace

RunResult run_hybrid_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  Hybrid& hy = *c.hybrid;
  Solver& s = *c.solver;
  fem::Solver& fe = *c.fem;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create output directory: " + ec.message());
  const fs::path dir(out_dir);
  fs::remove(dir / "summary.json", ec);
  fs::remove(dir / "fem.xdmf", ec);

  std::vector<std::array<double, 2>> pts;
  std::vector<int> bodies;
  std::vector<std::string> cols;
  for (const auto& pr : c.probes) {
    if (pr.fem_index < 0) {
      pts.push_back({pr.x, pr.y});
      bodies.push_back(pr.body);
    }
    for (const auto& f : pr.fields) cols.push_back(pr.name + "." + f);
  }
  for (const char* e : {"kinetic", "elastic", "dissipated", "absorbed", "external_work", "imbalance"})
    cols.push_back(std::string("energy.") + e);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    const auto ms = s.sample(pts, bodies);
    const auto fs_ = fe.sample();
    hy.update_energies();
    std::size_t k = 0, q_mpm = 0;
    for (const auto& pr : c.probes) {
      if (pr.fem_index < 0) {
        const ProbeSample& sm = ms[q_mpm++];
        for (const auto& f : pr.fields) row[k++] = mpm_field(sm, f);
      } else {
        for (const auto& f : pr.fields) row[k++] = fem_field(fs_[pr.fem_index], f);
      }
    }
    const Energies& e = hy.energy;
    for (double v : {e.kinetic, e.elastic, e.dissipated, e.absorbed, e.external_work, e.imbalance()})
      row[k++] = v;
    if (!std::isfinite(e.kinetic) || !std::isfinite(e.elastic))
      throw std::runtime_error("the hybrid run diverged at step " + std::to_string(s.steps) +
                               " (t = " + std::to_string(s.t) + " s): energy is not finite");
    hist.row(s.t, row);
  };

  const double dt = hy.dt();
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / dt - 1e-9)));
  long snap_every = 0;
  SnapshotWriter snap;
  if (c.output.snapshots > 0) {
    snap_every = std::max(1L, nsteps / c.output.snapshots);
    snap.open(out_dir, "particles");
  }
  const long hist_every = std::max(1L, c.output.history_every);
  const bool tty = isatty(2);

  const auto t_start = Clock::now();
  double step_seconds = 0, last_print = 0;
  record();
  if (snap_every) {
    snap.write(s.p, s.steps, s.t);
    fe.write_snapshot(out_dir, "fem");
  }
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    hy.step();
    step_seconds += since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) {
      snap.write(s.p, s.steps, s.t);
      fe.write_snapshot(out_dir, "fem");
    }
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
  snap.close();
  hy.update_energies();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = since(t_start);
  r.particle_updates_per_second =
      static_cast<double>(s.p.size()) * nsteps / std::max(step_seconds, 1e-12);
  r.dofs = fe.dofs();
  r.dof_updates_per_second = static_cast<double>(fe.dofs()) * nsteps / std::max(step_seconds, 1e-12);

  nlohmann::ordered_json j;
  j["title"] = c.title;
  j["case"] = c.source;
  j["steps"] = r.steps;
  j["dt"] = dt;
  j["t_end"] = s.t;
  j["cfl"] = dt / hy.critical_dt();
  j["wall_seconds"] = r.wall_seconds;
  j["step_seconds"] = step_seconds;
  j["particles"] = s.p.size();
  j["particle_updates_per_second"] = r.particle_updates_per_second;
  j["dofs"] = r.dofs;
  j["dof_updates_per_second"] = r.dof_updates_per_second;
  j["threads"] = s.thread_count();
  j["scheme"] = scheme_name(s.opt.scheme);
  j["flip"] = s.opt.flip;
  j["grid"] = {{"origin", {s.grid.x0, s.grid.y0}}, {"cells", {s.grid.nx, s.grid.ny}}, {"cell", s.grid.h}};
  j["fem"] = {{"nodes", fe.nodes()},
              {"cells", fe.cells()},
              {"degree", fe.degree()},
              {"critical_dt", fe.critical_dt()},
              {"dashpot_nodes", fe.dashpots().size()}};
  j["hybrid"] = {{"shared_nodes", hy.shared().size()}, {"interface_nodes", hy.interface_nodes()}};
  auto energies = [](const Energies& e) {
    const double scale = std::max({std::abs(e.initial) + std::abs(e.external_work), 1e-300});
    return nlohmann::ordered_json{{"kinetic", e.kinetic},
                                  {"elastic", e.elastic},
                                  {"dissipated", e.dissipated},
                                  {"absorbed", e.absorbed},
                                  {"external_work", e.external_work},
                                  {"initial", e.initial},
                                  {"imbalance", e.imbalance()},
                                  {"relative_imbalance", e.imbalance() / scale}};
  };
  j["energy"] = energies(hy.energy);
  j["energy_mpm"] = energies(s.energy);
  j["energy_fem"] = energies(fe.energy);
  nlohmann::ordered_json sil = nlohmann::ordered_json::array();
  for (const auto& sl : s.silents)
    sil.push_back({{"name", sl.layer.name},
                   {"particles", sl.layer.idx.size()},
                   {"form", sl.form == SilentForm::Nodal ? "nodal" : "particle"},
                   {"a", sl.a},
                   {"b", sl.b},
                   {"layer_width", sl.layer.width}});
  j["silent_boundaries"] = sil;
  j["loads"] = c.notes;
  j["outputs"] = {{"history", "history.csv"},
                  {"snapshots", snap_every ? snap.count() : 0},
                  {"xdmf", snap_every ? "particles.xdmf" : ""},
                  {"fem_snapshots", fe.snapshot_count()},
                  {"fem_xdmf", snap_every ? "fem.xdmf" : ""}};
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
