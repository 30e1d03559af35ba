// bench: particle-updates per second of the MPM step on the pulse plate (tungsten, elastic,
// MUSL, 1 particle per cell), refined to about 1e5, 1e6 and 4e6 particles, on one thread and on
// all threads, with a free and with a silent right boundary (a plane P pulse crossing it while
// the steps are timed, so that the silent edge's solve iterates as it does under a wave); and
// how close each rate comes to the host's memory bandwidth.
//
// Against the limit: the bench measures the host's streaming bandwidth in the same run (a
// STREAM-like triad a = b + s c over three arrays of 512 MiB, far beyond any L3; best of five,
// counted as STREAM counts it, 24 bytes per element), and counts the bytes one step of its case
// moves: each particle array and each grid field a pass of the step reads is counted once per
// pass, each one it writes once more (the same convention, no write-allocate; the table of
// passes is printed). Bytes per update times updates per second is the bandwidth the step
// would need if every byte came from memory; its fraction of the triad says how far the step is
// from the limit. Where the problem fits in the last-level cache the fraction can pass 1.
//
//   build/bench [--quick] [--shape bilinear|gimp|bspline|all] [--scheme musl|usl|usf]
//               [--threads N,M,...] [--sizes N,M,...] [--rounds R]
//     --quick: only the 1e5 size, fewer steps; --shape: the grid shape functions (default
//     bilinear; all: the three, alternating per size and thread count; the byte count is that of
//     the bilinear step); --scheme: the update scheme (default MUSL, whose silent edge's dashpots
//     act on the particles' mean velocity and solve for it; USL's act on the trapezoidal mean; the
//     byte count is MUSL's); --threads: the thread counts to run (default 1 and all; the triad is
//     measured on each); --sizes: about how many particles (default 1e5, 1e6, 4e6; from 1e3 to
//     1e8); --rounds: how many times each free and silent pair runs, alternating (default 1).
//     Steps per rate: 200, 30 or 10 by size, times half the thread count from 4 threads on.
//     After each size and thread count a line gives the silent edge's cost over the free one:
//     from a free and a silent plate stepped in turns, the median over their paired steps (four
//     times the rate's steps; paired_cost), then from the rates (the best of the rounds, and
//     the range of the rounds' own pairs); another, the
//     stores of the grid's write-only passes (Solver::streaming: a large grid times both kinds
//     on its first steps, which the warm-up takes; each round's silent run takes the stores its
//     free run chose).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "silentmpm/solver.hpp"
#include "triad.hpp"

using namespace smpm;

namespace {

// With steps > 0, a plane P pulse running towards the right edge (Gaussian, 16 cells at half
// height, 1 m/s; velocity and uniaxial-strain stress of a wave running in +x) whose centre
// reaches the edge halfway through the `steps` timed after the 3 of warm-up: the silent edge's
// dashpots, and their solve's iterations, work while they are timed (a quiet edge costs only its
// fixed part). The free plate gets the same pulse: the same work per particle.
// The update scheme of every plate (--scheme).
Scheme bench_scheme = Scheme::MUSL;

std::unique_ptr<Solver> pulse_plate(double h, bool silent, int threads,
                                    ShapeKind shape = ShapeKind::Bilinear, int steps = 0) {
  auto s = std::make_unique<Solver>();
  Material w;
  w.name = "tungsten"; w.model = Model::Elastic; w.E = 411e9; w.nu = 0.28; w.rho = 15000;
  w.derive();
  s->materials.push_back(w);
  const double Lx = 0.05, Ly = 0.2;
  const int nx = static_cast<int>(std::lround(Lx / h)) + 4, ny = static_cast<int>(std::lround(Ly / h)) + 4;
  s->grid.init(-2 * h, -2 * h, h, nx, ny);
  s->seed_rectangle(0, 0, Lx, Ly, 1, 0, 0, 0, 0);
  TractionLoad tl;
  tl.layer = s->select_layer("left", 0, 0, Ly, 0, 0, -1, 0, h);
  tl.normal = -200e6;
  tl.fn.kind = TimeFunction::Kind::Rectangular;
  tl.fn.duration = 2e-5;
  s->tractions.push_back(tl);
  if (silent) {
    SilentBoundary sb;
    sb.layer = s->select_layer("right", 0, Lx, 0, Lx, Ly, 1, 0, h);
    s->silents.push_back(sb);
  }
  s->opt.threads = threads;
  s->opt.shape = shape;
  s->opt.scheme = bench_scheme;
  s->dt = 0.237 * h / w.cd;
  if (steps > 0) {
    const double sig = 16 * h / 2.3548, xc = Lx - 0.237 * h * (3 + 0.5 * steps);
    Particles& p = s->p;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double d = p.x[k] - xc;
      if (std::abs(d) > 6 * sig) continue;
      const double v = std::exp(-0.5 * d * d / (sig * sig));
      p.vx[k] = v;
      p.sxx[k] = -w.rho * w.cd * v;
      p.syy[k] = p.szz[k] = w.lambda / w.M * p.sxx[k];
    }
  }
  s->finalize();
  return s;
}

