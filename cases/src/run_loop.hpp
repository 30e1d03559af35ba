#pragma once
// Internal: the run loop of every case (driver.cpp) and the regions it steps. A region is what a
// case advances in time: the MPM bodies (region_mpm.cpp), the FEM far field (region_fem.cpp) or
// both coupled (region_hybrid.cpp; the last two in cases/fe/, the far-field module). The loop owns the output folder, history.csv, probes.csv, the
// step loop with its progress line and summary.json; a region samples its probes and energies,
// writes its own snapshots and adds its blocks to summary.json.
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/state_io.hpp"

namespace smpm::detail {

class Region {
 public:
  virtual ~Region() = default;

  virtual double dt() const = 0;
  virtual double time() const = 0;  // the time of a history row
  // dt over the region's stability limit (summary.json "cfl").
  virtual double cfl() const = 0;
  // Called once the output folder exists (removes stale files of the region's own outputs; on a
  // restart, resuming, only those written after the checkpoint).
  virtual void prepare(const std::string& /*out_dir*/, bool /*resuming*/) {}
  virtual const char* kind() const = 0;  // "mpm", "fem", "hybrid" (checkpoints record it)
  virtual int threads() const = 0;
  virtual long steps() const = 0;        // steps taken since t = 0

  virtual void step() = 0;
  // One history row: the probe columns in the order of Case::probes, then the energy terms.
  // Throws std::runtime_error when the energy is not finite (the run diverged).
  virtual void record(std::vector<double>& row) = 0;
  // Checkpoints: the region's state (and its snapshot lists). restore() is called on a region
  // built from the same case, before the output folder is touched; it returns false when the
  // continuation sums over particles in another order (another thread count). Throws StateError.
  virtual void save(StateWriter& w) const = 0;
  virtual bool restore(const StateReader& r) = 0;
  // A restart on several ranks of a case set up from rank 0: the blocks (name prefixes) that
  // restore() reads on rank 0 alone, which sends each rank its part of them itself; the other
  // ranks receive the checkpoint without them.
  virtual std::vector<std::string> blocks_from_root() const { return {}; }
  // Snapshots (only when the case asks for them): opened before the first one is written; after
  // restore(), the earlier run's snapshots in the folder are kept and listed again.
  virtual void open_snapshots(const std::string& out_dir) = 0;
  virtual void write_snapshot(const std::string& out_dir) = 0;
  // After the last step: closes the snapshots and brings the energies up to date.
  virtual void finish() = 0;

  // RunResult's rates from the steps taken in this process and the time spent in step().
  virtual void rates(RunResult& r, long steps_run, double step_seconds) const = 0;
  // summary.json after the common head; `snapshots`: whether the run wrote snapshots.
  virtual void summary(nlohmann::ordered_json& j, const RunResult& r, bool snapshots) const = 0;
};

// `across`: ranks across x under an MPI launcher (RunOptions::ranks_across); `resuming`: a
// restart will load the state (the region is cut into blocks after it, else at once, so that a
// layout the ranks cannot form is an error before the run).
std::unique_ptr<Region> mpm_region(Case& c, int across = 0, bool resuming = false);  // region_mpm.cpp
// In the far-field module (cases/fe/; the core reaches them through modules.hpp).
std::unique_ptr<Region> fem_region(Case& c);     // region_fem.cpp
// The hybrid: `across` and `resuming` as for mpm_region (the grid's blocks).
std::unique_ptr<Region> hybrid_region(Case& c, int across = 0, bool resuming = false);  // region_hybrid.cpp

}  // namespace smpm::detail
