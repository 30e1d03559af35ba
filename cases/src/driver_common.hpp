#pragma once
// Internal: the pieces the run loop (driver.cpp) and its three regions (region_mpm.cpp,
// region_fem.cpp, region_hybrid.cpp) share — output folder, history.csv columns and energy terms,
// probe fields, the progress line, and the blocks and writing of summary.json.
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "silentmpm/boundary.hpp"
#include "silentmpm/case.hpp"
#include "silentmpm/decomposition.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/output.hpp"
#include "silentmpm/state_io.hpp"

namespace smpm::detail {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0);

// Creates the output folder (throws if it cannot) and removes the files an earlier run left
// that this run owns (summary.json first: its presence marks a complete run; RUN_INCOMPLETE;
// history, probes, snapshots). A restart (resuming) keeps the snapshot files: the regions keep
// those of the steps before the checkpoint and drop the rest.
std::filesystem::path prepare_output_dir(const std::string& out_dir, bool resuming);
// Removes DIR/fem.xdmf, DIR/fem.h5 when keep is 0 (a restart keeps it), and the files of the
// earlier one-file-per-snapshot layout, DIR/fem_NNNNN.h5 with NNNNN >= keep.
void remove_fem_snapshots(const std::string& out_dir, int keep);

// The particle snapshots a checkpoint lists (the run before a restart), and how the regions
// save and reopen them.
struct SnapshotList {
  std::vector<long> steps;
  std::vector<double> times;
  std::vector<std::size_t> sizes;
  static SnapshotList read(const StateReader& r);
  // A restart: reopens the earlier file keeping these snapshots; else opens a new one.
  void open(SnapshotWriter& w, const std::string& out_dir) const;
};
void save_snapshot_list(StateWriter& w, const SnapshotWriter& snap);

// The MPM grid's snapshots (output.grid): DIR/grid.h5 + grid.xdmf, the grid's nodes and cells
// once, then per snapshot the particles projected onto the nodes (Solver::nodal_projection):
// mass, velocity (3-vector) and stress (3 x 3 tensor), J2 of that stress. Written beside the
// particle snapshots, at the same times.
class GridSnapshots {
 public:
  // `earlier`: the times of the snapshots before a restart (empty: a new file).
  void open(const Solver& s, const std::string& out_dir, int compression,
            const std::vector<double>& earlier);
  // The same for a grid of nx x ny cells of h from (x0, y0). Several ranks (comm: as
  // SnapshotWriter::set_ranks'): the whole grid's, every rank writing grid.h5 together, each
  // its own nodes {i0, i1, j0, j1} (inclusive, the whole grid's numbering) and their cells;
  // write() then takes those nodes' values, row by row.
  void open(double x0, double y0, double h, int nx, int ny, const std::string& out_dir,
            int compression, const std::vector<double>& earlier, const void* comm = nullptr,
            const void* info = nullptr, int rank = 0, std::array<int, 4> own = {});
  void write(const Solver& s);
  void write(double t, const Solver::NodalProjection& P);
  void close() { w_.close(); }
  int count() const { return w_.count(); }

 private:
  MeshSnapshotWriter w_;
};

// An MPM region's snapshots (the MPM and hybrid regions): the particles' (particles.h5 + .xdmf)
// with the fields and compression of the case's output section, the grid's beside them when the
// case asks (output.grid), and the list of them that a checkpoint carries.
class MpmSnapshots {
 public:
  void save(StateWriter& w) const { save_snapshot_list(w, snap_); }
  void restore(const StateReader& r) { earlier_ = SnapshotList::read(r); }
  void open(const Solver& s, const OutputSpec& out, const std::string& out_dir);
  void write(const Solver& s);
  // Several ranks (comm: SnapshotWriter::set_ranks'): every rank opens and writes particles.h5
  // together, each its particles as rows [offset, offset + p.size()) of `total`, and grid.h5
  // (output.grid; the whole grid's geometry), each the projection P on its own nodes `own`
  // (GridSnapshots::open; P may be null without output.grid).
  void open(const OutputSpec& out, const std::string& out_dir, double x0, double y0, double h,
            int nx, int ny, const void* comm, const void* info, int rank, std::array<int, 4> own);
  void write(const Particles& p, long step, double time, const std::vector<std::uint8_t>& layer,
             std::size_t offset, std::size_t total, const Solver::NodalProjection* P);
  void close();
  int count() const { return snap_.count(); }

 private:
  SnapshotWriter snap_;
  SnapshotList earlier_;  // a restart's snapshots of the run before it
  GridSnapshots grid_;    // output.grid
  bool grid_on_ = false;
};

// An MPM solver under an MPI launcher (the MPM and the hybrid regions): every rank built the
// whole case; each keeps its block once split() has cut it (docs/parallel.md). Every rank writes
// its particles into the one snapshot file; counts and energies are summed over the ranks. On one process
// nothing is cut and every call is the solver's own.
class MpmRanks {
 public:
  // `scattered`: rank 0 holds the whole body and the other ranks a skeleton (load_case_on_ranks);
  // the split sends each rank its block.
  MpmRanks(Solver& s, int across, bool scattered = false);
  // Cuts the solver to this rank's block, once (nothing on one process); true when it cut now.
  bool split();
  Decomposition* dist() const { return dist_.get(); }
  bool several() const;  // split over more than one rank
  // After a whole checkpoint was read and split() cut it: the energy account's booked terms
  // (as read, in `whole`) stay with rank 0; each rank's kinetic and elastic energy are its
  // particles'.
  void keep_account_on_root(const Energies& whole);
  void open_snapshots(MpmSnapshots& snaps, const OutputSpec& out, const std::string& out_dir);
  // Every rank calls it: each writes its particles into particles.h5 (rank by rank, in the
  // ranks' order) and the grid's projection on its own nodes into grid.h5.
  void write_snapshot(MpmSnapshots& snaps, bool grid);
  void close_snapshots(MpmSnapshots& snaps);
  double total(double v) const;  // summed over the ranks (itself on one process)
  // summary.json: "mpi_ranks", "mpi_ranks_across" and "mpi" (the halo sums' and migrations'
  // time and bytes per step, over the `steps` this run made), when split; every rank calls it.
  void put_traffic(nlohmann::ordered_json& j, long steps) const;
  // The whole grid's geometry: "origin", "cells", "cell".
  nlohmann::ordered_json grid_json() const;
  // The particle counts of the "bodies" and "silent_boundaries" blocks, summed over the ranks.
  void total_counts(nlohmann::ordered_json& j) const;

