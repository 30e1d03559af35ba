// bench: particle-updates per second of the MPM step on the pulse plate (tungsten, elastic,
// MUSL, 1 particle per cell), refined to about 1e5 and 1e6 particles, on one thread and on all
// threads, with a free and with a silent right boundary; and bytes per particle.
//
//   build/bench [--quick] [--shape bilinear|gimp|bspline|all]
//     --quick: only the 1e5 size, fewer steps; --shape: the grid shape functions (default
//     bilinear; all: the three, alternating per size and thread count)
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "silentmpm/solver.hpp"

using namespace smpm;

namespace {

std::unique_ptr<Solver> pulse_plate(double h, bool silent, int threads,
                                    ShapeKind shape = ShapeKind::Bilinear) {
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
  s->dt = 0.237 * h / w.cd;
  s->finalize();
  return s;
}

double rate(double h, bool silent, int threads, int steps, ShapeKind shape) {
  auto s = pulse_plate(h, silent, threads, shape);
  for (int i = 0; i < 3; ++i) s->step();  // warm-up
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s->step();
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return static_cast<double>(s->p.size()) * steps / sec;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
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
    } else {
      std::fprintf(stderr, "bench: unknown argument \"%s\"; usage: bench [--quick] "
                           "[--shape bilinear|gimp|bspline|all]\n", argv[i]);
      return 1;
    }
  }
  const int all = omp_get_max_threads();
  std::printf("silentmpm bench: pulse plate 50 x 200 mm, tungsten, elastic, MUSL, 1 ppc\n");
  std::printf("bytes per particle (particle arrays): %zu\n", Particles::bytes_per_particle());
  std::printf("%10s %9s %8s %8s %14s %9s\n", "particles", "boundary", "threads", "steps",
              "updates/s", "shape");
  for (double h : {1e-4 * std::sqrt(10.0), 1e-4}) {
    if (quick && h < 2e-4) continue;
    auto probe = pulse_plate(h, false, 1);
    const std::size_t n = probe->p.size();
    const std::size_t grid_bytes = probe->grid.nodes() * (14 * sizeof(double) + 1);
    std::printf("# %zu particles, %zu grid nodes: %.0f bytes per particle including the grid\n", n,
                probe->grid.nodes(), Particles::bytes_per_particle() + double(grid_bytes) / n);
    probe.reset();
    const int steps = quick ? 20 : (n > 500000 ? 30 : 200);
    for (int th : {1, all}) {
      for (bool silent : {false, true})
        for (ShapeKind shape : shapes) {
          const double r = rate(h, silent, th, steps, shape);
          std::printf("%10zu %9s %8d %8d %14.3e %9s\n", n, silent ? "silent" : "free", th, steps, r,
                      shape_name(shape));
          std::fflush(stdout);
        }
      if (all == 1) break;
    }
  }
  return 0;
}
