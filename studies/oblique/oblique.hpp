#pragma once
// Reflection of plane P and SV pulses at an LK dashpot boundary, measured in the FEM far-field by
// extended-domain differencing (docs/physics.md §4.1), against the closed form (lk_reflection).
// Used by studies/oblique (all angles) and tests/physics/test_fem_oblique.cpp (15 and 30 degrees).
//
// Geometry, in cells of size h (the boundary under test is the right side x = Lx, outward normal
// +x; angles are measured from that normal):
//   * run A: [0, 160] x [0, Ly] with LK dashpots (a = b = 1) on the right side, other sides free;
//   * run B: [0, 260] x [0, Ly], all sides free: the same mesh over A, so A - B at a receiver is
//     the field reflected by A's right side, until B's own right end answers (after the window);
//   * the incident wave is an initial condition: a plane pulse travelling along n = (cos t, sin t)
//     with displacement d G(n.(x - x0) - c t) E(t.(x - x0)), d = n (P) or t = (-sin, cos) (SV),
//     G a Gaussian whose full width at half maximum is `fwhm` cells, E a flat-topped beam
//     envelope (flat over 2 x 200 cells, 60-cell cos^2 tapers; Ly = 2 (flat + taper + 20) + 60),
//     so the rays that reach the receiver after reflection are in the flat part;
//   * receiver R: 20.5 cells inside the boundary (Setup::receiver), at y = flat + taper + 20.5
//     cells, on the beam's centre line; the pulse starts 4 sigma + 8 cells before R;
//   * with a layer (damping, pml) the initial data is cut off (a cos^2 ramp over 8 cells) 2 cells
//     before the layer, in A and in B alike: an inclined beam is hundreds of cells wide along its
//     front and would otherwise reach into the layer at t = 0, which would start filled with a
//     field that does not solve its equations (and past the boundary, where A lacks the part that
//     B has). The cut's own edge waves are the same in A and B. For LK and Kelvin-Voigt the data
//     is not cut: a cut 2 cells before the boundary sends its edge waves straight into it, and
//     their reflections, which a weak absorber returns in full, then dominate the window (LK, P
//     at 30 degrees: |R_PS| 0.016 with the cut, 0.011 without, closed form 0.009).
// Measured: incident max|div B| (P) or max|curl B| (SV) at R; reflected max|div(A - B)| and
// max|curl(A - B)|. |R_PP| = div ratio, |R_PS| = (c_s/c_d) curl ratio; |R_SS| = curl ratio,
// |R_SP| = (c_d/c_s) div ratio (beyond the SV critical angle the reflected P is evanescent and
// R_SP is not a travelling-wave amplitude: reported, not compared).
#include <chrono>
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "silentmpm/geo_box.hpp"
#include "silentmpm/fem.hpp"
#include "silentmpm/shape.hpp"
#include "silentmpm/lk_reflection.hpp"

namespace smpm::oblique {

struct Setup {
  bool sv = false;        // incident SV (else P)
  double angle_deg = 15;  // incidence angle from the boundary normal
  double h = 1e-3;
  int fwhm = 24;          // pulse width (cells, full width at half maximum of the displacement)
  int degree = 1;
  double nu = 0.25;
  int threads = 0;
  int flat = 200;          // half width of the beam's flat top (cells)
  int taper = 60;          // cos^2 taper beyond it (cells)
  smpm::ShapeKind shape = smpm::ShapeKind::Bilinear;  // MPM grid shape functions
  int ppc = 1;             // MPM: particles per cell, 1, 4 or 9
  std::string scheme;      // MPM: "usl", "musl" or "usf"; empty: MUSL, USL with a pml
  // The right side of run A: "lk" (dashpots), "kv" (dashpots and springs with `delta` cells),
  // "damping" (a graded damping band of `band` cells with r0 and power (default 2), then the dashpots),
  // "pml" (FEM: a perfectly matched layer of `band` cells with r0, power (default 2) and alpha, then the
  // dashpots).
  // With "damping", beta > 0 adds the band's stiffness-proportional part, beta h / c_d seconds.
  std::string boundary = "lk";
  double delta = 40, band = 10, r0 = 1e-3, alpha = 0, power = 2, beta = 0;
  double parallel = 0;  // pml: the multi-axial layer's share of d along the edge
  // Cells from the boundary to the receiver R. A layer's initial-data cut (clear()) and its ramp
  // of 8 cells reach the incident pulse's tail at normal incidence once they pass about 28 cells
  // (the pulse ends 4 sigma + 8 cells before R): layers of more than 15 cells need R further in.
  double receiver = 20.5;
  // Cells before the boundary where the initial data ends (a layer's thickness plus 2), or -1:
  // not cut (LK, Kelvin-Voigt).
  double clear() const { return boundary == "damping" || boundary == "pml" ? band + 2 : -1.0; }
  // FEM: split both runs over the MPI ranks (fem::Solver::distribute; MPI running).
  bool distributed = false;
};

struct Result {
  double incident = 0;          // max |div B| (P) or max |curl B| (SV) at R
  double refl_div = 0, refl_curl = 0;
  double r_same = 0, r_conv = 0;  // measured |R_PP|, |R_PS| (P) or |R_SS|, |R_SP| (SV)
  double exact_same = 0, exact_conv = 0;
  bool evanescent = false;      // SV beyond the critical angle: the reflected P does not travel
  double t_end = 0, dt = 0, seconds = 0;
  std::size_t dofs_a = 0, dofs_b = 0;
  std::vector<double> t, inc, ddiv, dcurl;  // receiver traces (incident, reflected div / curl)
  double window_incident = 0, window_p = 0, window_s = 0, window_half = 0;  // window centres, half width
};

inline std::string rectangle_geo(const std::string& name, double lx, double ly, double h) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("smpm_oblique_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / (name + ".geo");
  std::ofstream f(p);
  f << smpm::fem::box_geo_text(0, 0, lx, ly, h);
  return p.string();
}

// The geometry, pulse, beam envelope and receiver windows of one measurement (the FEM and the
// MPM runs share them).
struct Plane {
  bool sv;
  double h;
  int lx = 160, lext = 100;  // run A and the extension of run B (cells)
  int yr, ly;                // receiver row and mesh height (cells)
  Material mat;
  double th, c, nx, ny, tx, ty, dx, dy, F, T, sig, rx, ry, D, x0, y0;
  // Windows at R: the incident pulse, and each reflected pulse around its plane-wave arrival
  // (the reflected P returns after 2 d cos(theta_P) / c_d more, the reflected S after
  // d (cos(theta_in) / c_in + cos(theta_S) / c_s)), each as long as the pulse plus 4 cells of
  // travel on either side. Outside them R sees the waves the beam's tapered edges radiate.
  double k, t_inc, t_p, t_s, half, t_end;
  bool evanescent;
  double cut_end, cut_ramp;  // the initial data's cut: 0 from x = cut_end on, a cos^2 ramp before