// The bytes one MUSL step of an elastic bilinear case moves, per particle and per grid node
// (kernels.hpp and Solver::step_with; doubles 8 bytes, the node's fix flags 1).
struct PassBytes {
  const char* pass;
  const char* arrays;
  double particle, node;
};
const PassBytes kMuslStep[] = {
    {"reset_grid", "W m px py fx fy qx qy", 0, 7 * 8},
    {"p2g", "R x y m vx vy vol sxx syy sxy; RW m px py fx fy", 9 * 8, 5 * 16},
    {"grid_update", "R m fix px py fx fy; W vx vy vnx vny", 0, 5 * 8 + 1 + 4 * 8},
    {"g2p + re-map", "R x y m, RW vx vy; R vx vy vnx vny, RW qx qy", 3 * 8 + 2 * 16, 4 * 8 + 2 * 16},
    {"re-mapped velocity", "R m fix; RW qx qy", 0, 8 + 1 + 2 * 16},
    {"stress + move", "RW x y vol sxx syy szz sxy; R qx qy vnx vny", 7 * 16, 4 * 8},
};

double step_bytes(double nodes_per_particle) {
  double b = 0;
  for (const PassBytes& p : kMuslStep) b += p.particle + p.node * nodes_per_particle;
  return b;
}

// The silent edge's dashpot solve over the last silent rate's timed steps: iterations a step.
double solve_iterations = 0;
// The grid's stores the timed runs used (Solver::store_mode): bit 0 plain, bit 1 streaming.
int stores_seen = 0;

// stores: the grid's stores to take (Solver::streaming; -1: the solver times both ways on its
// first steps and keeps the faster); `used` gets the mode the timed steps ran with.
double rate(double h, bool silent, int threads, int steps, ShapeKind shape, int stores,
            int& used) {
  auto s = pulse_plate(h, silent, threads, shape, steps);
  s->streaming = stores;
  // Warm-up, and the steps on which the solver times its grid's stores both ways.
  for (int i = 0; i < 3 || s->store_mode() < 0; ++i) s->step();
  used = s->store_mode();
  stores_seen |= used > 0 ? 2 : 1;
  const long it0 = s->dashpot_solve.iterations, st0 = s->dashpot_solve.steps;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s->step();
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (silent)
    solve_iterations = static_cast<double>(s->dashpot_solve.iterations - it0) /
                       std::max(1L, s->dashpot_solve.steps - st0);
  return static_cast<double>(s->p.size()) * steps / sec;
}

