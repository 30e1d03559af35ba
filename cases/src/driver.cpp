#include "silentmpm/driver.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "case_fem.hpp"
#include "driver_common.hpp"
#include "silentmpm/output.hpp"

namespace smpm {

using detail::Clock;
using detail::seconds_since;

RunResult run_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  if (!c.solver && c.fem) return detail::run_fem_case(c, out_dir);  // FEM-only case
  if (c.hybrid) return detail::run_hybrid_case(c, out_dir);         // driver_hybrid.cpp
  Solver& s = *c.solver;
  const fs::path dir = detail::prepare_output_dir(out_dir);

  // Probes and history columns.
  std::vector<std::array<double, 2>> pts;
  std::vector<int> probe_bodies;
  for (const auto& pr : c.probes) {
    pts.push_back({pr.x, pr.y});
    probe_bodies.push_back(pr.body);
  }
  const std::vector<std::string> cols = detail::history_columns(c.probes);
  detail::write_probe_table(dir, c.probes);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    const auto samples = s.sample(pts, probe_bodies);
    s.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c.probes.size(); ++q)
      for (const auto& f : c.probes[q].fields) row[k++] = detail::probe_field(samples[q], f);
    detail::put_energies(s.energy, row, k);
    if (!detail::energies_finite(s.energy))
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
  detail::Progress prog(c.output.progress, nsteps, /*eta=*/true);
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

  nlohmann::ordered_json j =
      detail::summary_head(c, r, s.dt, s.t, s.dt / s.critical_dt(), step_seconds);
  j["particles"] = s.p.size();
  j["particle_updates_per_second"] = r.particle_updates_per_second;
  j["threads"] = s.thread_count();
  detail::put_mpm_scheme(j, s);
  j["energy"] = detail::energy_json(s.energy);
  j["silent_boundaries"] = detail::silents_json(s);
  j["loads"] = c.notes;
  j["bodies"] = detail::bodies_json(c, s);
  j["curve_probes"] = detail::curve_probes_json(c.probes);
  j["outputs"] = {{"history", "history.csv"},
                  {"probes", "probes.csv"},
                  {"snapshots", snap_every ? snap.count() : 0},
                  {"xdmf", snap_every ? "particles.xdmf" : ""}};
  detail::write_summary(dir, j);
  return r;
}

}  // namespace smpm
