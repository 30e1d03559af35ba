#pragma once
// The MPM counterpart of oblique.hpp: the same geometry, pulse, beam, receiver and windows, on
// MPM bodies (1 particle per cell unless Setup::ppc, MUSL (USL with a pml) unless Setup::scheme, the default semi-implicit nodal silent layer on the
// right side of run A), with the particles of A and B on the same lattice and the identical dt
// (CFL 0.3 of h / c_d). The initial condition sets the particles' velocity and stress from the
// plane pulse. P and S are separated with div u and curl u at R (docs/physics.md §4.1: R are
// displacement-amplitude ratios): central differences of the solver's probe sampling of the
// velocity at R +- h, integrated over the steps from the exact initial values. (Taken on the
// velocity instead, the ratios are the same for a plane wave, but numerical short-wave content
// of the reflection weighs one order more.)
#include "oblique.hpp"
#include "silentmpm/solver.hpp"

namespace smpm::oblique {

inline Result measure_mpm(const Setup& su) {
  const auto t_start = std::chrono::steady_clock::now();
  const Plane w(su);
  const double h = w.h, sig = w.sig, c = w.c;
  const Material& mat = w.mat;
  // Displacement amplitude 1e-6 h: particles must stay put (MPM moves them with the velocity).
  const double amp = 1e-6 * h;
  auto G = [&](double s) {
    return std::abs(s) < 4 * sig ? amp * std::exp(-0.5 * s * s / (sig * sig)) : 0.0;
  };
  auto dG = [&](double s) { return -s / (sig * sig) * G(s); };
  const double dt = 0.3 * h / mat.cd;
  auto build = [&](int cells_x, bool silent) {
    auto s = std::make_unique<Solver>();
    s->materials.push_back(mat);
    s->grid.init(-2 * h, -2 * h, h, cells_x + 4, w.ly + 4);
    s->seed_rectangle(0, 0, cells_x * h, w.ly * h, su.ppc == 9 ? 3 : su.ppc == 4 ? 2 : 1, 0, 0,
                      0, 0);
    if (silent && su.boundary == "pml") {  // in front of the dashpots, as in the FE far field
      PmlBand band;
      band.name = "pml";
      band.body = 0;
      band.c = cells_x * h;
      band.width = su.band * h;
      band.r0 = su.r0;
      band.power = su.power;
      band.alpha = su.alpha;
      band.parallel = su.parallel;
      s->pml_bands.push_back(band);
    }
    if (silent) {
      SilentBoundary sb;
      sb.layer = s->select_layer("right", 0, cells_x * h, 0, cells_x * h, w.ly * h, 1, 0, h);
      if (su.boundary == "kv") sb.delta = su.delta * h;
      sb.delayed = su.boundary == "delayed";  // the edge lies on a grid line, 1 ppc, MUSL
      s->silents.push_back(sb);
      if (su.boundary == "damping") {
        DampingLayer dl;
        dl.layer = s->select_layer("band", 0, cells_x * h, 0, cells_x * h, w.ly * h, 1, 0,
                                   su.band * h);
        dl.r0 = su.r0;
        dl.power = su.power;
        dl.beta0 = su.beta * h / mat.cd;
        s->dampers.push_back(dl);
      }
    }
    s->opt.threads = su.threads;
    // The particle layer's scheme by default (both runs): USL; MUSL and USF take it at 4 and 9
    // ppc, and at 1 with the frequency shift that oblique.cpp checks.
    if (su.boundary == "pml") s->opt.scheme = Scheme::USL;
    if (su.scheme == "usl") s->opt.scheme = Scheme::USL;
    if (su.scheme == "musl") s->opt.scheme = Scheme::MUSL;
    if (su.scheme == "usf") s->opt.scheme = Scheme::USF;
    s->opt.shape = su.shape;
    s->dt = dt;
    s->finalize();
    Particles& p = s->p;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double px = p.x[k] - w.x0, py = p.y[k] - w.y0;
      const double sn = w.nx * px + w.ny * py, r = w.tx * px + w.ty * py;
      // The initial data cut off before the boundary (oblique.hpp): E times W(x).
      const double wc = w.cut(p.x[k]), wcs = w.cut_slope(p.x[k]);
      const double e = w.envelope(r) * wc, g = G(sn), gp = dG(sn), ep = w.envelope_slope(r) * wc;
      p.vx[k] = -c * w.dx * gp * e;
      p.vy[k] = -c * w.dy * gp * e;
      // grad u = d (x) (n G' E W + t G E' W + x G E W')
      const double ax = w.nx * gp * e + w.tx * g * ep + g * w.envelope(r) * wcs;
      const double ay = w.ny * gp * e + w.ty * g * ep;
      const double exx = w.dx * ax, eyy = w.dy * ay, gxy = w.dx * ay + w.dy * ax;
      const double tr = exx + eyy;
      p.sxx[k] = mat.lambda * tr + 2 * mat.mu * exx;
      p.syy[k] = mat.lambda * tr + 2 * mat.mu * eyy;
      p.szz[k] = mat.lambda * tr;
      p.sxy[k] = mat.mu * gxy;
    }
    return s;
  };
  auto A = build(w.lx, true);
  auto B = build(w.lx + w.lext, false);
  const std::vector<std::array<double, 2>> pts = {
      {w.rx + h, w.ry}, {w.rx - h, w.ry}, {w.rx, w.ry + h}, {w.rx, w.ry - h}};
  auto divcurl = [&](const Solver& s, double& dv, double& cv) {
    const auto q = s.sample(pts);
    dv = (q[0].vx - q[1].vx + q[2].vy - q[3].vy) / (2 * h);
    cv = (q[0].vy - q[1].vy - q[2].vx + q[3].vx) / (2 * h);
  };
  // div u and curl u of the initial pulse at R (the same in A and B).
  double div0, curl0;
  {
    const double px = w.rx - w.x0, py = w.ry - w.y0;
    const double sn = w.nx * px + w.ny * py, r = w.tx * px + w.ty * py;
    const double wc = w.cut(w.rx), wcs = w.cut_slope(w.rx);
    const double e = w.envelope(r) * wc, g = G(sn), gp = dG(sn), ep = w.envelope_slope(r) * wc;
    const double ax = w.nx * gp * e + w.tx * g * ep + g * w.envelope(r) * wcs;
    const double ay = w.ny * gp * e + w.ty * g * ep;
    div0 = w.dx * ax + w.dy * ay;
    curl0 = w.dx * ay - w.dy * ax;
  }
  double ua_div = div0, ua_curl = curl0, ub_div = div0, ub_curl = curl0;
  Result res;
  while (A->t < w.t_end) {
    A->step();
    B->step();
    double da, ca, db, cb;
    divcurl(*A, da, ca);
    divcurl(*B, db, cb);
    ua_div += da * dt, ua_curl += ca * dt, ub_div += db * dt, ub_curl += cb * dt;
    w.record(res, A->t, ua_div, ua_curl, ub_div, ub_curl);
  }
  w.finish(res, dt);
  res.dofs_a = A->p.size();
  res.dofs_b = B->p.size();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

}  // namespace smpm::oblique
