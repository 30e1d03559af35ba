// silentmpm: command-line entry point. A thin shell over the driver.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/history.hpp"

namespace {

// silentmpm compare: the relative L2 difference of one or more history columns (see its --help).
int compare(const std::string& a_csv, const std::string& b_csv, std::vector<std::string> columns,
            bool all, double t0, double t1, double n0, double n1, bool json) {
  if (columns.empty() && !all)
    throw std::runtime_error("compare: give --column (one or more) or --all");
  if (!columns.empty() && all) throw std::runtime_error("compare: give either --column or --all");
  if (!(t1 > t0))
    throw std::runtime_error("compare: the window [--from, --to] is empty (" + std::to_string(t0) +
                             " to " + std::to_string(t1) + ")");
  if (std::isnan(n0)) n0 = t0;
  if (std::isnan(n1)) n1 = t1;
  if (!(n1 > n0)) throw std::runtime_error("compare: the norm window [--norm-from, --norm-to] is empty");
  const auto a = smpm::read_history(a_csv);
  const auto b = smpm::read_history(b_csv);
  if (all)
    for (const auto& c : a.columns)
      if (std::find(b.columns.begin(), b.columns.end(), c) != b.columns.end()) columns.push_back(c);
  if (columns.empty()) throw std::runtime_error("compare: " + a_csv + " and " + b_csv + " share no column");
  // With --all a column that cannot be compared (a reference that is zero over the window, such
  // as the dissipated energy of an elastic run) is reported as such; a named one is an error.
  std::vector<smpm::Difference> d(columns.size());
  std::vector<std::string> why(columns.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    try {
      d[k] = smpm::difference(a, b, columns[k], t0, t1, n0, n1);
    } catch (const std::runtime_error& e) {
      if (!all) throw;
      why[k] = e.what();
    }
  }
  if (json) {
    nlohmann::ordered_json j;
    j["a"] = a_csv;
    j["b"] = b_csv;
    j["window"] = {t0, t1};
    j["norm_window"] = {n0, n1};
    j["interpolation"] = "b linear in time at a's rows; rows outside b's time span are left out";
    j["columns"] = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < columns.size(); ++k)
      j["columns"][columns[k]] =
          why[k].empty() ? nlohmann::ordered_json{{"relative", d[k].relative},
                                                  {"absolute", d[k].absolute},
                                                  {"reference", d[k].reference},
                                                  {"samples", d[k].samples},
                                                  {"norm_samples", d[k].norm_samples}}
                         : nlohmann::ordered_json{{"error", why[k]}};
    std::printf("%s\n", j.dump(2).c_str());
  } else if (columns.size() == 1) {
    std::printf("%.6e\n", d[0].relative);
  } else {
    std::size_t w = 6;
    for (const auto& c : columns) w = std::max(w, c.size());
    std::printf("%-*s  %12s  %12s  %12s  %7s\n", static_cast<int>(w), "column", "relative",
                "absolute", "reference", "samples");
    for (std::size_t k = 0; k < columns.size(); ++k)
      if (why[k].empty())
        std::printf("%-*s  %12.6e  %12.6e  %12.6e  %7zu\n", static_cast<int>(w), columns[k].c_str(),
                    d[k].relative, d[k].absolute, d[k].reference, d[k].samples);
      else
        std::printf("%-*s  %12s  (%s)\n", static_cast<int>(w), columns[k].c_str(), "-", why[k].c_str());
  }
  return 0;
}

}  // namespace

