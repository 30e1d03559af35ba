#include "silentmpm/driver.hpp"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "case_fem.hpp"
#include "silentmpm/output.hpp"

namespace smpm {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double probe_field(const ProbeSample& s, const std::string& f) {
  if (f == "sxx") return s.sxx;
  if (f == "syy") return s.syy;
  if (f == "szz") return s.szz;
  if (f == "sxy") return s.sxy;
  if (f == "J2") return s.j2;
  if (f == "vx") return s.vx;
  if (f == "vy") return s.vy;
  throw std::runtime_error("unknown probe field " + f);
}

class Progress {
 public:
  Progress(bool on, long total) : on_(on), total_(total), tty_(isatty(2)), t0_(Clock::now()) {}
  void update(long step) {
    if (!on_) return;
    const double el = seconds_since(t0_);
    if (el - last_ < (tty_ ? 0.5 : 5.0) && step < total_) return;
    if (el < 2.0 && step < total_) return;  // short runs stay quiet
    last_ = el;
    const double rate = step / std::max(el, 1e-9);
    const double left = (total_ - step) / std::max(rate, 1e-9);
    std::fprintf(stderr, "%s  %5.1f%%  step %ld/%ld  %.0f steps/s  %.1f s left%s",
                 tty_ ? "\r" : "", 100.0 * step / total_, step, total_, rate, left,
                 tty_ ? "   " : "\n");
    if (step >= total_ && tty_) std::fprintf(stderr, "\n");
  }

 private:
  bool on_;
  long total_;
  bool tty_;
  Clock::time_point t0_;
  double last_ = 0;
};

}  // namespace

RunResult run_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  if (!c.solver && c.fem) return detail::run_fem_case(c, out_dir);  // FEM-only case
  if (c.hybrid) return detail::run_hybrid_case(c, out_dir);         // driver_hybrid.cpp
  Solver& s = *c.solver;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create output directory: " + ec.message());
  const fs::path dir(out_dir);
  fs::remove(dir / "summary.json", ec);  // its presence marks a complete run

  // Probes and history columns.
  std::vector<std::array<double, 2>> pts;
  std::vector<int> probe_bodies;
  std::vector<std::string> cols;
  for (const auto& pr : c.probes) {
    pts.push_back({pr.x, pr.y});
    probe_bodies.push_back(pr.body);
    for (const auto& f : pr.fields) cols.push_back(pr.name + "." + f);
  }
  for (const char* e : {"kinetic", "elastic", "dissipated", "absorbed", "external_work", "imbalance"})
    cols.push_back(std::string("energy.") + e);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    const auto samples = s.sample(pts, probe_bodies);
    s.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c.probes.size(); ++q)
      for (const auto& f : c.probes[q].fields) row[k++] = probe_field(samples[q], f);
    const Energies& e = s.energy;
    for (double v : {e.kinetic, e.elastic, e.dissipated, e.absorbed, e.external_work, e.imbalance()})
      row[k++] = v;
    if (!std::isfinite(e.kinetic) || !std::isfinite(e.elastic))
      throw std::runtime_error("the run diverged at step " + std::to_string(s.steps) + " (t = " +
                               std::to_string(s.t) + " s): energy is not finite; reduce time.dt");
    hist.row(s.t, row);
  };

  SnapshotWriter snap;
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / s.dt - 1e-9)));
  long snap_every = 0;
  if (c.output.snapshots > 0) {
    snap.open(out_dir, "particles");
    snap_every = std::max(1L, nsteps / c.output.snapshots);
  }
  const long hist_every = std::max(1L, c.output.history_every);

  const auto t_start = Clock::now();
  double step_seconds = 0;
  Progress prog(c.output.progress, nsteps);
  record();
  if (snap_every) snap.write(s.p, s.steps, s.t);
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    s.step();
    step_seconds += seconds_since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) snap.write(s.p, s.steps, s.t);
    prog.update(n);
  }
  hist.close();
  snap.close();
  s.update_energies();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = seconds_since(t_start);
  r.particle_updates_per_second = static_cast<double>(s.p.size()) * nsteps / std::max(step_seconds, 1e-12);

  nlohmann::ordered_json j;
  j["title"] = c.title;
  j["case"] = c.source;
  j["steps"] = r.steps;
  j["dt"] = s.dt;
  j["t_end"] = s.t;
  j["cfl"] = s.dt / s.critical_dt();
  j["wall_seconds"] = r.wall_seconds;
  j["step_seconds"] = step_seconds;
  j["particles"] = s.p.size();
  j["particle_updates_per_second"] = r.particle_updates_per_second;
  j["threads"] = s.thread_count();
  j["scheme"] = scheme_name(s.opt.scheme);
  j["flip"] = s.opt.flip;
  j["grid"] = {{"origin", {s.grid.x0, s.grid.y0}}, {"cells", {s.grid.nx, s.grid.ny}}, {"cell", s.grid.h}};
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
                  {"xdmf", snap_every ? "particles.xdmf" : ""}};
  const fs::path tmp = dir / "summary.json.tmp";
  {
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error((dir / "summary.json").string() + ": cannot write");
    f << std::setw(2) << j << "\n";
  }
  fs::rename(tmp, dir / "summary.json");
  return r;
}

}  // namespace smpm
