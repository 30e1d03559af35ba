// The MPM region of the run loop (a case with bodies and no FEM region): probes sampled from the
// particles, particle snapshots (particles.h5 + particles.xdmf). Under an MPI launcher the
// solver is cut into blocks (MpmRanks, shared with the hybrid region).
#include <algorithm>
#include <array>
#include <stdexcept>

#include "driver_common.hpp"
#include "run_loop.hpp"
#include "modules.hpp"
#include "silentmpm/output.hpp"

namespace smpm::detail {

// Solver::layer_flags uses the snapshot's layer bits.
static_assert(kLayerSilent == 1 && kLayerTraction == 2 && kLayerSpring == 4 &&
              kLayerDamping == 8 && kLayerPml == 16);

MpmRanks::MpmRanks(Solver& s, int across, bool scattered)
    : s_(s), whole_{s.grid.x0, s.grid.y0, s.grid.h, s.grid.nx, s.grid.ny}, across_(across),
      scattered_(scattered) {}

bool MpmRanks::split() {
  if (dist_ || !mpi()) return false;
  dist_ = mpi()->distribute(s_, across_, scattered_);
  return true;
}

bool MpmRanks::several() const { return dist_ && dist_->size() > 1; }

void MpmRanks::keep_account_on_root(const Energies& e) {
  if (!dist_) return;
  const bool root = dist_->rank() == 0;
  s_.energy.initial = root ? e.initial : 0.0;
  s_.energy.dissipated = root ? e.dissipated : 0.0;
  s_.energy.absorbed = root ? e.absorbed : 0.0;
  s_.energy.external_work = root ? e.external_work : 0.0;
}

void MpmRanks::open_snapshots(MpmSnapshots& snaps, const OutputSpec& out,
                              const std::string& out_dir) {
  if (!several()) return snaps.open(s_, out, out_dir);
  mpi()->any(false);  // every rank waits for rank 0 to have made the output folder
  snaps.open(out, out_dir, whole_.x0, whole_.y0, whole_.h, whole_.nx, whole_.ny, mpi()->world(),
             mpi()->no_info(), dist_->rank(), dist_->own_nodes());
}

void MpmRanks::write_snapshot(MpmSnapshots& snaps, bool grid) {
  if (!several()) return snaps.write(s_);
  // This rank's rows of the snapshot: after those of the ranks before it.
  std::vector<double> counts(static_cast<std::size_t>(dist_->size()), 0.0);
  counts[static_cast<std::size_t>(dist_->rank())] = static_cast<double>(s_.p.size());
  dist_->sum(counts.data(), static_cast<int>(counts.size()));
  std::size_t offset = 0, total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    if (static_cast<int>(r) == dist_->rank()) offset = total;
    total += static_cast<std::size_t>(counts[r]);
  }
  // The grid's projection (output.grid) on this rank's own nodes, row by row.
  Solver::NodalProjection P;
  if (grid) {
    const Solver::NodalProjection W = s_.nodal_projection();  // over the window
    const auto own = dist_->own_nodes();
    const auto org = dist_->window_origin();
    const long run = own[1] - own[0] + 1;  // each row of the block is a run of window nodes
    for (auto [to, from] : {std::pair{&P.mass, &W.mass}, {&P.vx, &W.vx}, {&P.vy, &W.vy},
                            {&P.sxx, &W.sxx}, {&P.syy, &W.syy}, {&P.szz, &W.szz},
                            {&P.sxy, &W.sxy}}) {
      to->reserve(static_cast<std::size_t>(run) * (own[3] - own[2] + 1));
      for (int j = own[2]; j <= own[3]; ++j) {
        const auto k = from->begin() + static_cast<long>(j - org[1]) * s_.grid.nnx + (own[0] - org[0]);
        to->insert(to->end(), k, k + run);
      }
    }
  }
  snaps.write(s_.p, s_.steps, s_.t, s_.layer_flags(), offset, total, grid ? &P : nullptr);
}

void MpmRanks::close_snapshots(MpmSnapshots& snaps) { snaps.close(); }

double MpmRanks::total(double v) const {
  if (dist_) dist_->sum(&v, 1);
  return v;
}

void MpmRanks::put_traffic(nlohmann::ordered_json& j, long steps) const {
  if (!dist_) return;
  // Communication per step: the slowest rank's seconds, every rank's bytes.
  const Decomposition::Traffic t = dist_->traffic();
  double slow[2] = {t.halo_seconds, t.migration_seconds};
  double bytes[3] = {t.halo_bytes, t.migration_bytes, static_cast<double>(t.particles_sent)};
  dist_->max(slow, 2);
  dist_->sum(bytes, 3);
  const double n = std::max(1.0, static_cast<double>(steps));
  j["mpi_ranks"] = dist_->size();
  j["mpi_ranks_across"] = dist_->across();
  j["mpi"] = {{"halo_seconds_per_step", slow[0] / n},
              {"migration_seconds_per_step", slow[1] / n},
              {"halo_bytes_per_step", bytes[0] / n},
              {"migration_bytes_per_step", bytes[1] / n},
              {"particles_migrated", bytes[2]}};
}

nlohmann::ordered_json MpmRanks::grid_json() const {
  return {{"origin", {whole_.x0, whole_.y0}}, {"cells", {whole_.nx, whole_.ny}}, {"cell", whole_.h}};
}

void MpmRanks::total_counts(nlohmann::ordered_json& j) const {
  if (!dist_) return;
  for (auto& sl : j["silent_boundaries"])
    sl["particles"] = static_cast<std::size_t>(total(sl["particles"].get<double>()));
  for (auto& b : j["bodies"])
    b["particles"] = static_cast<std::size_t>(total(b["particles"].get<double>()));
}