 private:
  Solver& s_;
  struct {
    double x0, y0, h;
    int nx, ny;
  } whole_;  // the grid of the whole case (a rank's solver holds its window of it)
  int across_ = 0;
  bool scattered_ = false;
  std::unique_ptr<Decomposition> dist_;
};

// Writes `bytes` to `dst` whole or not at all: a temporary file beside it, every write, the
// flush, fsync and close checked, then a rename. Throws naming dst and the cause.
void write_file_atomically(const std::filesystem::path& dst, const std::string& bytes);

// history.csv columns: "<probe>.<field>" for every probe, then "energy.<term>".
std::vector<std::string> history_columns(const std::vector<ProbeSpec>& probes);
// Writes the energy terms of history.csv into row[k...], advancing k.
void put_energies(const Energies& e, std::vector<double>& row, std::size_t& k);
inline bool energies_finite(const Energies& e) {
  return std::isfinite(e.kinetic) && std::isfinite(e.elastic);
}
// The FE far field's and the hybrid's check at each history row, as the MPM step's own: a run
// whose kinetic energy exceeds 10 times the energy put in (initial + |external work|) has blown
// up. Throws naming the step and the time.
inline void check_energy_bound(const Energies& e, const char* what, long step, double t) {
  const double put_in = e.initial + std::abs(e.external_work);
  if (!(e.kinetic > 10 * put_in)) return;
  std::ostringstream o;
  o << "the " << what << " run is unstable at step " << step << " (t = " << t << " s): kinetic energy "
    << e.kinetic << " J exceeds 10 times the energy put in (" << put_in << " J: initial "
    << e.initial << ", external work " << e.external_work
    << ") (reduce time.cfl or time.dt; " << kPmlGrowthHint << ")";
  throw std::runtime_error(o.str());
}

// One probe field ("sxx", "syy", "szz", "sxy", "J2", "vx", "vy"; FEM samples also "div", "curl").
double probe_field(const ProbeSample& s, const std::string& f);
double probe_field(const fem::Sample& s, const std::string& f);

// The progress line on stderr (a carriage-return line on a terminal, else a line every 5 s).
// With eta, the MPM form: "... steps/s  N s left", and the last step is always reported; without,
// the FEM / hybrid form: no estimate, and runs shorter than 2 s print nothing.
// The progress line: percent, step, the stepping rate (steps over the time spent in the steps
// alone, not in set-up or output) and the time left (the remaining steps at the pace of the run
// so far, output included). Quiet for the first 2 s.
class Progress {
 public:
  // `first`: the step the run starts from (a restart's checkpoint), so rates count this run's steps.
  Progress(bool on, long total, Clock::time_point t0 = Clock::now(), long first = 0);
  // step_seconds: the time spent in this run's steps so far.
  void update(long step, double step_seconds);

 private:
  bool on_;
  long total_, first_;
  bool tty_;
  Clock::time_point t0_;
  double last_ = 0;
};

// summary.json blocks. The head: "title", "case", "steps", "dt", "t_end", "cfl", "wall_seconds",
// "step_seconds" (each region adds its own keys after these).
nlohmann::ordered_json summary_head(const Case& c, const RunResult& r, double dt, double t_end,
                                    double cfl, double step_seconds);
nlohmann::ordered_json energy_json(const Energies& e);       // "energy"
nlohmann::ordered_json silents_json(const Solver& s);        // "silent_boundaries"
nlohmann::ordered_json fem_json(const fem::Solver& s);       // "fem"
// The FE far field's ghost updates over ranks (collective when it is split): time and bytes
// per step, the largest rank's counts.
nlohmann::ordered_json fem_traffic_json(const fem::Solver& s);
void put_mpm_scheme(nlohmann::ordered_json& j, const Solver& s);  // "scheme", "flip", "grid"
// DIR/probes.csv: one row per probe column group of history.csv, "name,x,y,along,s" (along: the
// probe along a curve a point belongs to, s its arc length; empty for a point probe).
void write_probe_table(const std::filesystem::path& dir, const std::vector<ProbeSpec>& probes);
nlohmann::ordered_json curve_probes_json(const std::vector<ProbeSpec>& probes);  // "curve_probes"
nlohmann::ordered_json bodies_json(const Case& c, const Solver& s);              // "bodies"
// The MPM region's blocks of summary.json that follow its energies (the MPM and the hybrid
// regions): "silent_boundaries", "loads", "bodies" (counts summed over the ranks) and
// "curve_probes". Every rank calls it.
void put_mpm_blocks(nlohmann::ordered_json& j, const Case& c, const Solver& s, const MpmRanks& ranks);
// Writes DIR/summary.json through a temporary file, so that it appears complete or not at all.
void write_summary(const std::filesystem::path& dir, const nlohmann::ordered_json& j);

}  // namespace smpm::detail
