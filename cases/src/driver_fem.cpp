// Run loop of a case with an FEM region (no MPM bodies): the same outputs as the MPM driver —
// history.csv (probe fields, then the energy terms), summary.json (written last), and HDF5 + XDMF
// snapshots through deal.II's DataOut (fem_NNNNN.h5 + fem.xdmf).

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "case_fem.hpp"
#include "driver_common.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

RunResult run_fem_case(Case& c, const std::string& out_dir) {
  namespace fs = std::filesystem;
  fem::Solver& s = *c.fem;
  const fs::path dir = prepare_output_dir(out_dir);
  std::error_code ec;

  const std::vector<std::string> cols = history_columns(c.probes);
  write_probe_table(dir, c.probes);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    const auto samples = s.sample();
    s.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c.probes.size(); ++q)
      for (const auto& f : c.probes[q].fields) row[k++] = probe_field(samples[q], f);
    put_energies(s.energy, row, k);
    if (!energies_finite(s.energy))
      throw std::runtime_error("the FEM run diverged at step " + std::to_string(s.steps) +
                               ": energy is not finite");
    hist.row(s.t, row);
  };

  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / s.dt - 1e-9)));
  long snap_every = 0;
  if (c.output.snapshots > 0) snap_every = std::max(1L, nsteps / c.output.snapshots);
  for (const auto& old : {"fem.xdmf"}) fs::remove(dir / old, ec);
  const long hist_every = std::max(1L, c.output.history_every);

  const auto t_start = Clock::now();
  double step_seconds = 0;
  Progress prog(c.output.progress, nsteps, /*eta=*/false, t_start);
  record();
  if (snap_every) s.write_snapshot(out_dir, "fem");
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    s.step();
    step_seconds += seconds_since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) s.write_snapshot(out_dir, "fem");
    prog.update(n);
  }
  hist.close();
  s.update_energies();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = seconds_since(t_start);
  r.dofs = s.dofs();
  r.dof_updates_per_second = static_cast<double>(s.dofs()) * nsteps / std::max(step_seconds, 1e-12);

  nlohmann::ordered_json j = summary_head(c, r, s.dt, s.t, s.dt / s.critical_dt(), step_seconds);
  j["particles"] = 0;
  j["particle_updates_per_second"] = 0;
  j["dofs"] = r.dofs;
  j["dof_updates_per_second"] = r.dof_updates_per_second;
  j["threads"] = s.thread_count();
  j["fem"] = fem_json(s);
  j["energy"] = energy_json(s.energy);
  j["model"] = c.notes;
  j["outputs"] = {{"history", "history.csv"},
                  {"probes", "probes.csv"},
                  {"snapshots", s.snapshot_count()},
                  {"xdmf", snap_every ? "fem.xdmf" : ""}};
  write_summary(dir, j);
  return r;
}

}  // namespace smpm::detail
