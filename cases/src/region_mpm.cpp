// The MPM region of the run loop (a case with bodies and no FEM region): probes sampled from the
// particles, particle snapshots (particles.h5 + particles.xdmf).
#include <algorithm>
#include <array>
#include <stdexcept>

#include "driver_common.hpp"
#include "run_loop.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

// Solver::layer_flags uses the snapshot's layer bits.
static_assert(kLayerSilent == 1 && kLayerTraction == 2 && kLayerSpring == 4 &&
              kLayerDamping == 8 && kLayerPml == 16);

namespace {

class MpmRegion final : public Region {
 public:
  explicit MpmRegion(Case& c) : c_(c), s_(*c.solver) {
    for (const auto& pr : c.probes) {
      pts_.push_back({pr.x, pr.y});
      bodies_.push_back(pr.body);
    }
  }

  double dt() const override { return s_.dt; }
  double time() const override { return s_.t; }
  double cfl() const override { return s_.dt / s_.critical_dt(); }
  const char* kind() const override { return "mpm"; }
  int threads() const override { return s_.thread_count(); }
  long steps() const override { return s_.steps; }

  void step() override { s_.step(); }

  void record(std::vector<double>& row) override {
    auto samples = s_.sample(pts_, bodies_);
    s_.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c_.probes.size(); ++q) {
      const ProbeSpec& pr = c_.probes[q];
      if (pr.region) samples[q] = s_.region_mean(pr.rx0, pr.ry0, pr.rx1, pr.ry1, pr.body);
      for (const auto& f : pr.fields) row[k++] = probe_field(samples[q], f);
    }
    put_energies(s_.energy, row, k);
    if (!energies_finite(s_.energy))
      throw std::runtime_error("the run diverged at step " + std::to_string(s_.steps) + " (t = " +
                               std::to_string(s_.t) + " s): energy is not finite; reduce time.dt");
  }

  void save(StateWriter& w) const override {
    s_.save_state(w, "mpm.");
    snaps_.save(w);
  }
  bool restore(const StateReader& r) override {
    snaps_.restore(r);
    return s_.load_state(r, "mpm.");
  }

  void open_snapshots(const std::string& out_dir) override {
    snaps_.open(s_, c_.output, out_dir);
  }
  void write_snapshot(const std::string&) override {
    snaps_.write(s_);
  }
  void finish() override {
    snaps_.close();
    s_.update_energies();
  }

  void rates(RunResult& r, long steps_run, double step_seconds) const override {
    r.particle_updates_per_second =
        static_cast<double>(s_.p.size()) * steps_run / std::max(step_seconds, 1e-12);
  }

  void summary(nlohmann::ordered_json& j, const RunResult& r, bool snapshots) const override {
    j["particles"] = s_.p.size();
    j["particle_updates_per_second"] = r.particle_updates_per_second;
    j["threads"] = s_.thread_count();
    put_mpm_scheme(j, s_);
    j["energy"] = energy_json(s_.energy);
    j["silent_boundaries"] = silents_json(s_);
    j["loads"] = c_.notes;
    j["bodies"] = bodies_json(c_, s_);
    j["curve_probes"] = curve_probes_json(c_.probes);
    j["outputs"] = {{"history", "history.csv"},
                    {"probes", "probes.csv"},
                    {"snapshots", snapshots ? snaps_.count() : 0},
                    {"xdmf", snapshots ? "particles.xdmf" : ""},
                    {"grid_xdmf", snapshots && c_.output.grid ? "grid.xdmf" : ""}};
  }

 private:
  Case& c_;
  Solver& s_;
  std::vector<std::array<double, 2>> pts_;
  std::vector<int> bodies_;
  MpmSnapshots snaps_;
};

}  // namespace

std::unique_ptr<Region> mpm_region(Case& c) { return std::make_unique<MpmRegion>(c); }

}  // namespace smpm::detail