namespace {

class MpmRegion final : public Region {
 public:
  MpmRegion(Case& c, int across, bool resuming)
      : c_(c), s_(*c.solver), ranks_(s_, across, c.scattered) {
    for (const auto& pr : c.probes) {
      pts_.push_back({pr.x, pr.y});
      bodies_.push_back(pr.body);
    }
    // Under an MPI launcher every rank built the whole case; each keeps its block, now (a layout
    // the ranks cannot form is an error before the run) or after a restart has loaded the whole
    // body's state.
    if (!resuming) split();
  }

  // Cuts the solver to this rank's block, once (under an MPI launcher).
  void split() const { ranks_.split(); }

  double dt() const override { return s_.dt; }
  double time() const override { return s_.t; }
  double cfl() const override { return s_.dt / s_.critical_dt(); }
  const char* kind() const override { return "mpm"; }
  int threads() const override { return s_.thread_count(); }
  long steps() const override { return s_.steps; }

  void step() override {
    split();
    s_.step();
  }

  void record(std::vector<double>& row) override {
    split();
    auto samples = s_.sample(pts_, bodies_);
    s_.update_energies();
    std::size_t k = 0;
    for (std::size_t q = 0; q < c_.probes.size(); ++q) {
      const ProbeSpec& pr = c_.probes[q];
      if (pr.region) samples[q] = s_.region_mean(pr.rx0, pr.ry0, pr.rx1, pr.ry1, pr.body);
      for (const auto& f : pr.fields) row[k++] = probe_field(samples[q], f);
    }
    const Energies e = s_.total_energy();
    put_energies(e, row, k);
    if (!energies_finite(e))
      throw std::runtime_error("the run diverged at step " + std::to_string(s_.steps) + " (t = " +
                               std::to_string(s_.t) + " s): energy is not finite; reduce time.dt");
  }

  // Several ranks write one checkpoint of the whole body (each its own particles, at once),
  // which a restart on any number of ranks, or on one process, reads whole before it splits.
  void save(StateWriter& w) const override {
    split();
    if (ranks_.several()) s_.save_state_parts(w, "mpm.");
    else s_.save_state(w, "mpm.");
    snaps_.save(w);
  }
  // Set up from rank 0 (c.scattered): rank 0 loads the whole body, the others the clock and the
  // accounts; rank 0's error is every rank's; the split then sends each rank its particles.
  bool restore(const StateReader& r) override {
    snaps_.restore(r);
    const bool skeleton = c_.scattered && mpi() && mpi()->rank() != 0;
    bool same_order = false;
    std::string error;
    try {
      if (skeleton) s_.load_clock(r, "mpm.");
      else same_order = s_.load_state(r, "mpm.");
    } catch (const std::exception& e) {
      if (!c_.scattered || !mpi()) throw;
      error = e.what();
    }
    if (c_.scattered && mpi() && mpi()->any(!error.empty())) {
      std::string verdict = error;
      mpi()->broadcast(verdict);
      throw StateError(verdict.empty() ? r.file() + ": the checkpoint could not be read on rank " +
                                             std::to_string(mpi()->rank())
                                       : verdict);
    }
    if (!mpi()) return same_order;
    const Energies e = s_.energy;
    split();
    ranks_.keep_account_on_root(e);
    return false;  // the particles were re-cut into blocks and re-sorted
  }

  // Several ranks: every rank writes its particles into the one file (MpmRanks).
  void open_snapshots(const std::string& out_dir) override {
    split();
    ranks_.open_snapshots(snaps_, c_.output, out_dir);
  }
  void write_snapshot(const std::string&) override {
    split();
    ranks_.write_snapshot(snaps_, c_.output.grid);
  }
  void finish() override {
    split();
    ranks_.close_snapshots(snaps_);
    s_.update_energies();
  }

  void rates(RunResult& r, long steps_run, double step_seconds) const override {
    split();
    r.particles = static_cast<std::size_t>(ranks_.total(static_cast<double>(s_.p.size())));
    r.particle_updates_per_second =
        static_cast<double>(r.particles) * steps_run / std::max(step_seconds, 1e-12);
  }

  // Every rank calls it (the counts are sums over ranks); rank 0 writes it.
  void summary(nlohmann::ordered_json& j, const RunResult& r, bool snapshots) const override {
    j["particles"] = r.particles;
    j["particle_updates_per_second"] = r.particle_updates_per_second;
    j["threads"] = s_.thread_count();
    ranks_.put_traffic(j, r.steps_run);
    put_mpm_scheme(j, s_);
    j["grid"] = ranks_.grid_json();
    j["energy"] = energy_json(s_.total_energy());
    put_mpm_blocks(j, c_, s_, ranks_);
    j["outputs"] = {{"history", "history.csv"},
                    {"probes", "probes.csv"},
                    {"snapshots", snapshots ? snaps_.count() : 0},
                    {"xdmf", snapshots ? "particles.xdmf" : ""},
                    {"grid_xdmf", snapshots && c_.output.grid ? "grid.xdmf" : ""}};
  }

 private:
  Case& c_;
  Solver& s_;
  mutable MpmRanks ranks_;
  std::vector<std::array<double, 2>> pts_;
  std::vector<int> bodies_;
  MpmSnapshots snaps_;
};

}  // namespace

std::unique_ptr<Region> mpm_region(Case& c, int across, bool resuming) {
  return std::make_unique<MpmRegion>(c, across, resuming);
}

}  // namespace smpm::detail