  explicit Plane(const Setup& su) : sv(su.sv), h(su.h) {
    // Room for the beam: R sits (flat + taper + 20) cells above the bottom, the mesh is twice
    // that plus 60 cells tall.
    yr = su.flat + su.taper + 20;
    ly = 2 * yr + 60;
    mat.name = "solid";
    mat.E = 200e9;
    mat.nu = su.nu;
    mat.rho = 8000;
    mat.derive();
    th = su.angle_deg * M_PI / 180;
    c = su.sv ? mat.cs : mat.cd;
    nx = std::cos(th), ny = std::sin(th), tx = -ny, ty = nx;
    dx = su.sv ? tx : nx, dy = su.sv ? ty : ny;
    F = su.flat * h, T = su.taper * h;
    sig = su.fwhm * h / 2.3548;  // Gaussian sigma of the pulse
    rx = (lx - su.receiver) * h, ry = (yr + 0.5) * h;
    D = 4 * sig + 8 * h;
    x0 = rx - D * nx, y0 = ry - D * ny;
    k = mat.cs / mat.cd;
    const double dr = lx * h - rx;  // distance from R to the boundary
    const double sin_p = su.sv ? std::sin(th) / k : std::sin(th);  // reflected P angle
    const double sin_s = su.sv ? std::sin(th) : k * std::sin(th);  // reflected S angle
    evanescent = sin_p > 1;
    const double cos_p = evanescent ? 0.0 : std::sqrt(1 - sin_p * sin_p);
    const double cos_s = std::sqrt(1 - sin_s * sin_s);
    t_inc = D / c;
    t_p = t_inc + dr * (std::cos(th) / c + cos_p / mat.cd);
    t_s = t_inc + dr * (std::cos(th) / c + cos_s / mat.cs);
    half = 3 * sig / c + 4 * h / mat.cs;
    t_end = std::max(t_p, t_s) + half;
    cut_end = su.clear() < 0 ? 1e300 : (lx - su.clear()) * h;
    cut_ramp = 8 * h;
  }
  // The cut of the initial data along x, and its slope.
  double cut(double x) const {
    if (x <= cut_end - cut_ramp) return 1.0;
    if (x >= cut_end) return 0.0;
    return std::pow(std::cos(M_PI * (x - (cut_end - cut_ramp)) / (2 * cut_ramp)), 2);
  }
  double cut_slope(double x) const {
    if (x <= cut_end - cut_ramp || x >= cut_end) return 0.0;
    const double q = M_PI * (x - (cut_end - cut_ramp)) / (2 * cut_ramp);
    return -M_PI / (2 * cut_ramp) * 2 * std::sin(q) * std::cos(q);
  }
  // Beam envelope across the direction of travel: flat over |r| <= F, cos^2 taper over T.
  double envelope(double r) const {
    const double a = std::abs(r);
    if (a <= F) return 1.0;
    if (a >= F + T) return 0.0;
    return std::pow(std::cos(M_PI * (a - F) / (2 * T)), 2);
  }
  double envelope_slope(double r) const {
    const double a = std::abs(r);
    if (a <= F || a >= F + T) return 0.0;
    const double q = M_PI * (a - F) / (2 * T);
    return -(r > 0 ? 1.0 : -1.0) * M_PI / (2 * T) * 2 * std::sin(q) * std::cos(q);
  }
  // One receiver sample: div and curl of run A and run B at R.
  void record(Result& res, double t, double div_a, double curl_a, double div_b,
              double curl_b) const {
    const double inc = sv ? curl_b : div_b;
    if (std::abs(t - t_inc) <= half) res.incident = std::max(res.incident, std::abs(inc));
    if (std::abs(t - t_p) <= half) res.refl_div = std::max(res.refl_div, std::abs(div_a - div_b));
    if (std::abs(t - t_s) <= half)
      res.refl_curl = std::max(res.refl_curl, std::abs(curl_a - curl_b));
    res.t.push_back(t);
    res.inc.push_back(inc);
    res.ddiv.push_back(div_a - div_b);
    res.dcurl.push_back(curl_a - curl_b);
  }
  // The measured ratios beside the closed form.
  void finish(Result& res, double dt) const {
    res.window_incident = t_inc;
    res.window_p = t_p;
    res.window_s = t_s;
    res.window_half = half;
    const LKReflection ex = lk_reflection(mat.nu, 1, 1, th);
    if (sv) {
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
  }
};

inline Result measure(const Setup& su) {
  const auto t_start = std::chrono::steady_clock::now();
  const Plane w(su);
  const double h = w.h, sig = w.sig, c = w.c;
  // Gaussian displacement profile (smooth, so no grid-scale content that the coarse-mesh
  // dispersion would smear over the reflected window), cut at 4 sigma.
  auto G = [&](double s) { return std::abs(s) < 4 * sig ? std::exp(-0.5 * s * s / (sig * sig)) : 0.0; };
  auto dG = [&](double s) { return -s / (sig * sig) * G(s); };

  auto build = [&](int cells_x, bool dashpot) {
    fem::Spec s;
    s.mesh = fem::load_mesh(
        rectangle_geo("oblique_" + std::to_string(cells_x) + "x" + std::to_string(w.ly) + "_h" +
                          std::to_string(std::lround(h * 1e9)),
                      cells_x * h, w.ly * h, h),
        h);
    s.degree = su.degree;
    s.materials = {w.mat};
    s.region_material = {{1, 0}};
    s.threads = su.threads;
    if (dashpot) {
      fem::Boundary b;
      b.kind = fem::Boundary::Kind::Dashpot;
      b.curves = {12};
      b.name = "right";
      if (su.boundary == "kv") b.delta = su.delta * h;
      s.boundaries.push_back(b);
      if (su.boundary == "damping" || su.boundary == "pml") {
        fem::Boundary d;
        d.kind = su.boundary == "pml" ? fem::Boundary::Kind::Pml : fem::Boundary::Kind::Damping;
        d.alpha = su.alpha;
        d.parallel = su.parallel;
        d.curves = {12};
        d.name = "band";
        d.width = su.band * h;
        d.r0 = su.r0;
        d.power = su.power;
        if (su.boundary == "damping") d.beta = su.beta * h / w.mat.cd;
        s.boundaries.push_back(d);
      }
    }
    return std::make_unique<fem::Solver>(s);
  };
  auto A = build(w.lx, true);
  auto B = build(w.lx + w.lext, false);
  const double dt = 0.5 * std::min(A->critical_dt(), B->critical_dt());
  for (fem::Solver* s : {A.get(), B.get()}) {
    s->set_dt(dt);
    auto& u = s->displacement();
    auto& v = s->velocity();
    for (std::size_t i = 0; i < s->nodes(); ++i) {
      const double px = s->node_x()[i] - w.x0, py = s->node_y()[i] - w.y0;
      const double sn = w.nx * px + w.ny * py, r = w.tx * px + w.ty * py;
      const double e = w.envelope(r) * w.cut(s->node_x()[i]);
      const double g = G(sn) * e;
      // v at t = -dt/2: -c d G'(s + c dt / 2) E
      const double gv = -c * dG(sn + 0.5 * c * dt) * e;
      u[2 * i] = w.dx * g;
      u[2 * i + 1] = w.dy * g;
      v[2 * i] = w.dx * gv;
      v[2 * i + 1] = w.dy * gv;
    }
    if (s->add_probe(w.rx, w.ry) != 0) throw std::runtime_error("oblique: receiver outside the mesh");
    if (su.distributed) s->distribute();
  }
  Result res;
  while (A->t < w.t_end) {
    A->step();
    B->step();
    const fem::Sample a = A->sample()[0], b = B->sample()[0];
    w.record(res, A->t, a.div, a.curl, b.div, b.curl);
  }
  w.finish(res, dt);
  res.dofs_a = A->dofs();
  res.dofs_b = B->dofs();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

}  // namespace smpm::oblique