namespace {

// Under several MPI ranks only rank 0 prints, except a run's failure, which may be one rank's
// alone: that rank prints it and ends every rank (exit 2).
bool root() { return smpm::process_rank() == 0; }

int run_main(int argc, char** argv) {
  CLI::App app{
      "silentmpm - explicit 2D plane-strain MPM with the Lysmer-Kuhlemeyer silent boundary layer "
      "of Shen & Chen (2005), a finite-element far field (deal.II) and the two coupled; LK, "
      "Kelvin-Voigt, damping-band and PML boundaries in both.\nCase files are JSON in SI units; "
      "every key is documented in docs/case-reference.md."};
  app.footer("Exit status: 0 success; 1 bad input (case file, command line, restart file); "
             "2 the run failed (instability, I/O error: DIR/RUN_INCOMPLETE says why); "
             "3 interrupted by SIGINT/SIGTERM (a checkpoint was written: continue with --restart).");
  app.require_subcommand(1);
#ifndef SMPM_VERSION
#define SMPM_VERSION "unknown"
#endif
  app.set_version_flag("--version,-V", std::string("silentmpm ") + SMPM_VERSION);
  std::vector<std::string> overrides;
  std::string case_path, out_dir;
  int threads = -1;
  bool quiet = false;

  auto* run = app.add_subcommand("run", "Run a case and write history.csv, summary.json and "
                                        "particle snapshots (particles.h5 + particles.xdmf)");
  run->add_option("case", case_path, "Case file (JSON)")->required();
  run->add_option("--out,-o", out_dir, "Output directory (created if missing)")->required();
  run->add_option("--set", overrides, "Override a case key, e.g. --set grid.cell=0.002 "
                                      "(repeatable; value parsed as JSON)");
  run->add_option("--threads", threads, "OpenMP threads, 0 = all cores (default: the case's "
                                        "scheme.threads)")
      ->check([](const std::string& v) -> std::string {
        char* end = nullptr;
        const long n = std::strtol(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || n < 0 || n > 4096)
          return "must be a whole number from 0 (all cores) to 4096, got \"" + v + "\"";
        return "";
      });
  std::string shape;
  run->add_option("--shape", shape, "Grid shape functions: bilinear, gimp or bspline (default: "
                                    "the case's scheme.shape)");
  run->add_flag("--quiet,-q", quiet, "Print nothing but errors: no progress line, no completion line");
  int ranks_across = 0;
  run->add_option("--ranks-across", ranks_across, "Under mpirun: ranks across x of the blocks "
                                                  "each rank holds (1: slabs of cell rows; "
                                                  "default: the layout sharing the fewest nodes)")
      ->check(CLI::Range(0, 1 << 20));
  std::string restart;
  run->add_option("--restart", restart, "Continue from a checkpoint (DIR/checkpoint.smpm) of this "
                                        "case, written by output.checkpoint_every/_time or an "
                                        "interrupt");

  auto* check = app.add_subcommand("check", "Validate a case file without running it and "
                                            "print what it would run");
  check->add_option("case", case_path, "Case file (JSON)")->required();
  check->add_option("--set", overrides, "Override a case key (as for run)");

  std::string a_csv, b_csv;
  std::vector<std::string> columns;
  double t0 = 0, t1 = 1e300, n0 = std::nan(""), n1 = std::nan("");
  bool cmp_all = false, cmp_json = false;
  auto* cmp = app.add_subcommand(
      "compare", "Relative L2 difference ||a - b|| / ||b|| of history columns over a time window "
                 "(b interpolated linearly at a's times, never extrapolated)");
  cmp->add_option("a", a_csv, "history.csv of the run to test")->required();
  cmp->add_option("b", b_csv, "history.csv of the reference run")->required();
  cmp->add_option("--column,-c", columns, "Column, e.g. A.sxx (repeatable, or a comma-separated list)")
      ->delimiter(',');
  cmp->add_flag("--all", cmp_all, "Every column the two files share");
  cmp->add_option("--from", t0, "Window start (s)");
  cmp->add_option("--to", t1, "Window end (s)");
  cmp->add_option("--norm-from", n0, "Start of the window ||b|| is taken over (default: --from)");
  cmp->add_option("--norm-to", n1, "End of the window ||b|| is taken over (default: --to)");
  cmp->add_flag("--json", cmp_json, "Print the result as JSON");
  cmp->footer("One column prints the bare number; several print a table (column, relative, "
              "absolute ||a - b||, reference ||b||, samples); --json prints every figure with the "
              "files, windows and the interpolation used.");

  // Command-line errors exit 1, as bad case files do (CLI11's own codes are 100 and more).
  if (argc > 1 && argv[1][0] != '-') {
    const std::string w = argv[1];
    const std::vector<std::string> known = {"run", "check", "compare"};
    if (std::find(known.begin(), known.end(), w) == known.end()) {
      const std::string hint = smpm::did_you_mean(w, known);
      std::fprintf(stderr, "silentmpm: error: unknown command \"%.64s\"%s (commands: run, check, "
                           "compare; see silentmpm --help)\n",
                   w.c_str(), hint.c_str());
      return 1;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "silentmpm: error: %s (see silentmpm --help)\n", e.what());
    return 1;
  }
  try {
    if (*cmp) return compare(a_csv, b_csv, columns, cmp_all, t0, t1, n0, n1, cmp_json);
    // The command line's own settings: a section the case leaves out is created with the key
    // (overrides given with --set must name existing sections, so typos are caught).
    std::vector<std::string> cli;  // in order; prepended to the --set overrides below
    std::vector<std::string> made;  // sections the command line creates
    auto setting = [&](const std::string& section, const std::string& key, const std::string& value) {
      bool has = std::find(made.begin(), made.end(), section) != made.end();
      try {
        std::ifstream in(case_path);
        const auto doc = nlohmann::json::parse(in, nullptr, false, true);
        has = has || (doc.is_object() && doc.contains(section));
      } catch (const std::exception&) {
        // unreadable or malformed: load_case reports it
      }
      cli.push_back(has ? section + "." + key + "=" + value
                        : section + "={\"" + key + "\":" + value + "}");
      made.push_back(section);
    };
    if (*run && threads >= 0) setting("scheme", "threads", std::to_string(threads));
    if (*run && !shape.empty()) setting("scheme", "shape", nlohmann::json(shape).dump());
    if (*run && quiet) setting("output", "progress", "false");
    overrides.insert(overrides.begin(), cli.begin(), cli.end());
    // A run on several ranks: rank 0 builds the whole case (and reads a restart's whole
    // checkpoint), the others receive their blocks from it.
    smpm::Case c = *run ? smpm::load_case_on_ranks(case_path, overrides)
                        : smpm::load_case(case_path, overrides);
    smpm::RunOptions ropt;
    ropt.restart = restart;
    ropt.ranks_across = ranks_across;
    if (!c.solver && c.fem) {  // FEM-only case
      if (*check) {
        if (!root()) return 0;
        std::printf("%s: ok\n", case_path.c_str());
        std::printf("  %s\n", smpm::fem_check_line(c).c_str());
        for (const auto& n : c.notes) std::printf("  %s\n", n.c_str());
        return 0;
      }
      const auto r = smpm::run_case(c, out_dir, ropt);
      if (!quiet)
        std::printf("%s: %ld steps, %zu dofs, %.2f s, %.3g dof-updates/s -> %s\n",
                    case_path.c_str(), r.steps, r.dofs, r.wall_seconds, r.dof_updates_per_second,
                    out_dir.c_str());
      return 0;
    }
    const smpm::Solver& s = *c.solver;
    if (*check) {
      if (!root()) return 0;
      std::printf("%s: ok\n", case_path.c_str());
      std::printf("  particles %zu, grid %d x %d cells of %g m, dt %g s (CFL %.3f), %ld steps\n",
                  s.p.size(), s.grid.nx, s.grid.ny, s.grid.h, s.dt, s.dt / s.critical_dt(),
                  static_cast<long>(std::ceil(c.t_end / s.dt - 1e-9)));
      const std::string mc = s.opt.mass_correction > 0
                                 ? ", mass correction " + std::to_string(s.opt.mass_correction) +
                                       " term(s)" +
                                       (s.opt.mass_correction_symmetric ? " (symmetric)" : "")
                                 : "";
      char ln[64] = "";
      if (s.opt.light_node_ratio > 0)
        std::snprintf(ln, sizeof ln, ", light nodes extended (ratio %g)", s.opt.light_node_ratio);
      std::printf("  scheme %s, shape %s, flip %g%s%s; %zu traction(s), %zu silent layer(s), "
                  "%zu constraint(s), %zu probe(s)\n", smpm::scheme_name(s.opt.scheme),
                  smpm::shape_name(s.opt.shape), s.opt.flip, mc.c_str(), ln, s.tractions.size(),
                  s.silents.size(), s.constraints.size(), c.probes.size());
      for (const auto& n : c.notes) std::printf("  %s\n", n.c_str());
      return 0;
    }
    if (root())  // what check calls a note, run says on stderr before it starts
      for (const auto& n : c.notes)
        if (n.rfind("note: ", 0) == 0) std::fprintf(stderr, "%s\n", n.c_str());
    const auto r = smpm::run_case(c, out_dir, ropt);
    if (!quiet && root())
      std::printf("%s: %ld steps, %zu particles, %.2f s, %.3g particle-updates/s -> %s\n",
                  case_path.c_str(), r.steps, r.particles, r.wall_seconds,
                  r.particle_updates_per_second, out_dir.c_str());
    if (root() && s.dashpot_solve.unconverged > 0)
      std::fprintf(stderr,
                   "note: the silent layers' dashpot mean did not converge in %d iterations on %ld "
                   "of %ld steps (their last iterate was used; summary.json \"dashpot_solve\")\n",
                   smpm::Solver::kCmMaxIterations, s.dashpot_solve.unconverged,
                   s.dashpot_solve.steps);
    return 0;
  } catch (const smpm::RunInterrupted& e) {
    if (root()) std::fprintf(stderr, "silentmpm: %s\n", e.what());
    return 3;
  } catch (const smpm::RunFailure& e) {
    if (smpm::process_count() > 1) {
      std::fprintf(stderr, "silentmpm: error (rank %d of %d): %s\n", smpm::process_rank(),
                   smpm::process_count(), e.what());
      std::fflush(stderr);
      smpm::abort_processes(2);
    }
    std::fprintf(stderr, "silentmpm: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    if (root()) std::fprintf(stderr, "silentmpm: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    smpm::start_processes(&argc, &argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silentmpm: error: %s\n", e.what());
    return 1;
  }
  const int code = run_main(argc, argv);
  smpm::stop_processes();
  return code;
}
