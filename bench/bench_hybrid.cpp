// bench_hybrid: the hybrid's speed benchmark, the MPM-FEM hybrid film case against the all-MPM
// extended film case (studies/hybrid/README.md).
//
// Every case is the tungsten film of studies/film (2 500 j2_softening particles, 0.1 um cells,
// 1 ppc, MUSL, dt 3.2 ps, 1000 steps to 3.2 ns); they differ only below the film: 15 um of
// silicon particles (the all-MPM extended reference), or some silicon particles on a deal.II Q1
// far field to the same depth. Each case is built from its case file (the set-up is timed apart:
// gmsh, deal.II, seeding) and its whole step loop is run on one thread without output; the cases
// alternate --reps times, so that a busy spell of a shared machine hits all alike. The step loop
// is timed with the process's CPU clock (on a shared machine it does not count the time the
// process waits for a core) and with the wall clock. Prints per case the min and median of both,
// particle-updates and FE dof-updates per second, and the step-loop speed-up of each case over
// the first one (the reference).
//
//   build/bench_hybrid [--reps R] [--json FILE] [CASE.json ...]
//     default cases: studies/film/cases/extended.json and the hybrid study's hybrid cases
//     --json FILE    also write the figures as JSON
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"

using namespace smpm;

namespace {

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Figures {
  std::string file, name;
  std::size_t particles = 0, dofs = 0;
  long steps = 0;
  std::vector<double> setup, cpu, wall;
};

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// One build and step loop of a case; appends its timings.
void run_once(Figures& f) {
  const double s0 = wall_now();
  Case c = load_case(f.file, {"scheme.threads=1"});
  f.setup.push_back(wall_now() - s0);
  if (!c.solver) throw std::runtime_error(f.file + ": not an MPM or hybrid case");
  const double dt = c.hybrid ? c.hybrid->dt() : c.solver->dt;
  const long n = std::max(1L, static_cast<long>(std::ceil(c.t_end / dt - 1e-9)));
  f.particles = c.solver->p.size();
  f.dofs = c.fem ? c.fem->dofs() : 0;
  f.steps = n;
  const double c0 = cpu_now(), w0 = wall_now();
  if (c.hybrid)
    for (long k = 0; k < n; ++k) c.hybrid->step();
  else
    for (long k = 0; k < n; ++k) c.solver->step();
  f.cpu.push_back(cpu_now() - c0);
  f.wall.push_back(wall_now() - w0);
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::string json_out;
  std::vector<Figures> cases;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--reps" || a == "--json") && i + 1 >= argc) {
      std::fprintf(stderr, "bench_hybrid: %s needs a value\n", a.c_str());
      return 2;
    }
    if (a == "--reps") {
      char* end = nullptr;
      const long r = std::strtol(argv[++i], &end, 10);
      reps = (end && *end == '\0' && r >= 1 && r <= 1000) ? static_cast<int>(r) : 0;
      if (reps < 1) {
        std::fprintf(stderr, "bench_hybrid: --reps must be an integer in 1..1000, got %s\n", argv[i]);
        return 2;
      }
    } else if (a == "--json") {
      json_out = argv[++i];
    } else if (a == "--help" || a == "-h") {
      std::printf(
          "usage: bench_hybrid [--reps R] [--json FILE] [CASE.json ...]\n"
          "  Runs each case's whole step loop on one thread without output, the cases alternating\n"
          "  R times (default 5); prints per case the step-loop CPU time (min, median), wall time,\n"
          "  particle- and FE dof-updates per second and the speed-up over the first case.\n"
          "  Default cases: studies/film/cases/extended.json (the reference) and the hybrid film\n"
          "  cases of studies/hybrid/cases. --json FILE also writes the figures as JSON.\n");
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "bench_hybrid: unknown option %s (see --help)\n", a.c_str());
      return 2;
    } else {
      Figures f;
      f.file = a;
      cases.push_back(f);
    }
  }
  if (cases.empty()) {
    const std::string root = SMPM_SOURCE_DIR;
    for (const char* p : {"/studies/film/cases/extended.json",
                          "/studies/hybrid/cases/film_hybrid_unstructured_fixed.json",
                          "/studies/hybrid/cases/film_hybrid_unstructured_1um_fixed.json",
                          "/studies/hybrid/cases/film_hybrid_coarse_fixed.json"}) {
      Figures f;
      f.file = root + p;
      cases.push_back(f);
    }
  }
  for (auto& f : cases) {
    const auto slash = f.file.find_last_of('/');
    f.name = f.file.substr(slash == std::string::npos ? 0 : slash + 1);
    if (f.name.size() > 5 && f.name.compare(f.name.size() - 5, 5, ".json") == 0)
      f.name.resize(f.name.size() - 5);
  }
  std::ofstream json_file;
  if (!json_out.empty()) {  // before the runs: an unwritable path is reported at once
    json_file.open(json_out);
    if (!json_file) {
      std::fprintf(stderr, "bench_hybrid: cannot write %s\n", json_out.c_str());
      return 1;
    }
  }
  std::printf("bench_hybrid: step loops on one thread, %d alternating repetitions; first case = reference\n",
              reps);
  try {
    for (int r = 0; r < reps; ++r)
      for (auto& f : cases) run_once(f);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_hybrid: %s\n", e.what());
    if (json_file.is_open()) {  // no empty figures file left behind
      json_file.close();
      std::remove(json_out.c_str());
    }
    return 1;
  }
  const Figures& ref = cases.front();
  std::printf("%-36s %9s %7s %6s %8s %8s %8s %8s %12s %12s %8s %8s\n", "case", "particles", "FE dofs",
              "steps", "setup_s", "cpu_min", "cpu_med", "wall_min", "p-upd/s", "dof-upd/s", "x(min)",
              "x(med)");
  nlohmann::ordered_json out;
  out["reps"] = reps;
  out["threads"] = 1;
  out["reference"] = ref.name;
  for (const auto& f : cases) {
    const double cmin = min_of(f.cpu), cmed = median_of(f.cpu), wmin = min_of(f.wall);
    const double pu = static_cast<double>(f.particles) * f.steps / cmin;
    const double du = static_cast<double>(f.dofs) * f.steps / cmin;
    const double xmin = min_of(ref.cpu) / cmin, xmed = median_of(ref.cpu) / cmed;
    std::printf("%-36s %9zu %7zu %6ld %8.3f %8.3f %8.3f %8.3f %12.3e %12.3e %8.2f %8.2f\n",
                f.name.c_str(), f.particles, f.dofs, f.steps, median_of(f.setup), cmin, cmed, wmin, pu,
                du, xmin, xmed);
    out["cases"][f.name] = {{"file", f.file},
                            {"particles", f.particles},
                            {"fem_dofs", f.dofs},
                            {"steps", f.steps},
                            {"setup_wall_seconds_median", median_of(f.setup)},
                            {"step_cpu_seconds", f.cpu},
                            {"step_cpu_seconds_min", cmin},
                            {"step_cpu_seconds_median", cmed},
                            {"step_wall_seconds_min", wmin},
                            {"step_wall_seconds_median", median_of(f.wall)},
                            {"particle_updates_per_second", pu},
                            {"dof_updates_per_second", du},
                            {"speedup_over_reference_min", xmin},
                            {"speedup_over_reference_median", xmed}};
  }
  if (!json_out.empty()) {
    json_file << out.dump(2) << "\n";
    json_file.flush();
    if (!json_file) {
      std::fprintf(stderr, "bench_hybrid: cannot write %s\n", json_out.c_str());
      return 1;
    }
  }
  return 0;
}
