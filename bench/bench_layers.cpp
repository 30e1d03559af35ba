// bench_layers: what each absorbing boundary costs per step, in MPM and in the FE far field.
//
// A steel square of W x W cells (MPM: 1 particle per cell; FEM: Q1) with the same boundary on
// its left, right and bottom sides and a free top: free edges, LK dashpots (`silent` /
// `dashpot`), Kelvin-Voigt springs, a graded damping band of L cells in front of the dashpots,
// a perfectly matched layer of L cells in front of them. Each variant runs a short sin^2 pulse
// from the top for a few steps to warm up, then the variants take turns of 10 steps, R rounds of
// S steps each, every step timed but each turn's first (one thread by default, timed by the
// process's CPU clock; with more threads by the wall clock, since idle OpenMP threads spin and
// count as CPU). The time per step is the median step's; the ratio to the free square is the
// median over the timed steps of each step's time over the free square's step of the same turn
// and place, which cancels the host's drifts (10-30 % between whole runs on a shared host; the
// edge-only boundaries amplify the ratio's noise by N / N_layer, about 70 at 200 cells: measure
// them on a smaller square too, e.g. `--cells 50 --steps 3200 --kind lk`, where it is about 17).
//
// Per variant it prints the time per step, the ratio to the free square's, and the cost of one
// cell of the layer against a free cell:
//     cost/cell = 1 + (t_variant / t_free - 1) N / N_layer,
// N the cells of the square and N_layer those within the layer's thickness of the three sides
// (L cells for the band and the PML, one cell for the dashpots and springs, which act on the
// edge only). 1 means the layer is free; the goal the project keeps is at most 1.5.
//
// The MPM PML runs under USL, timed against a free square under USL too (the other MPM variants
// use MUSL, the default scheme); with --ppc 4 or 9 also under MUSL, whose layer damps its
// particles (docs/physics.md section 9.3). The LK and Kelvin-Voigt edges run under USL as well:
// there their dashpots act on the trapezoidal mean, under MUSL on the particles' mean, whose solve
// (docs/physics.md section 4) is most of their cost; the two rows show its price.
//
//   build/bench_layers [--cells W] [--layer L] [--steps S] [--rounds R] [--threads T]
//                      [--only mpm|fem] [--kind lk|kv|damping|pml] [--ppc 1|4|9]
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "silentmpm/geo_box.hpp"

using namespace smpm;
namespace fs = std::filesystem;