// The silent edge's cost measured in pairs: a free and a silent plate held at once and stepped
// in turns, `block` steps each (the first of each turn not counted: its cache holds the other
// plate's arrays), every counted step timed; the pulse reaches the edge halfway through the
// `blocks` turns. A step of one plate is paired with the same step of the other (the wave at the
// same place), and the cost is the median over the pairs of t_silent / t_free - 1, which this
// host's drifts of 10-30 % between whole runs leave within a few tenths of a percent. `lo10`
// gets the ratio of the plates' 10th-percentile step times, less one.
double paired_cost(double h, int threads, int blocks, int block, ShapeKind shape, double& lo10) {
  const int counted = blocks * (block - 1);
  auto f = pulse_plate(h, false, threads, shape, blocks * block);
  int warm = 0;  // the free plate's warm-up (with its stores' trial), which the silent one takes
  for (; warm < 3 || f->store_mode() < 0; ++warm) f->step();
  auto s = pulse_plate(h, true, threads, shape, blocks * block);
  s->streaming = f->store_mode();
  for (int i = 0; i < warm; ++i) s->step();
  std::vector<double> tf, ts;
  tf.reserve(counted);
  ts.reserve(counted);
  for (int b = 0; b < blocks; ++b)
    for (Solver* x : {f.get(), s.get()})
      for (int i = 0; i < block; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        x->step();
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (i > 0) (x == f.get() ? tf : ts).push_back(t);
      }
  std::vector<double> ratio(counted);
  for (int k = 0; k < counted; ++k) ratio[k] = ts[k] / tf[k];
  auto quantile = [](std::vector<double> v, double q) {
    const auto at = v.begin() + static_cast<std::ptrdiff_t>(q * (v.size() - 1));
    std::nth_element(v.begin(), at, v.end());
    return *at;
  };
  lo10 = quantile(ts, 0.1) / quantile(tf, 0.1) - 1;
  return quantile(ratio, 0.5) - 1;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::vector<int> thread_counts;
  std::vector<double> sizes = {1e5, 1e6, 4e6};
  int rounds = 1;
  std::vector<ShapeKind> shapes = {ShapeKind::Bilinear};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--shape") == 0 && i + 1 < argc) {
      const std::string v = argv[++i];
      if (v == "bilinear") shapes = {ShapeKind::Bilinear};
      else if (v == "gimp") shapes = {ShapeKind::UGimp};
      else if (v == "bspline") shapes = {ShapeKind::BSpline2};
      else if (v == "all") shapes = {ShapeKind::Bilinear, ShapeKind::UGimp, ShapeKind::BSpline2};
      else {
        std::fprintf(stderr, "bench: --shape: must be bilinear, gimp, bspline or all, got \"%s\"\n",
                     v.c_str());
        return 1;
      }
    } else if (std::strcmp(argv[i], "--scheme") == 0 && i + 1 < argc) {
      const std::string v = argv[++i];
      if (v == "musl") bench_scheme = Scheme::MUSL;
      else if (v == "usl") bench_scheme = Scheme::USL;
      else if (v == "usf") bench_scheme = Scheme::USF;
      else {
        std::fprintf(stderr, "bench: --scheme: must be musl, usl or usf, got \"%s\"\n", v.c_str());
        return 1;
      }
    } else if ((std::strcmp(argv[i], "--threads") == 0 || std::strcmp(argv[i], "--sizes") == 0 ||
                std::strcmp(argv[i], "--rounds") == 0) && i + 1 < argc) {
      // A comma-separated list of numbers, each in [lo, hi] (--rounds: one whole number).
      const std::string opt = argv[i], v = argv[++i];
      const bool threads = opt == "--threads", rounds_arg = opt == "--rounds";
      const double lo = threads || rounds_arg ? 1 : 1e3, hi = threads ? 4096 : rounds_arg ? 100 : 1e8;
      std::vector<double> list;
      for (std::size_t at = 0; at <= v.size();) {
        const std::size_t comma = std::min(v.find(',', at), v.size());
        const std::string item = v.substr(at, comma - at);
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !(x >= lo && x <= hi) ||
            ((threads || rounds_arg) && x != std::floor(x)) || (rounds_arg && !list.empty())) {
          std::fprintf(stderr, "bench: %s: \"%s\" is not %s from %g to %g (in \"%s\")\n",
                       opt.c_str(), item.c_str(), rounds_arg ? "one whole number" : "a number",
                       lo, hi, v.c_str());
          return 1;
        }
        list.push_back(x);
        at = comma + 1;
      }
      if (threads) thread_counts.assign(list.begin(), list.end());
      else if (rounds_arg) rounds = static_cast<int>(list[0]);
      else sizes = list;
    } else {
      std::fprintf(stderr, "bench: unknown argument \"%s\"; usage: bench [--quick] "
                           "[--shape bilinear|gimp|bspline|all] [--scheme musl|usl|usf] [--threads N,M,...] "
                           "[--sizes N,M,...] "
                           "[--rounds R]\n", argv[i]);
      return 1;
    }
  }
  const int all = omp_get_max_threads();
  if (thread_counts.empty()) thread_counts = all > 1 ? std::vector<int>{1, all} : std::vector<int>{1};
  std::printf("silentmpm bench: pulse plate 50 x 200 mm, tungsten, elastic, %s, 1 ppc; a plane "
              "P pulse crosses the right edge while the steps are timed\n",
              scheme_name(bench_scheme));
  std::printf("bytes per particle (particle arrays): %zu\n", Particles::bytes_per_particle());
  std::printf("bytes one %sstep moves (R read, W written, RW both; per particle + per grid node):\n",
              bench_scheme == Scheme::MUSL ? "" : "MUSL ");
  for (const PassBytes& p : kMuslStep)
    std::printf("  %-20s %4.0f + %4.0f  %s\n", p.pass, p.particle, p.node, p.arrays);
  std::vector<double> triad;
  std::printf("triad (3 x 512 MiB, best of 5):");
  for (int th : thread_counts) {
    triad.push_back(benchmarks::triad_gbs(th));
    std::printf(" %.1f GB/s on %d thread%s%s", triad.back(), th, th == 1 ? "" : "s",
                th == thread_counts.back() ? "\n" : ",");
  }
  std::printf("%10s %9s %8s %8s %14s %9s %8s %8s %9s\n", "particles", "boundary", "threads",
              "steps", "updates/s", "shape", "B/update", "GB/s", "of triad");
  if (quick) sizes = {1e5};
  for (double size : sizes) {
    const double h = 1e-4 * std::sqrt(1e6 / size);  // 1e6 particles at 0.1 mm
    auto probe = pulse_plate(h, false, 1);
    const std::size_t n = probe->p.size();
    // Per node: 11 fields, the dashpot record (Grid::kDash), the flags and the dashpot index.
    const std::size_t grid_bytes =
        probe->grid.nodes() * ((11 + smpm::Grid::kDash) * sizeof(double) + 1 + sizeof(int));
    const double per_update = step_bytes(double(probe->grid.nodes()) / n);
    std::printf("# %zu particles, %zu grid nodes: %.0f bytes per particle including the grid, "
                "%.0f MB in all\n", n, probe->grid.nodes(),
                Particles::bytes_per_particle() + double(grid_bytes) / n,
                (Particles::bytes_per_particle() * double(n) + grid_bytes) / 1e6);
    probe.reset();
    const int base = quick ? 20 : (n > 2000000 ? 10 : n > 500000 ? 30 : 200);
    for (std::size_t k = 0; k < thread_counts.size(); ++k) {
      const int th = thread_counts[k];
      const int steps = base * std::max(1, th / 2);
      // Each round's rates, free and silent, per shape: the silent edge's cost over the free one.
      const std::size_t ns = shapes.size();
      std::vector<double> free_rate(ns * rounds), silent_rate(ns * rounds);
      // The silent run of a round takes the stores its free run chose, so that the two differ
      // by the edge alone.
      std::vector<int> free_stores(ns, -1);
      stores_seen = 0;
      for (int round = 0; round < rounds; ++round)
        for (bool silent : {false, true})
          for (std::size_t si = 0; si < ns; ++si) {
            const ShapeKind shape = shapes[si];
            int used = -1;
            const double r = rate(h, silent, th, steps, shape, silent ? free_stores[si] : -1, used);
            if (!silent) free_stores[si] = used;
            (silent ? silent_rate : free_rate)[round * ns + si] = r;
            const double gbs = r * per_update / 1e9;
            std::printf("%10zu %9s %8d %8d %14.3e %9s %8.0f %8.1f %8.0f%%\n", n,
                        silent ? "silent" : "free", th, steps, r, shape_name(shape), per_update,
                        gbs, 100 * gbs / triad[k]);
            std::fflush(stdout);
          }
      for (std::size_t si = 0; si < ns; ++si) {
        // Paired steps: four times the rate's steps in turns of 10 (5 above 5e5 particles, 2 above
        // 2e6), each turn's first step not counted.
        const int block = n > 2000000 ? 2 : n > 500000 ? 5 : 10;
        const int blocks = std::max(4, 4 * steps / block);
        double lo10 = 0;
        const double paired = paired_cost(h, th, blocks, block, shapes[si], lo10);
        double best_free = 0, best_silent = 0, lo = 1e300, hi = -1e300;
        for (int round = 0; round < rounds; ++round) {
          const double f = free_rate[round * ns + si], sr = silent_rate[round * ns + si];
          best_free = std::max(best_free, f);
          best_silent = std::max(best_silent, sr);
          lo = std::min(lo, f / sr - 1);
          hi = std::max(hi, f / sr - 1);
        }
        std::printf("# %zu particles, %d thread%s, %s, %s: the silent edge costs %.1f %% over the free "
                    "one (median of %d paired steps; %.1f %% between the steps' 10th "
                    "percentiles; the rates above: %.1f %% between the best of %d round%s, %.1f to "
                    "%.1f %% round by round; its solve %.1f iterations a step)\n",
                    n, th, th == 1 ? "" : "s", shape_name(shapes[si]), scheme_name(bench_scheme),
                    100 * paired,
                    blocks * (block - 1), 100 * lo10, 100 * (best_free / best_silent - 1), rounds,
                    rounds == 1 ? "" : "s", 100 * lo, 100 * hi, solve_iterations);
      }
      std::printf("# %zu particles, %d thread%s: the grid's write-only passes with %s stores "
                  "(each free run times both on its first steps, its silent run takes the same)\n",
                  n, th, th == 1 ? "" : "s",
                  stores_seen == 2 ? "streaming" : stores_seen == 1 ? "plain" : "plain or streaming");
    }
  }
  return 0;
}
