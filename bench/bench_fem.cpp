// bench_fem: DoF-updates per second of the FEM far-field's explicit step (internal force as a
// node-block sparse matrix-vector product, semi-implicit dashpots, tractions) for Q1 and Q2 at
// about 1e6 degrees of freedom, on 1 and 2 threads.
//
//   bench_fem [--dofs N] [--steps S] [--threads "1 2"]
//
// A square plate of side 1 m, square cells (Q1: 707^2 cells, Q2: 354^2 cells for 1e6 dofs),
// traction on the left, LK dashpots on the right, rollers on top and bottom. Prints one line per
// (degree, threads) and the speed-up, and how close the rate comes to the host's memory
// bandwidth: the triad measured in the same run (bench/triad.hpp) against the bytes a step moves,
// counted as bench counts them (each array a pass reads once, each it writes once more). The
// step is one pass over the rows (K u and the nodal update together, u^{n+1} written to a second
// buffer), per node:
//   R rowptr (8), the blocks (4 column per block; 32 values per stored block: every block, or
//   where rows share their values (a structured mesh) each kind of row's once, and an offset of
//   4 per node), u^n (16, its neighbours' entries from cache), f_ext (16), constraint mask (1),
//   dashpot index (4), 1/m (8); W -K u (16, kept for the energies), u^{n+1} (16); RW v (32)
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "silentmpm/fem.hpp"
#include "triad.hpp"

using namespace smpm;
namespace fs = std::filesystem;

namespace {

std::string square_geo(int cells) {
  const fs::path p = fs::temp_directory_path() / ("smpm_bench_fem_" + std::to_string(cells) + ".geo");
  std::ofstream f(p);
  f << "DefineConstant[ h = {" << 1.0 / cells << ", Name \"Parameters/h\"} ];\n"
    << "Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};\n"
    << "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
    << "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
    << "Transfinite Curve{1, 2, 3, 4} = Round(1 / h) + 1;\n"
    << "Transfinite Surface{1}; Recombine Surface{1};\n"
    << "Physical Surface(\"plate\", 1) = {1};\n"
    << "Physical Curve(\"left\", 11) = {4}; Physical Curve(\"right\", 12) = {2};\n"
    << "Physical Curve(\"bottom\", 13) = {1}; Physical Curve(\"top\", 14) = {3};\n";
  return p.string();
}

fem::Spec plate(int degree, double target_dofs) {
  const int cells = static_cast<int>(std::lround(std::sqrt(target_dofs / 2.0) / degree));
  fem::Spec s;
  s.mesh = fem::load_mesh(square_geo(cells), 0);
  s.degree = degree;
  Material m;
  m.name = "tungsten";
  m.E = 411e9;
  m.nu = 0.28;
  m.rho = 15000;
  m.derive();
  s.materials = {m};
  s.region_material = {{1, 0}};
  fem::Boundary load;
  load.kind = fem::Boundary::Kind::Traction;
  load.curves = {11};
  load.normal = -1e8;
  load.fn.kind = TimeFunction::Kind::Step;
  fem::Boundary dash;
  dash.kind = fem::Boundary::Kind::Dashpot;
  dash.curves = {12};
  fem::Boundary r1, r2;
  r1.kind = r2.kind = fem::Boundary::Kind::Roller;
  r1.curves = {13};
  r2.curves = {14};
  r1.component = r2.component = 1;
  s.boundaries = {load, dash, r1, r2};
  return s;
}

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  double target = 1e6;
  int steps = 100;
  std::vector<int> threads = {1, 2};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--dofs" && i + 1 < argc) target = std::atof(argv[++i]);
    else if (a == "--steps" && i + 1 < argc) steps = std::atoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) {
      threads.clear();
      std::istringstream in(argv[++i]);
      for (int t; in >> t;) threads.push_back(t);
    } else {
      std::fprintf(stderr, "usage: bench_fem [--dofs N] [--steps S] [--threads \"1 2\"]\n");
      return a == "--help" || a == "-h" ? 0 : 1;
    }
  }
  std::vector<double> triad;
  for (int th : threads) triad.push_back(benchmarks::triad_gbs(th));
  for (std::size_t k = 0; k < threads.size(); ++k)
    std::printf("triad (3 x 512 MiB, best of 5) on %d thread(s): %.1f GB/s\n", threads[k], triad[k]);
  try {
    for (int degree : {1, 2}) {
      double base = 0;
      for (const int& th : threads) {
        fem::Spec spec = plate(degree, target);
        spec.threads = th;
        const auto t_setup = std::chrono::steady_clock::now();
        fem::Solver s(spec);
        const double setup = seconds(t_setup);
        s.set_dt(0.5 * s.critical_dt());
        for (int k = 0; k < 5; ++k) s.step();  // warm-up
        const auto t0 = std::chrono::steady_clock::now();
        for (int k = 0; k < steps; ++k) s.step();
        const double el = seconds(t0);
        const double rate = static_cast<double>(s.dofs()) * steps / el;
        // The matrix-vector product alone.
        std::vector<double> f(s.dofs());
        const auto t1 = std::chrono::steady_clock::now();
        for (int k = 0; k < steps; ++k) s.internal_force(s.displacement().data(), f.data());
        const double mv = static_cast<double>(s.dofs()) * steps / seconds(t1);
        if (th == threads.front()) base = rate;
        const double bytes = 4.0 * s.matrix_blocks() + 32.0 * s.stored_blocks() +
                             (8 + 16 + 16 + 16 + 1 + 4 + 8 + 16 + 32.0 + (s.rows_shared() ? 4 : 0)) * s.nodes();
        const double per_dof = bytes / s.dofs();
        const double gbs = rate * per_dof / 1e9;
        const std::size_t k = static_cast<std::size_t>(&th - threads.data());
        std::printf("Q%d  %8zu dofs  %zu cells  threads %d  setup %.2f s  step %.3f ms  "
                    "%.1f M dof-updates/s (K u alone %.1f M/s)  speed-up %.2f  %.0f B/dof-update  "
                    "%.1f GB/s, %.0f%% of the triad  (K: %zu of %zu blocks stored)\n",
                    degree, s.dofs(), s.cells(), th, setup, 1e3 * el / steps, rate / 1e6, mv / 1e6,
                    rate / base, per_dof, gbs, 100 * gbs / triad[k], s.stored_blocks(),
                    s.matrix_blocks());
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_fem: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
