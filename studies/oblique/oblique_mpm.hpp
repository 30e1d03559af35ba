#pragma once
// The MPM counterpart of oblique.hpp: the same geometry, pulse, beam, receiver and windows, on
// MPM bodies (1 particle per cell, MUSL, the default semi-implicit nodal silent layer on the
// right side of run A), with the particles of A and B on the same lattice and the identical dt
// (CFL 0.3 of h / c_d). The initial condition sets the particles' velocity and stress from the
// plane pulse. P and S are separated with div v and curl v at R, from central differences of the
// solver's probe sampling at R +- h (for a plane wave the ratios of their maxima are the same
// displacement-amplitude ratios as with div u and curl u: d/dt scales both by the same frequency).
#include "oblique.hpp"
#include "silentmpm/solver.hpp"

namespace smpm::oblique {

inline Result measure_mpm(const Setup& su) {
  const auto t_start = std::chrono::steady_clock::now();
  const double h = su.h;
  const int lx = 160, lext = 100;
  const int yr = su.flat + su.taper + 20, ly = 2 * yr + 60;
  Material mat;
  mat.name = "solid";
  mat.E = 200e9;
  mat.nu = su.nu;
  mat.rho = 8000;
  mat.derive();
  const double th = su.angle_deg * M_PI / 180;
  const double c = su.sv ? mat.cs : mat.cd;
  const double nx = std::cos(th), ny = std::sin(th), tx = -ny, ty = nx;
  const double dx = su.sv ? tx : nx, dy = su.sv ? ty : ny;
  const double W = su.fwhm * h, F = su.flat * h, T = su.taper * h;
  const double sig = W / 2.3548;
  const double rx = (lx - 20.5) * h, ry = (yr + 0.5) * h;
  const double D = 4 * sig + 8 * h;
  const double x0 = rx - D * nx, y0 = ry - D * ny;
  // Displacement amplitude 1e-6 h: particles must stay put (MPM moves them with the velocity).
  const double amp = 1e-6 * h;
  auto G = [&](double s) {
    return std::abs(s) < 4 * sig ? amp * std::exp(-0.5 * s * s / (sig * sig)) : 0.0;
  };
  auto dG = [&](double s) { return -s / (sig * sig) * G(s); };
  auto E = [&](double r) {
    const double a = std::abs(r);
    if (a <= F) return 1.0;
    if (a >= F + T) return 0.0;
    return std::pow(std::cos(M_PI * (a - F) / (2 * T)), 2);
  };
  auto dE = [&](double r) {
    const double a = std::abs(r);
    if (a <= F || a >= F + T) return 0.0;
    const double q = M_PI * (a - F) / (2 * T);
    return -(r > 0 ? 1.0 : -1.0) * M_PI / (2 * T) * 2 * std::sin(q) * std::cos(q);
  };
  const double dt = 0.3 * h / mat.cd;
  auto build = [&](int cells_x, bool silent) {
    auto s = std::make_unique<Solver>();
    s->materials.push_back(mat);
    s->grid.init(-2 * h, -2 * h, h, cells_x + 4, ly + 4);
    s->seed_rectangle(0, 0, cells_x * h, ly * h, 1, 0, 0, 0, 0);
    if (silent) {
      SilentBoundary sb;
      sb.layer = s->select_layer("right", 0, cells_x * h, 0, cells_x * h, ly * h, 1, 0, h);
      s->silents.push_back(sb);
    }
    s->opt.threads = su.threads;
    s->dt = dt;
    s->finalize();
    Particles& p = s->p;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double px = p.x[k] - x0, py = p.y[k] - y0;
      const double sn = nx * px + ny * py, r = tx * px + ty * py;
      const double e = E(r), g = G(sn), gp = dG(sn), ep = dE(r);
      p.vx[k] = -c * dx * gp * e;
      p.vy[k] = -c * dy * gp * e;
      // grad u = d (x) (n G' E + t G E')
      const double ax = nx * gp * e + tx * g * ep, ay = ny * gp * e + ty * g * ep;
      const double exx = dx * ax, eyy = dy * ay, gxy = dx * ay + dy * ax;
      const double tr = exx + eyy;
      p.sxx[k] = mat.lambda * tr + 2 * mat.mu * exx;
      p.syy[k] = mat.lambda * tr + 2 * mat.mu * eyy;
      p.szz[k] = mat.lambda * tr;
      p.sxy[k] = mat.mu * gxy;
    }
    return s;
  };
  auto A = build(lx, true);
  auto B = build(lx + lext, false);
  const std::vector<std::array<double, 2>> pts = {
      {rx + h, ry}, {rx - h, ry}, {rx, ry + h}, {rx, ry - h}};
  auto divcurl = [&](const Solver& s, double& dv, double& cv) {
    const auto q = s.sample(pts);
    dv = (q[0].vx - q[1].vx + q[2].vy - q[3].vy) / (2 * h);
    cv = (q[0].vy - q[1].vy - q[2].vx + q[3].vx) / (2 * h);
  };
  const double k = mat.cs / mat.cd;
  const double dr = lx * h - rx;
  const double sin_p = su.sv ? std::sin(th) / k : std::sin(th);
  const double sin_s = su.sv ? std::sin(th) : k * std::sin(th);
  const bool evanescent = sin_p > 1;
  const double cos_p = evanescent ? 0.0 : std::sqrt(1 - sin_p * sin_p);
  const double cos_s = std::sqrt(1 - sin_s * sin_s);
  const double t_inc = D / c;
  const double t_p = t_inc + dr * (std::cos(th) / c + cos_p / mat.cd);
  const double t_s = t_inc + dr * (std::cos(th) / c + cos_s / mat.cs);
  const double half = 3 * sig / c + 4 * h / mat.cs;
  const double t_end = std::max(t_p, t_s) + half;
  Result res;
  while (A->t < t_end) {
    A->step();
    B->step();
    double da, ca, db, cb;
    divcurl(*A, da, ca);
    divcurl(*B, db, cb);
    const double tt = A->t;
    if (std::abs(tt - t_inc) <= half) res.incident = std::max(res.incident, std::abs(su.sv ? cb : db));
    if (std::abs(tt - t_p) <= half) res.refl_div = std::max(res.refl_div, std::abs(da - db));
    if (std::abs(tt - t_s) <= half) res.refl_curl = std::max(res.refl_curl, std::abs(ca - cb));
    res.t.push_back(tt);
    res.inc.push_back(su.sv ? cb : db);
    res.ddiv.push_back(da - db);
    res.dcurl.push_back(ca - cb);
  }
  res.window_incident = t_inc;
  res.window_p = t_p;
  res.window_s = t_s;
  res.window_half = half;
  const LKReflection ex = lk_reflection(su.nu, 1, 1, th);
  if (su.sv) {
    res.r_same = res.refl_curl / res.incident;
    res.r_conv = res.refl_div / res.incident / k;
    res.exact_same = std::abs(ex.rss);
    res.exact_conv = std::abs(ex.rsp);
    res.evanescent = evanescent;
  } else {
    res.r_same = res.refl_div / res.incident;
    res.r_conv = k * res.refl_curl / res.incident;
    res.exact_same = std::abs(ex.rpp);
    res.exact_conv = std::abs(ex.rps);
  }
  res.t_end = t_end;
  res.dt = dt;
  res.dofs_a = A->p.size();
  res.dofs_b = B->p.size();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

}  // namespace smpm::oblique
