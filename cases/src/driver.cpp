// The run loop: one for every case, over the region the case advances (run_loop.hpp).
#include "silentmpm/driver.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "driver_common.hpp"
#include "run_loop.hpp"
#include "silentmpm/output.hpp"

namespace smpm {

using detail::Clock;
using detail::seconds_since;

namespace {

RunResult run_region(const Case& c, detail::Region& region, const std::string& out_dir) {
  namespace fs = std::filesystem;
  const fs::path dir = detail::prepare_output_dir(out_dir);
  region.prepare(out_dir);

  const std::vector<std::string> cols = detail::history_columns(c.probes);
  detail::write_probe_table(dir, c.probes);
  HistoryWriter hist;
  hist.open((dir / "history.csv").string(), cols);
  std::vector<double> row(cols.size());
  auto record = [&]() {
    region.record(row);
    hist.row(region.time(), row);
  };

  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / region.dt() - 1e-9)));
  long snap_every = 0;
  if (c.output.snapshots > 0) {
    snap_every = std::max(1L, nsteps / c.output.snapshots);
    region.open_snapshots(out_dir);
  }
  const long hist_every = std::max(1L, c.output.history_every);

  const auto t_start = Clock::now();
  double step_seconds = 0;
  detail::Progress prog(c.output.progress, nsteps, region.progress_eta(), t_start);
  record();
  if (snap_every) region.write_snapshot(out_dir);
  for (long n = 1; n <= nsteps; ++n) {
    const auto t0 = Clock::now();
    region.step();
    step_seconds += seconds_since(t0);
    if (n % hist_every == 0 || n == nsteps) record();
    if (snap_every && (n % snap_every == 0 || n == nsteps)) region.write_snapshot(out_dir);
    prog.update(n);
  }
  hist.close();
  region.finish();

  RunResult r;
  r.steps = nsteps;
  r.wall_seconds = seconds_since(t_start);
  region.rates(r, step_seconds);

  nlohmann::ordered_json j =
      detail::summary_head(c, r, region.dt(), region.time(), region.cfl(), step_seconds);
  region.summary(j, r, snap_every != 0);
  detail::write_summary(dir, j);
  return r;
}

}  // namespace

RunResult run_case(Case& c, const std::string& out_dir) {
  const std::unique_ptr<detail::Region> region =
      c.hybrid     ? detail::hybrid_region(c)
      : c.solver   ? detail::mpm_region(c)
                   : detail::fem_region(c);
  return run_region(c, *region, out_dir);
}

}  // namespace smpm