namespace {

struct Options {
  int cells = 200, layer = 10, steps = 200, rounds = 5, threads = 1;
  int ppc = 1;       // MPM particles per cell: 1, 4 or 9
  std::string only;  // "mpm" or "fem": that method only
  std::string kind;  // one boundary (with the free square it is compared with)
};

double seconds(int threads) {
  timespec t{};
  clock_gettime(threads > 1 ? CLOCK_MONOTONIC : CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

constexpr double kH = 1e-3;  // cell size (m)

std::string num(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

const char* kMaterial =
    R"("materials": {"steel": {"model": "elastic", "young": 200e9, "poisson": 0.25, "density": 7800}})";

// The boundary entries of `kind` on the left, right and bottom sides, each side named by
// `select` + side (MPM: a body's side; FEM: a curve), the LK entry of the method being `lk`.
std::string edges(const std::string& kind, const std::string& select, const std::string& lk,
                  double L) {
  std::string b;
  if (kind == "free") return b;
  for (const char* side : {"left", "right", "bottom"}) {
    const std::string at = select + side + "\"";
    const std::string dashpots = R"(, {"type": ")" + lk + "\", " + at + "}";
    if (kind == "lk") b += dashpots;
    if (kind == "kv") b += R"(, {"type": "kelvin_voigt", "delta": )" + num(40 * kH) + ", " + at + "}";
    if (kind == "damping")
      b += R"(, {"type": "damping_layer", "width": )" + num(L) + R"(, "r0": 0.9, )" + at + "}" + dashpots;
    if (kind == "pml")
      b += R"(, {"type": "pml", "width": )" + num(L) + R"(, "r0": 0.01, )" + at + "}" + dashpots;
  }
  return b;
}

// The load: a sin^2 pulse on the middle fifth of the top.
std::string mpm_case(const Options& o, const std::string& kind, const std::string& scheme) {
  const double W = o.cells * kH, L = o.layer * kH;
  std::string b = R"({"title": "layer bench", "time": {"end": 1, "cfl": 0.5},)";
  b += R"("grid": {"origin": [)" + num(-2 * kH) + ", " + num(-2 * kH) + R"(], "size": [)" +
       num(W + 4 * kH) + ", " + num(W + 4 * kH) + R"(], "cell": )" + num(kH) + "},";
  b += R"("scheme": {"update": ")" + scheme + R"(", "threads": )" + std::to_string(o.threads) + "},";
  b += std::string(kMaterial) + ",";
  b += R"("bodies": [{"name": "b", "material": "steel", "box": [0, 0, )" + num(W) + ", " + num(W) +
       R"(], "particles_per_cell": )" + std::to_string(o.ppc) + "}],";
  b += R"("boundaries": [{"type": "traction", "body": "b", "side": "top", "interval": [)" +
       num(0.4 * W) + ", " + num(0.6 * W) +
       R"(], "normal": -1e8, "time": {"shape": "sin2", "start": 0, "duration": 2e-6, "ramp": 1e-6}})";
  b += edges(kind, R"("body": "b", "side": ")", "silent", L);
  b += R"(], "output": {"snapshots": 0, "progress": false}})";
  return b;
}

std::string fem_case(const Options& o, const std::string& kind, const std::string& geo) {
  const double L = o.layer * kH;
  std::string b = R"({"title": "layer bench", "time": {"end": 1, "cfl": 0.5},)";
  b += R"("scheme": {"threads": )" + std::to_string(o.threads) + "},";
  b += std::string(kMaterial) + ",";
  b += R"("fem": {"mesh": ")" + geo + R"(", "regions": {"body": "steel"}, "boundaries": [)";
  // The FE load is on the whole top (the mesh has no curve for its middle fifth); a traction
  // costs the same per step either way.
  b += R"({"type": "traction", "curve": "top", "normal": -1e8, "time": {"shape": "sin2", "start": 0, "duration": 2e-6, "ramp": 1e-6}})";
  b += edges(kind, R"("curve": ")", "dashpot", L);
  b += R"(]}, "output": {"snapshots": 0, "progress": false}})";
  return b;
}

struct Variant {
  std::string method, kind, scheme;  // scheme: MPM only
  Case c;
  int layer_cells = 0;               // thickness of the layer in cells (0: none)
  std::vector<double> steps;         // seconds of each timed step, in order
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void step(Variant& v) {
  if (v.c.solver) v.c.solver->step();
  else v.c.fem->step();
}

// Cells of a W x W square within `t` cells of its left, right and bottom sides.
double layer_cells(int W, int t) { return double(W) * W - double(W - 2 * t) * (W - t); }

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](const char* what) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_layers: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--cells") o.cells = std::atoi(next("--cells"));
    else if (a == "--layer") o.layer = std::atoi(next("--layer"));
    else if (a == "--steps") o.steps = std::atoi(next("--steps"));
    else if (a == "--rounds") o.rounds = std::atoi(next("--rounds"));
    else if (a == "--threads") o.threads = std::atoi(next("--threads"));
    else if (a == "--only") o.only = next("--only");
    else if (a == "--kind") o.kind = next("--kind");
    else if (a == "--ppc") o.ppc = std::atoi(next("--ppc"));
    else {
      std::fprintf(stderr,
                   "usage: bench_layers [--cells W] [--layer L] [--steps S] [--rounds R] "
                   "[--threads T] [--only mpm|fem] [--kind lk|kv|damping|pml] [--ppc 1|4|9]\n");
      return 2;
    }
  }
  if (o.cells < 4 * o.layer || o.layer < 1 || o.steps < 1 || o.rounds < 1 || o.threads < 1 ||
      (!o.only.empty() && o.only != "mpm" && o.only != "fem") ||
      (!o.kind.empty() && o.kind != "lk" && o.kind != "kv" && o.kind != "damping" &&
       o.kind != "pml") ||
      (o.ppc != 1 && o.ppc != 4 && o.ppc != 9)) {
    std::fprintf(stderr, "bench_layers: need --layer >= 1, --cells >= 4 layers, --steps, --rounds, "
                         "--threads >= 1, --only mpm or fem, --kind lk, kv, damping or pml, "
                         "--ppc 1, 4 or 9\n");
    return 2;
  }
  const fs::path dir = fs::temp_directory_path() / "smpm_bench_layers";
  fs::create_directories(dir);
  const std::string geo = (dir / "box.geo").string();
  std::ofstream(geo) << fem::box_geo_text(0, 0, o.cells * kH, o.cells * kH, kH);

  std::vector<Variant> vs;
  try {
    if (o.only != "fem") {
      for (const char* k : {"free", "lk", "kv", "damping", "pml"}) {
        if (std::string(k) == "pml" && o.ppc < 4) continue;  // MUSL's layer needs 4 or 9 ppc
        Variant v{"MPM", k, "MUSL", {}, 0, {}};
        v.c = load_case_text(mpm_case(o, k, "MUSL"), (dir / "mpm.json").string());
        vs.push_back(std::move(v));
      }
      for (const char* k : {"free", "lk", "kv", "pml"}) {
        Variant v{"MPM", k, "USL", {}, 0, {}};
        v.c = load_case_text(mpm_case(o, k, "USL"), (dir / "mpm.json").string());
        vs.push_back(std::move(v));
      }
    }
    if (o.only != "mpm")
      for (const char* k : {"free", "lk", "kv", "damping", "pml"}) {
        Variant v{"FEM", k, "", {}, 0, {}};
        v.c = load_case_text(fem_case(o, k, geo), (dir / "fem.json").string());
        vs.push_back(std::move(v));
      }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_layers: %s\n", e.what());
    return 1;
  }
  if (!o.kind.empty()) {  // that boundary, and the free squares it is compared with
    std::vector<char> keep(vs.size(), 0);
    for (std::size_t i = 0; i < vs.size(); ++i)
      for (const Variant& w : vs)
        keep[i] |= vs[i].kind == o.kind || (vs[i].kind == "free" && w.kind == o.kind &&
                                            w.method == vs[i].method && w.scheme == vs[i].scheme);
    std::vector<Variant> kept;
    for (std::size_t i = 0; i < vs.size(); ++i)
      if (keep[i]) kept.push_back(std::move(vs[i]));
    vs = std::move(kept);
  }
  for (Variant& v : vs)
    v.layer_cells = (v.kind == "damping" || v.kind == "pml") ? o.layer : v.kind == "free" ? 0 : 1;

  std::printf("bench_layers: %d x %d cells (h = 1 mm, steel), layers on left, right and bottom, "
              "band and PML %d cells; %d steps x %d rounds in turns of 10, %d thread(s)\n",
              o.cells, o.cells, o.layer, o.steps, o.rounds, o.threads);
  for (Variant& v : vs)
    for (int s = 0; s < 20; ++s) step(v);
  // In turns of kTurn steps, the variants one after another, every step timed but each turn's
  // first (its caches hold the variant before's arrays).
  constexpr int kTurn = 10;
  const int turns = std::max(1, o.steps / kTurn);
  for (int r = 0; r < o.rounds; ++r)
    for (int b = 0; b < turns; ++b)
      for (Variant& v : vs)
        for (int s = 0; s < kTurn; ++s) {
          const double t0 = seconds(o.threads);
          step(v);
          if (s > 0) v.steps.push_back(seconds(o.threads) - t0);
        }
  std::printf("%-6s %-8s %-6s %12s %10s %14s\n", "method", "boundary", "scheme", "us/step",
              "vs free", "cost/cell");
  const double N = double(o.cells) * o.cells;
  for (const Variant& v : vs) {
    const Variant* f = nullptr;
    for (const Variant& w : vs)
      if (w.method == v.method && w.kind == "free" && w.scheme == v.scheme) f = &w;
    // Each step against the free square's step of the same turn and place (the wave where it
    // is in both): the median of those ratios.
    std::vector<double> r(v.steps.size());
    for (std::size_t k = 0; k < r.size(); ++k) r[k] = v.steps[k] / f->steps[k];
    const double ratio = median(r);
    std::printf("%-6s %-8s %-6s %12.1f %10.3f", v.method.c_str(), v.kind.c_str(),
                v.scheme.empty() ? "-" : v.scheme.c_str(), 1e6 * median(v.steps), ratio);
    if (v.layer_cells > 0)
      std::printf(" %14.2f\n", 1 + (ratio - 1) * N / layer_cells(o.cells, v.layer_cells));
    else
      std::printf(" %14s\n", "-");
  }
  return 0;
}
