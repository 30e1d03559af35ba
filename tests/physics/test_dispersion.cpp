// The MPM step's dispersion relation in closed form (docs/physics.md section 1.1): a standing
// wave of a free column, every particle started on the grid's interpolant of cos(kx), follows a
// two-term recurrence whose coefficients the scheme, the particles' places in the cell and the
// mass correction fix exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "common.hpp"

using namespace smpm;
using namespace smpm::testing;

namespace {

struct Recurrence {
  double trace = 0, det = 0;  // A[n+1] = trace A[n] - det A[n-1]
};

// The column's mode n (wavenumber n pi / L) from rest with velocity amplitude v0: the
// recurrence fitted by least squares to 400 steps of the mode's amplitude on the particles.
Recurrence fit_mode(const ColumnSpec& c, int n, double& kh, double& x) {
  auto s = make_column(c);
  const double L = c.cells * c.h, k = n * M_PI / L, v0 = 1e-3;
  const Grid& g = s->grid;
  // The grid's interpolant (no part of the particles' velocity outside the grid's picture).
  for (std::size_t q = 0; q < s->p.size(); ++q) {
    const double f = (s->p.x[q] - g.x0) / g.h;
    const double i = std::floor(f), a = f - i;
    s->p.vx[q] = v0 * ((1 - a) * std::cos(k * g.node_x(static_cast<int>(i))) +
                       a * std::cos(k * g.node_x(static_cast<int>(i) + 1)));
    s->p.vy[q] = 0;
  }
  auto amplitude = [&] {
    double a = 0;
    for (std::size_t q = 0; q < s->p.size(); ++q) a += s->p.mass[q] * s->p.vx[q] * std::cos(k * s->p.x0[q]);
    return a;
  };
  std::vector<double> A{amplitude()};
  for (int step = 0; step < 400; ++step) {
    s->step();
    A.push_back(amplitude());
  }
  double s11 = 0, s12 = 0, s22 = 0, r1 = 0, r2 = 0;
  for (std::size_t i = 1; i + 1 < A.size(); ++i) {
    s11 += A[i] * A[i]; s12 += A[i] * A[i - 1]; s22 += A[i - 1] * A[i - 1];
    r1 += A[i] * A[i + 1]; r2 += A[i - 1] * A[i + 1];
  }
  const double d = s11 * s22 - s12 * s12;
  const double cd = s->materials[0].cd;
  kh = k * c.h;
  x = std::pow(s->dt * 2 * cd / c.h * std::sin(kh / 2), 2);  // (dt omega_lumped-static)^2
  return {(r1 * s22 - r2 * s12) / d, -(s11 * r2 - s12 * r1) / d};
}

// R's eigenvalue for a wave along x: the consistent mass over the lumped one of particles at
// xi_j with shares w_j of the cell side, 1 - 2 sum_j w_j xi_j (1 - xi_j) (1 - cos kh): at the
// centres of the ppc x ppc sub-cells (w_j = 1 / ppc), or at the Gauss points (then 2/3 + 1/3 cos
// kh from 4 ppc on, FE's consistent mass).
double mass_ratio(int ppc, double kh, Seeding seeding) {
  double sum = 0;
  for (int j = 0; j < ppc; ++j) {
    double xi = (j + 0.5) / ppc, w = 1.0 / ppc;
    if (seeding == Seeding::Gauss) Solver::gauss_point(ppc, j, xi, w);
    sum += w * xi * (1 - xi);
  }
  return 1 - 2 * sum * (1 - std::cos(kh));
}

}  // namespace

// With x = (dt omega)^2 of the lumped-mass grid (omega = 2 c_d / h sin(kh / 2)) and r = R's
// eigenvalue: MUSL and USF A[n+1] = (2 - rho x) A[n] - A[n-1] with rho = 1 - (1 - r)^(k+1) for k
// terms of the mass correction (rho = r without it); USL, which strains with the lumped
// increment, trace 2 - x and det 1 - (1 - rho) x. The symmetric form, k terms of the series of
// r^-1/2, y = sum_j c_j (1 - r)^j (c_j = 1, 1/2, 3/8, ...), on the increment and on the strain's
// velocity: rho = r y^2. Measured to 1e-12 of the trace; bound 1e-9 (and on the determinant).
TEST(Dispersion, ColumnModeFollowsTheSchemesClosedForm) {
  struct Run {
    Scheme scheme;
    int terms;
    Seeding seeding = Seeding::Uniform;
    bool symmetric = false;
  };
  const Run runs[] = {{Scheme::MUSL, 0}, {Scheme::USF, 0}, {Scheme::USL, 0},
                      {Scheme::MUSL, 1}, {Scheme::USF, 1}, {Scheme::MUSL, 2},
                      {Scheme::USL, 1}, {Scheme::USL, 2},
                      {Scheme::MUSL, 0, Seeding::Gauss}, {Scheme::USL, 0, Seeding::Gauss},
                      {Scheme::MUSL, 2, Seeding::Gauss}, {Scheme::USL, 2, Seeding::Gauss},
                      {Scheme::MUSL, 1, Seeding::Uniform, true},
                      {Scheme::USF, 1, Seeding::Uniform, true},
                      {Scheme::MUSL, 2, Seeding::Uniform, true},
                      {Scheme::USF, 2, Seeding::Uniform, true},
                      {Scheme::MUSL, 2, Seeding::Gauss, true}};
  for (const Run& run : runs)
    for (const int ppc : {1, 2, 3})
      for (const int n : {4, 10}) {
        ColumnSpec c;
        c.cells = 40;
        c.height = 2;
        c.ppc_side = ppc;
        c.end = End::Free;
        c.amplitude = 0;
        c.cells_beyond = 2;
        c.scheme = run.scheme;
        c.mass_correction = run.terms;
        c.seeding = run.seeding;
        c.symmetric = run.symmetric;
        double kh = 0, x = 0;
        const Recurrence f = fit_mode(c, n, kh, x);
        const double r = mass_ratio(ppc, kh, run.seeding);
        // R's factor with k terms of the correction (r itself with none).
        double rho = 1 - std::pow(1 - r, run.terms + 1);
        if (run.symmetric) {
          double y = 1, cj = 1, e = 1;
          for (int j = 1; j <= run.terms; ++j) {
            cj *= (2.0 * j - 1) / (2.0 * j);
            e *= 1 - r;
            y += cj * e;
          }
          rho = r * y * y;
        }
        const Recurrence cf = run.scheme == Scheme::USL ? Recurrence{2 - x, 1 - (1 - rho) * x}
                                                        : Recurrence{2 - rho * x, 1};
        // The frequency over the lumped mass's (FE Q1's) at this step.
        const double ratio = std::acos(f.trace / (2 * std::sqrt(f.det))) / std::acos(1 - x / 2);
        std::printf("  [%s, %d terms%s, %d ppc%s, kh %.3f] trace %.12f (closed form %.12f), det "
                    "%.12f (%.12f); frequency over the lumped mass's %.5f\n",
                    scheme_name(run.scheme), run.terms, run.symmetric ? ", symmetric" : "",
                    ppc * ppc,
                    run.seeding == Seeding::Gauss ? " at the Gauss points" : "", kh, f.trace,
                    cf.trace, f.det, cf.det, ratio);
        EXPECT_NEAR(f.trace, cf.trace, 1e-9) << scheme_name(run.scheme) << " " << ppc * ppc;
        EXPECT_NEAR(f.det, cf.det, 1e-9) << scheme_name(run.scheme) << " " << ppc * ppc;
      }
}
