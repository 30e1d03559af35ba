// Run loop of a hybrid (MPM + FEM) case: the outputs of the MPM and FEM drivers in one run —
// history.csv (probe fields, each probe read from the region holding its point, then the energy
// terms of both regions summed), particle snapshots (particles.h5/.xdmf), FEM snapshots
// (fem_NNNNN.h5 + fem.xdmf), summary.json (written last).

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "case_fem.hpp"
#include "driver_common.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

RunResult run_hybrid_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  Hybrid& hy = *c.hybrid;
  Solver& s = *c.solver;
  fem::Solver& fe = *c.fem;
  const fs::path dir = prepare_output_dir(out_dir);
  std::error_code ec;
  fs::remove(dir / "fem.xdmf", ec);

  std::vector<std::array<double, 2>> pts;
  std::vector<int> bodies;
  for (const auto& pr : c.probes) {
    if (pr.fem_index < 0) {
      pts.push_back({pr.x, pr.y});
      bodies.push_back(pr.body);
    }
  }
  const std::vector<std::string> cols = history_columns(c.probes);
  write_probe_table(dir, c.probes);
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
        for (const auto& f : pr.fields) row[k++] = probe_field(sm, f);
      } else {
        for (const auto& f : pr.fields) row[k++] = probe_field(fs_[pr.fem_index], f);
      }
    }
    put_energies(hy.energy, row, k);
    if (!energies_finite(hy.energy))
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

  const auto t_start = Clock::now();
  double step_seconds = 0;
  Progress prog(c.output.progress, nsteps, /*eta=*/false, t_start);
  record();
  if (snap_every) {
    snap.write(s.p, s.steps, s.t);
    fe.write_snapshot(out_dir, "fem");
  }
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    hy.step();
    step_seconds += seconds_since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) {
      snap.write(s.p, s.steps, s.t);
      fe.write_snapshot(out_dir, "fem");
    }
    prog.update(n);
  }
  hist.close();
  snap.close();
  hy.update_energies();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = seconds_since(t_start);
  r.particle_updates_per_second =
      static_cast<double>(s.p.size()) * nsteps / std::max(step_seconds, 1e-12);
  r.dofs = fe.dofs();
  r.dof_updates_per_second = static_cast<double>(fe.dofs()) * nsteps / std::max(step_seconds, 1e-12);

  nlohmann::ordered_json j = summary_head(c, r, dt, s.t, dt / hy.critical_dt(), step_seconds);
  j["particles"] = s.p.size();
  j["particle_updates_per_second"] = r.particle_updates_per_second;
  j["dofs"] = r.dofs;
  j["dof_updates_per_second"] = r.dof_updates_per_second;
  j["threads"] = s.thread_count();
  put_mpm_scheme(j, s);
  j["fem"] = fem_json(fe);
  j["hybrid"] = {{"shared_nodes", hy.shared().size()}, {"interface_nodes", hy.interface_nodes()}};
  j["energy"] = energy_json(hy.energy);
  j["energy_mpm"] = energy_json(s.energy);
  j["energy_fem"] = energy_json(fe.energy);
  j["energy_regions_note"] = "energy_mpm and energy_fem hold each region's own terms; their "
                             "imbalances are the energy that crossed the MPM-FEM interface and sum "
                             "to the total imbalance in energy";
  j["silent_boundaries"] = silents_json(s);
  j["loads"] = c.notes;
  j["bodies"] = bodies_json(c, s);
  j["curve_probes"] = curve_probes_json(c.probes);
  j["outputs"] = {{"history", "history.csv"},
                  {"probes", "probes.csv"},
                  {"snapshots", snap_every ? snap.count() : 0},
                  {"xdmf", snap_every ? "particles.xdmf" : ""},
                  {"fem_snapshots", fe.snapshot_count()},
                  {"fem_xdmf", snap_every ? "fem.xdmf" : ""}};
  write_summary(dir, j);
  return r;
}

}  // namespace smpm::detail
