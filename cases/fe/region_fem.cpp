// The FEM region of the run loop (a case with an FEM region and no MPM bodies): probes sampled
// from the FE field, HDF5 + XDMF snapshots (fem.h5 + fem.xdmf). Under an MPI launcher the far
// field is split over the ranks (fem::Solver::distribute, localize; docs/parallel.md): every
// rank calls the same functions, rank 0 writes.
#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "driver_common.hpp"
#include "modules.hpp"
#include "run_loop.hpp"

namespace smpm::detail {

namespace {

class FemRegion final : public Region {
 public:
  explicit FemRegion(Case& c) : c_(c), s_(*c.fem) {
    if (mpi() && c.scattered) {  // built on rank 0, which sends each rank its part
      s_.distribute_from_root();
    } else if (mpi()) {  // not set up from rank 0 (one rank): the same part, kept from the whole
                         // model each rank built
      s_.distribute();
      s_.localize();
    }
  }

  double dt() const override { return s_.dt; }
  double time() const override { return s_.t; }
  double cfl() const override { return s_.dt / s_.critical_dt(); }
  const char* kind() const override { return "fem"; }
  int threads() const override { return s_.thread_count(); }
  long steps() const override { return s_.steps; }
  void prepare(const std::string& out_dir, bool resuming) override {
    remove_fem_snapshots(out_dir, resuming ? s_.snapshot_count() : 0);
  }

  void step() override { s_.step(); }

  void record(std::vector<double>& row) override {
    const auto samples = s_.sample();
    s_.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c_.probes.size(); ++q)
      for (const auto& f : c_.probes[q].fields) row[k++] = probe_field(samples[q], f);
    put_energies(s_.energy, row, k);
    if (!energies_finite(s_.energy))
      throw std::runtime_error("the FEM run diverged at step " + std::to_string(s_.steps) +
                               ": energy is not finite");
    check_energy_bound(s_.energy, "FEM", s_.steps, s_.t);
  }

  void save(StateWriter& w) const override { s_.save_state(w, "fem."); }
  std::vector<std::string> blocks_from_root() const override {
    return mpi() ? fem::Solver::blocks_from_root("fem.") : std::vector<std::string>{};
  }
  bool restore(const StateReader& r) override {
    s_.load_state(r, "fem.");
    return true;
  }

  void open_snapshots(const std::string& out_dir) override {
    s_.set_snapshot_compression(c_.output.compression);
    s_.resume_snapshots(out_dir, "fem");
  }
  void write_snapshot(const std::string& out_dir) override { s_.write_snapshot(out_dir, "fem"); }
  void finish() override {
    s_.close_snapshots();
    s_.update_energies();
  }

  void rates(RunResult& r, long steps_run, double step_seconds) const override {
    r.dofs = s_.dofs();
    r.dof_updates_per_second =
        static_cast<double>(s_.dofs()) * steps_run / std::max(step_seconds, 1e-12);
  }

  void summary(nlohmann::ordered_json& j, const RunResult& r, bool snapshots) const override {
    j["particles"] = 0;
    j["particle_updates_per_second"] = 0;
    j["dofs"] = r.dofs;
    j["dof_updates_per_second"] = r.dof_updates_per_second;
    j["threads"] = s_.thread_count();
    if (mpi()) {  // the ghost updates (every rank takes part)
      j["mpi_ranks"] = s_.ranks();
      j["mpi"] = fem_traffic_json(s_);
    }
    j["fem"] = fem_json(s_);
    j["energy"] = energy_json(s_.energy);
    j["model"] = c_.notes;
    j["outputs"] = {{"history", "history.csv"},
                    {"probes", "probes.csv"},
                    {"snapshots", s_.snapshot_count()},
                    {"xdmf", snapshots ? "fem.xdmf" : ""}};
  }

 private:
  Case& c_;
  fem::Solver& s_;
};

}  // namespace

std::unique_ptr<Region> fem_region(Case& c) { return std::make_unique<FemRegion>(c); }

}  // namespace smpm::detail
