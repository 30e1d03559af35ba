// The hybrid region of the run loop (MPM + FEM coupled): each probe read from the region holding
// its point, the energy terms of both regions summed, particle snapshots (particles.h5/.xdmf) and
// FEM snapshots (fem.h5 + fem.xdmf), both regions' blocks in summary.json. Under an MPI launcher
// the grid is cut into blocks (MpmRanks), the far field by METIS (fem::Solver::distribute), and
// the coupling sums its interface over the ranks (Hybrid::distribute; docs/parallel.md).
#include <algorithm>
#include <array>
#include <filesystem>
#include <stdexcept>

#include "driver_common.hpp"
#include "modules.hpp"
#include "run_loop.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

namespace {

class HybridRegion final : public Region {
 public:
  HybridRegion(Case& c, int across, bool resuming)
      : c_(c), hy_(*c.hybrid), s_(*c.solver), fe_(*c.fem), ranks_(s_, across) {
    for (const auto& pr : c.probes) {
      if (pr.fem_index < 0) {
        pts_.push_back({pr.x, pr.y});
        bodies_.push_back(pr.body);
      }
    }
    // As the MPM region: split now, or after a restart has read the whole state.
    if (!resuming) split();
  }

  // Under an MPI launcher, once: the grid into blocks, the far field by METIS, the interface.
  void split() const {
    if (!ranks_.split()) return;
    fe_.distribute();
    hy_.distribute(*ranks_.dist());
  }

  double dt() const override { return hy_.dt(); }
  double time() const override { return s_.t; }
  double cfl() const override { return hy_.dt() / hy_.critical_dt(); }
  const char* kind() const override { return "hybrid"; }
  int threads() const override { return s_.thread_count(); }
  long steps() const override { return s_.steps; }
  void prepare(const std::string& out_dir, bool resuming) override {
    remove_fem_snapshots(out_dir, resuming ? fe_.snapshot_count() : 0);
  }

  void step() override {
    split();
    hy_.step();
  }

  void record(std::vector<double>& row) override {
    split();
    const auto ms = s_.sample(pts_, bodies_);
    const auto fs = fe_.sample();
    hy_.update_energies();
    std::size_t k = 0, q_mpm = 0;
    for (const auto& pr : c_.probes) {
      if (pr.fem_index < 0) {
        const ProbeSample sm =
            pr.region ? s_.region_mean(pr.rx0, pr.ry0, pr.rx1, pr.ry1, pr.body) : ms[q_mpm];
        ++q_mpm;
        for (const auto& f : pr.fields) row[k++] = probe_field(sm, f);
      } else {
        for (const auto& f : pr.fields) row[k++] = probe_field(fs[pr.fem_index], f);
      }
    }
    put_energies(hy_.energy, row, k);
    if (!energies_finite(hy_.energy))
      throw std::runtime_error("the hybrid run diverged at step " + std::to_string(s_.steps) +
                               " (t = " + std::to_string(s_.t) + " s): energy is not finite");
    check_energy_bound(hy_.energy, "hybrid", s_.steps, s_.t);
  }

  // Several ranks: one process's checkpoint, written by every rank at once (Hybrid::save_state).
  void save(StateWriter& w) const override {
    split();
    hy_.save_state(w);
    snaps_.save(w);
  }
  bool restore(const StateReader& r) override {
    snaps_.restore(r);
    const bool same_order = hy_.load_state(r);
    if (!mpi()) return same_order;
    const Energies e = s_.energy;
    split();
    ranks_.keep_account_on_root(e);
    return false;  // the particles were re-cut into blocks and re-sorted
  }

  void open_snapshots(const std::string& out_dir) override {
    split();
    ranks_.open_snapshots(snaps_, c_.output, out_dir);
    fe_.set_snapshot_compression(c_.output.compression);
    fe_.resume_snapshots(out_dir, "fem");
  }
  void write_snapshot(const std::string& out_dir) override {
    split();
    ranks_.write_snapshot(snaps_, c_.output.grid);
    fe_.write_snapshot(out_dir, "fem");
  }
  void finish() override {
    split();
    ranks_.close_snapshots(snaps_);
    fe_.close_snapshots();
    hy_.update_energies();
  }

  void rates(RunResult& r, long steps_run, double step_seconds) const override {
    split();
    r.particles = static_cast<std::size_t>(ranks_.total(static_cast<double>(s_.p.size())));
    r.particle_updates_per_second =
        static_cast<double>(r.particles) * steps_run / std::max(step_seconds, 1e-12);
    r.dofs = fe_.dofs();
    r.dof_updates_per_second =
        static_cast<double>(fe_.dofs()) * steps_run / std::max(step_seconds, 1e-12);
  }

  // Every rank calls it (sums over the ranks); rank 0 writes it.
  void summary(nlohmann::ordered_json& j, const RunResult& r, bool snapshots) const override {
    j["particles"] = r.particles;
    j["particle_updates_per_second"] = r.particle_updates_per_second;
    j["dofs"] = r.dofs;
    j["dof_updates_per_second"] = r.dof_updates_per_second;
    j["threads"] = s_.thread_count();
    if (ranks_.dist()) {  // the grid's halo sums and migrations, the far field's ghost updates,
                          // the interface's sums (the slowest rank's seconds)
      ranks_.put_traffic(j, r.steps_run);
      j["mpi"]["fem"] = fem_traffic_json(fe_);
      double slow = hy_.interface_seconds();
      ranks_.dist()->max(&slow, 1);
      const double n = std::max(1.0, static_cast<double>(r.steps_run));
      j["mpi"]["interface_seconds_per_step"] = slow / n;
      j["mpi"]["interface_values_per_step"] = hy_.interface_values() / n;
    }
    put_mpm_scheme(j, s_);
    j["grid"] = ranks_.grid_json();  // the whole grid (a rank's solver holds its window)
    j["fem"] = fem_json(fe_);
    j["hybrid"] = {{"shared_nodes", hy_.shared().size()},
                   {"interface_nodes", hy_.interface_nodes()}};
    j["energy"] = energy_json(hy_.energy);
    j["energy_mpm"] = energy_json(hy_.mpm_energy());
    j["energy_fem"] = energy_json(fe_.energy);
    j["energy_regions_note"] = "energy_mpm and energy_fem hold each region's own terms; their "
                               "imbalances are the energy that crossed the MPM-FEM interface and "
                               "sum to the total imbalance in energy";
    put_mpm_blocks(j, c_, s_, ranks_);
    j["outputs"] = {{"history", "history.csv"},
                    {"probes", "probes.csv"},
                    {"snapshots", snapshots ? snaps_.count() : 0},
                    {"xdmf", snapshots ? "particles.xdmf" : ""},
                    {"fem_snapshots", fe_.snapshot_count()},
                    {"fem_xdmf", snapshots ? "fem.xdmf" : ""},
                    {"grid_xdmf", snapshots && c_.output.grid ? "grid.xdmf" : ""}};
  }

 private:
  Case& c_;
  Hybrid& hy_;
  Solver& s_;
  fem::Solver& fe_;
  mutable MpmRanks ranks_;
  std::vector<std::array<double, 2>> pts_;
  std::vector<int> bodies_;
  MpmSnapshots snaps_;
};

}  // namespace

std::unique_ptr<Region> hybrid_region(Case& c, int across, bool resuming) {
  return std::make_unique<HybridRegion>(c, across, resuming);
}

}  // namespace smpm::detail
