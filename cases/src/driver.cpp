// The run loop: one for every case, over the region the case advances (run_loop.hpp), with its
// checkpoints, restarts and clean interrupts.
#include "silentmpm/driver.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "driver_common.hpp"
#include "modules.hpp"
#include "run_loop.hpp"
#include "silentmpm/output.hpp"
#include "silentmpm/state_io.hpp"

#ifndef SMPM_VERSION
#define SMPM_VERSION "unknown"
#endif

namespace smpm {

using detail::Clock;
using detail::seconds_since;

namespace {

namespace fs = std::filesystem;

// SIGINT / SIGTERM: the handler only records the signal; the loop stops after the step it is in.
// The handler is one-shot (SA_RESETHAND), so a second signal stops the process at once.
volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_stop_signal(int sig) { g_signal = sig; }

class SignalGuard {
 public:
  SignalGuard() {
    g_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

// A text file (the history so far) in one buffer the size of the file.
std::string read_whole(const fs::path& p) {
  std::error_code ec;
  const auto size = fs::file_size(p, ec);
  std::FILE* f = ec ? nullptr : std::fopen(p.c_str(), "rb");
  if (!f) throw std::runtime_error(p.string() + ": cannot read it");
  std::string s(size, '\0');
  const bool ok = std::fread(s.data(), 1, size, f) == size;
  std::fclose(f);
  if (!ok) throw std::runtime_error(p.string() + ": cannot read it");
  return s;
}

std::string hex(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

// Checks a checkpoint's run record against this case and restores the region. Returns the step
// it continues from and the history text written before it.
long restore_run(const Case& c, detail::Region& region, const std::string& file,
                 std::string& history, std::string& note) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw StateError(file + ": no such checkpoint file");
  // A case set up from rank 0 (load_case_on_ranks): rank 0 reads the whole checkpoint, the
  // others what is not the particles' or the far field's nodes' (the clock, the accounts, the
  // run record), which rank 0 sends them; rank 0's error is every rank's. The particles follow
  // with the split, the far field's nodal state in restore() (each rank its nodes').
  std::optional<StateReader> reader;
  if (process_count() > 1 && c.scattered) {
    std::string error, rest;
    if (process_rank() == 0) try {
        reader.emplace(StateReader::open(file));
        std::vector<std::string> skip = Solver::particle_blocks("mpm.");
        for (const auto& b : region.blocks_from_root()) skip.push_back(b);
        rest = reader->without(skip);
      } catch (const std::exception& e) {
        error = e.what();
      }
    detail::mpi()->broadcast(error);
    if (!error.empty()) throw StateError(error);
    detail::mpi()->broadcast(rest);
    if (process_rank() != 0) reader.emplace(std::move(rest), file);
  } else {
    reader.emplace(StateReader::open(file));
  }
  const StateReader& r = *reader;
  const std::string version = r.get_string("run.version");
  if (version != SMPM_VERSION)
    r.fail("written by silentmpm " + version + ", this is " + SMPM_VERSION +
           " (a checkpoint is read by the version that wrote it)");
  const std::string kind = r.get_string("run.kind");
  if (kind != region.kind())
    r.fail("a checkpoint of a run of kind \"" + kind + "\", this case is of kind \"" +
           region.kind() + "\"");
  const std::uint64_t fp = r.get<std::uint64_t>("run.fingerprint");
  if (fp != c.fingerprint)
    r.fail("written for another case (" + r.get_string("run.case") + ", fingerprint " + hex(fp) +
           "; this case " + hex(c.fingerprint) + "): only output.*, time.end and scheme.threads "
           "may change between a run and its restart");
  if (r.has("run.failed"))
    r.fail("the state of a step that failed (" + r.get_string("run.failed") + "), kept for "
           "inspection; restart from the last checkpoint of the run (" + checkpoint_file_name() +
           ") instead");
  history = r.get_string("run.history");
  const long step = static_cast<long>(r.get<std::int64_t>("run.step"));
  const int threads = r.get<std::int32_t>("run.threads");
  const bool same_order = region.restore(r);
  if (region.steps() != step) r.fail("step counts disagree (corrupt checkpoint)");
  if (process_count() > 1)
    note = "note: continuing on " + std::to_string(process_count()) + " MPI ranks from a checkpoint "
           "of the whole body, so sums run in another order and the history differs from an "
           "uninterrupted run in round-off";
  else if (!same_order || threads != region.threads())
    note = "note: continuing on " + std::to_string(region.threads()) + " thread(s); the checkpoint "
           "was written on " + std::to_string(threads) + ", so sums run in another order and the "
           "history differs from an uninterrupted run in round-off";
  return step;
}

// A checkpoint (DIR/checkpoint.smpm); with `failed` (the failure's message) the state of a failed
// step instead (DIR/failed.smpm), which a restart refuses.
// Several MPI ranks: every rank writes its share of the one file at once (the region puts its
// particles as parts of the blocks), rank 0 the rest.
void write_checkpoint(const Case& c, const detail::Region& region, const fs::path& dir,
                      HistoryWriter& hist, const std::string& failed = "") {
  const bool root = process_rank() == 0;
  hist.flush();
  StateWriter w;
  if (!failed.empty()) w.put_string("run.failed", failed);
  w.put_string("run.version", SMPM_VERSION);
  w.put_string("run.kind", region.kind());
  w.put_string("run.case", c.source);
  w.put("run.fingerprint", c.fingerprint);
  w.put("run.step", static_cast<std::int64_t>(region.steps()));
  w.put("run.threads", static_cast<std::int32_t>(region.threads()));
  if (root) w.put_string("run.history", read_whole(dir / "history.csv"));
  region.save(w);
  const fs::path file = dir / (failed.empty() ? checkpoint_file_name() : failed_state_file_name());
  if (process_count() > 1) detail::mpi()->write_state(w, file.string());
  else detail::write_file_atomically(file, w.bytes());
}

// After a step failed: its state, for inspection, as DIR/failed.smpm and (when the run writes
// snapshots) a last snapshot. Returns what was written, to append to the failure's message;
// a write that fails too is only named (the step's failure is the error to report).
std::string keep_failed_state(const Case& c, detail::Region& region, const fs::path& dir,
                              const std::string& out_dir, HistoryWriter& hist, bool snapshots,
                              const std::string& failure) {
  std::string kept;
  try {
    write_checkpoint(c, region, dir, hist, failure);
    kept = (dir / failed_state_file_name()).string();
  } catch (const std::exception& e) {
    kept = std::string("not written: ") + e.what();
  }
  std::string msg = "; the failed step's state: " + kept;
  if (snapshots) {
    try {
      region.write_snapshot(out_dir);
      msg += ", and the last snapshot";
    } catch (const std::exception& e) {
      msg += std::string(", snapshot not written: ") + e.what();
    }
  }
  return msg;
}

// DIR/RUN_INCOMPLETE: why the run stopped and how far it came (no summary.json is written).
void mark_incomplete(const fs::path& dir, const std::string& why) {
  try {
    detail::write_file_atomically(dir / "RUN_INCOMPLETE", why + "\n");
  } catch (const std::exception&) {
    // The run's own error is the one to report.
  }
}

RunResult run_region(const Case& c, detail::Region& region, const std::string& out_dir,
                     const RunOptions& opt) {
  // Several MPI ranks: every rank steps and samples (the samples are sums over ranks), rank 0
  // alone writes the folder and prints; every rank stops at the same step.
  const int ranks = process_count();
  const bool root = process_rank() == 0;
  std::string history, note;
  const long first = opt.restart.empty() ? 0 : restore_run(c, region, opt.restart, history, note);
  const bool resuming = !opt.restart.empty();
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(c.t_end / region.dt() - 1e-9)));
  if (first >= nsteps)
    throw StateError(opt.restart + ": the checkpoint is at step " + std::to_string(first) +
                     ", the case ends at step " + std::to_string(nsteps) +
                     ": nothing left to run (raise time.end to continue)");
  fs::path dir = out_dir;
  try {
    if (root) dir = detail::prepare_output_dir(out_dir, resuming);
  } catch (const std::exception& e) {
    throw RunFailure(e.what());
  }
  if (!note.empty() && root) std::fprintf(stderr, "%s\n", note.c_str());
  auto mark = [&](const std::string& why) {
    if (root) mark_incomplete(dir, why);
  };
  SignalGuard signals;
  try {
    // The marker is there while the run is: a run killed outright (SIGKILL, power loss) or
    // unable to write its reason (a full disk) still leaves it; completion removes it.
    mark("running or killed: started " + std::string(resuming ? "from the checkpoint "
         "at step " + std::to_string(first) : "at step 0") + " of " +
         std::to_string(nsteps) + "; a complete run removes this file and writes summary.json");
    if (root) region.prepare(out_dir, resuming);

    const std::vector<std::string> cols = detail::history_columns(c.probes);
    if (root) detail::write_probe_table(dir, c.probes);
    HistoryWriter hist;
    if (root && resuming) hist.resume((dir / "history.csv").string(), cols, history);
    else if (root) hist.open((dir / "history.csv").string(), cols);
    std::vector<double> row(cols.size());
    auto record = [&]() {
      region.record(row);
      if (root) hist.row(region.time(), row);
    };

    long snap_every = 0;
    if (c.output.snapshots > 0) {
      snap_every = std::max(1L, nsteps / c.output.snapshots);
      region.open_snapshots(out_dir);
    }
    const long hist_every = std::max(1L, c.output.history_every);
    // Checkpoints every ck_steps steps, or each time the clock passes a multiple of ck_time.
    const long ck_steps = c.output.checkpoint_every;
    const double ck_time = c.output.checkpoint_time;
    auto checkpoint_due = [&](long n, double t_before, double t_after) {
      if (n >= nsteps) return false;  // the run completes: no checkpoint needed
      if (ck_steps > 0) return n % ck_steps == 0;
      if (ck_time > 0) return std::floor(t_after / ck_time + 1e-9) > std::floor(t_before / ck_time + 1e-9);
      return false;
    };

    const auto t_start = Clock::now();
    double step_seconds = 0;
    detail::Progress prog(c.output.progress && root, nsteps, t_start, first);
    if (!resuming) {
      record();
      if (snap_every) region.write_snapshot(out_dir);
    }
    for (long n = first + 1; n <= nsteps; ++n) {
      const double t_before = region.time();
      const auto t0 = Clock::now();
      try {
        region.step();
      } catch (const HybridError&) {
        throw;
      } catch (const std::exception& e) {
        // Several ranks: the others cannot join a checkpoint of the failed step.
        if (ranks > 1) throw RunFailure(e.what());
        throw RunFailure(e.what() + keep_failed_state(c, region, dir, out_dir, hist, snap_every != 0,
                                                      e.what()));
      }
      step_seconds += seconds_since(t0);
      if (n % hist_every == 0 || n == nsteps) record();
      if (snap_every && (n % snap_every == 0 || n == nsteps)) region.write_snapshot(out_dir);
      // Several ranks stop together (a launcher passes a signal on to every rank, not at once).
      const bool stop = ranks > 1 ? detail::mpi()->any(g_signal != 0) : g_signal != 0;
      if (stop && n < nsteps) {
        const char* name = g_signal == SIGINT    ? "SIGINT"
                           : g_signal == SIGTERM ? "SIGTERM"
                                                 : "a signal to another rank";
        write_checkpoint(c, region, dir, hist);
        hist.close();
        region.finish();
        std::ostringstream why;
        why << "interrupted by " << name << " after step " << n << " of " << nsteps
            << " (t = " << region.time() << " s); checkpoint " << (dir / checkpoint_file_name()).string()
            << "; continue with: "
            << (ranks > 1 ? "mpirun -np " + std::to_string(ranks) + " (or any number of ranks) " : "")
            << "silentmpm run '" << c.source << "' --out '" << out_dir
            << "' --restart '" << (dir / checkpoint_file_name()).string()
            << "' (and the same --set and --shape options as this run)";
        mark(why.str());
        throw RunInterrupted(why.str());
      }
      if (checkpoint_due(n, t_before, region.time())) write_checkpoint(c, region, dir, hist);
      if (root) prog.update(n, step_seconds);
    }
    hist.close();
    region.finish();

    RunResult r;
    r.steps = nsteps;
    r.steps_run = nsteps - first;
    r.wall_seconds = seconds_since(t_start);
    region.rates(r, nsteps - first, step_seconds);

    nlohmann::ordered_json j =
        detail::summary_head(c, r, region.dt(), region.time(), region.cfl(), step_seconds);
    region.summary(j, r, snap_every != 0);
    if (resuming)
      j["restart"] = {{"checkpoint", opt.restart}, {"from_step", first}};
    if (!root) return r;
    detail::write_summary(dir, j);
    std::error_code ec;
    fs::remove(dir / "RUN_INCOMPLETE", ec);
    return r;
  } catch (const RunInterrupted&) {
    throw;
  } catch (const HybridError& e) {  // a guard of the coupling that only a step finds: bad input
    mark(std::string("failed: ") + e.what());
    throw;
  } catch (const std::exception& e) {
    // Several ranks: the failing one says why (it may be the only one that failed).
    if (ranks > 1) mark_incomplete(dir, "failed on rank " + std::to_string(process_rank()) + " of " +
                                   std::to_string(ranks) + ": " + e.what());
    else mark(std::string("failed: ") + e.what());
    throw RunFailure(e.what());
  }
}

}  // namespace

RunResult run_case(Case& c, const std::string& out_dir, const RunOptions& opt) {
  if (process_count() > 1 && !c.solver && !c.hybrid && opt.ranks_across > 0)
    throw std::runtime_error("--ranks-across " + std::to_string(opt.ranks_across) +
                             " lays out the blocks of an MPM grid; an FE case's mesh is cut by "
                             "METIS: leave the option out");
  const std::unique_ptr<detail::Region> region =
      c.hybrid     ? detail::far_field_module().hybrid_region(c, opt.ranks_across, !opt.restart.empty())
      : c.solver   ? detail::mpm_region(c, opt.ranks_across, !opt.restart.empty())
                   : detail::far_field_module().fem_region(c);
  return run_region(c, *region, out_dir, opt);
}

}  // namespace smpm
