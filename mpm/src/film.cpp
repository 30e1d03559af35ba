// Bifurcation sweep, closed-form J2 criterion and the decohesion return mapping
// (bifurcation.hpp, decohesion.hpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "silentmpm/bifurcation.hpp"
#include "silentmpm/decohesion.hpp"

namespace smpm {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Golden-section minimisation of f on [a, b].
template <class F>
double golden_min(F&& f, double a, double b, int iters, double& fmin) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < iters; ++i) {
    if (fc <= fd) {
      b = d; d = c; fd = fc;
      c = b - g * (b - a); fc = f(c);
    } else {
      a = c; c = d; fc = fd;
      d = a + g * (b - a); fd = f(d);
    }
  }
  const double x = fc <= fd ? c : d;
  fmin = std::min(fc, fd);
  return x;
}

double wrap_deg(double t) {
  t = std::fmod(t, 180.0);
  if (t < 0) t += 180.0;
  if (t > 180.0 - 1e-7) t = 0.0;  // n and -n are one plane
  return t;
}
}  // namespace

double acoustic_det(const double C[16], double th) {
  const double n[2] = {std::cos(th), std::sin(th)};
  double Q[2][2] = {{0, 0}, {0, 0}};
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k) {
      double s = 0;
      for (int i = 0; i < 2; ++i)
        for (int l = 0; l < 2; ++l) s += n[i] * C[((i * 2 + j) * 2 + k) * 2 + l] * n[l];
      Q[j][k] = s;
    }
  return Q[0][0] * Q[1][1] - Q[0][1] * Q[1][0];
}

BifurcationResult bifurcation_sweep(const double C[16], const BifurcationParams& P, double scale) {
  // Q_jk(n) = n_x^2 C_0jk0 + n_x n_y (C_0jk1 + C_1jk0) + n_y^2 C_1jk1: nine coefficients once,
  // then every angle costs a handful of flops.
  double A[2][2], B[2][2], D[2][2];
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k) {
      A[j][k] = C[((0 * 2 + j) * 2 + k) * 2 + 0];
      B[j][k] = C[((0 * 2 + j) * 2 + k) * 2 + 1] + C[((1 * 2 + j) * 2 + k) * 2 + 0];
      D[j][k] = C[((1 * 2 + j) * 2 + k) * 2 + 1];
    }
  auto det_at = [&](double c, double s) {
    const double xx = c * c, xy = c * s, yy = s * s;
    const double q00 = A[0][0] * xx + B[0][0] * xy + D[0][0] * yy;
    const double q01 = A[0][1] * xx + B[0][1] * xy + D[0][1] * yy;
    const double q10 = A[1][0] * xx + B[1][0] * xy + D[1][0] * yy;
    const double q11 = A[1][1] * xx + B[1][1] * xy + D[1][1] * yy;
    return q00 * q11 - q01 * q10;
  };
  auto det_deg = [&](double t) { return det_at(std::cos(t * kDeg), std::sin(t * kDeg)); };
  const int n = std::max(4, static_cast<int>(std::lround(180.0 / P.step_deg)));
  const double step = 180.0 / n;
  double dv[3600];
  std::vector<double> dyn;
  double* d = dv;
  if (n > 3600) {
    dyn.resize(n);
    d = dyn.data();
  }
  // Angles by rotation of (cos, sin) (no trig call per angle).
  const double cs = std::cos(step * kDeg), sn = std::sin(step * kDeg);
  double c = 1, s = 0;
  int argmin = 0;
  for (int k = 0; k < n; ++k) {
    d[k] = det_at(c, s);
    if (d[k] < d[argmin]) argmin = k;
    const double c2 = c * cs - s * sn;
    s = s * cs + c * sn;
    c = c2;
  }
  BifurcationResult r;
  // det Q is a trigonometric polynomial of degree 4 whose amplitude is a few mu M, so between two
  // samples it dips below the sampled minimum by at most ~ |f''| step^2 / 8 < 40 step^2 mu M
  // (step in radians). A sampled minimum above that cannot hide a bifurcation: skip refinement.
  const double step_rad = step * kDeg;
  if (d[argmin] > 40 * step_rad * step_rad * std::fabs(scale)) {
    r.theta = argmin * step;
    r.det_min = d[argmin];
    r.minima = 1;
    return r;
  }
  // Local minima on the periodic sweep (strict on the left, so a plateau gives one candidate).
  struct Cand { double theta, det; };
  Cand cands[8];
  int nc = 0;
  for (int k = 0; k < n && nc < 8; ++k) {
    const double l = d[(k + n - 1) % n], rr = d[(k + 1) % n];
    if (d[k] < l && d[k] <= rr) {
      double fmin;
      const double th = golden_min(det_deg, (k - 1) * step, (k + 1) * step, 48, fmin);
      cands[nc++] = {wrap_deg(th), std::min(fmin, d[k])};
    }
  }
  if (nc == 0) cands[nc++] = {argmin * step, d[argmin]};
  double best = cands[0].det;
  for (int q = 1; q < nc; ++q) best = std::min(best, cands[q].det);
  const double tol = P.tie_tolerance * std::fabs(scale);
  r.det_min = best;
  bool first = true;
  for (int q = 0; q < nc; ++q) {
    if (cands[q].det > best + tol) continue;
    ++r.minima;
    const bool better = P.tie == TieBreak::SmallestAngle ? cands[q].theta < r.theta
                                                         : cands[q].theta > r.theta;
    if (first || better) r.theta = cands[q].theta;
    first = false;
  }
  r.bifurcated = best <= 0;
  return r;
}

double hcr_j2(double sxx, double syy, double szz, double sxy, double mu, double M, double th) {
  const double p = (sxx + syy + szz) / 3.0;
  const double a0 = sxx - p, b0 = syy - p, c0 = szz - p;
  const double norm = std::sqrt(a0 * a0 + b0 * b0 + c0 * c0 + 2 * sxy * sxy);
  if (!(norm > 0)) return -3 * mu;
  const double nx = std::cos(th), ny = std::sin(th);
  const double ax = (a0 * nx + sxy * ny) / norm, ay = (sxy * nx + b0 * ny) / norm;
  const double aa = ax * ax + ay * ay, an = ax * nx + ay * ny;
  return 6 * mu * (aa - an * an) + 6 * mu * mu / M * an * an - 3 * mu;
}

double hcr_j2_max(double sxx, double syy, double szz, double sxy, double mu, double M,
                  double* theta_deg) {
  const int n = 3600;
  double best = -1e300, bt = 0;
  for (int k = 0; k < n; ++k) {
    const double t = k * 180.0 / n;
    const double h = hcr_j2(sxx, syy, szz, sxy, mu, M, t * kDeg);
    if (h > best) best = h, bt = t;
  }
  double fmin;
  const double step = 180.0 / n;
  const double t = golden_min(
      [&](double x) { return -hcr_j2(sxx, syy, szz, sxy, mu, M, x * kDeg); }, bt - step,
      bt + step, 60, fmin);
  if (-fmin > best) best = -fmin, bt = t;
  if (theta_deg) *theta_deg = wrap_deg(bt);
  return best;
}

// ------------------------------------------------------------------------------------------
// Decohesion

bool decohesion_start(const DecohesionParams& P, double M, double mu, double sxx, double syy,
                      double sxy, double particle_size, Discontinuity& d) {
  double tn, tt;
  plane_tractions(d.nx, d.ny, sxx, syy, sxy, tn, tt);
  d.ttf = std::max(std::fabs(tt), P.min_strength);
  if (tn > 0) d.tnf = tn;
  else d.tnf = P.compressed_normal_strength > 0 ? P.compressed_normal_strength : d.ttf;
  d.tnf = std::max(d.tnf, P.min_strength);
  d.un = d.ut = d.ubar = 0;
  double L = P.smear_length > 0 ? P.smear_length : particle_size;
  const double limit = std::min(M * P.u_nf / d.tnf, mu * P.u_tf / d.ttf);
  bool clamped = false;
  if (L >= limit) {
    L = P.snap_back_factor * limit;
    clamped = true;
  }
  d.L = L;
  return clamped;
}

namespace {
// Apply a jump increment (dn, dt) to the stress: sigma -= C : (1/L) sym(du (x) n).
inline void apply_jump(double lambda, double mu, const Discontinuity& d, double dn, double dt,
                       double& sxx, double& syy, double& szz, double& sxy) {
  const double ux = dn * d.nx - dt * d.ny, uy = dn * d.ny + dt * d.nx;
  const double exx = ux * d.nx / d.L, eyy = uy * d.ny / d.L;
  const double gxy = (ux * d.ny + uy * d.nx) / d.L;
  const double tr = lambda * (exx + eyy);
  sxx -= tr + 2 * mu * exx;
  syy -= tr + 2 * mu * eyy;
  szz -= tr;
  sxy -= mu * gxy;
}
}  // namespace

double decohesion_update(const DecohesionParams& P, double lambda, double mu, Discontinuity& d,
                         uint8_t& state, double& sxx, double& syy, double& szz, double& sxy) {
  const double M = lambda + 2 * mu;
  const double cn = M / d.L, ct = mu / d.L;
  double tn, tt;
  plane_tractions(d.nx, d.ny, sxx, syy, sxy, tn, tt);
  // Closure: an open plane under normal compression closes at zero normal traction.
  if (tn < 0 && d.un > 0) {
    const double dn = std::max(tn / cn, -d.un);
    apply_jump(lambda, mu, d, dn, 0, sxx, syy, szz, sxy);
    d.un += dn;
    tn -= cn * dn;
  }
  if (state == kSeparated) {
    // No tension, no shear: the jump takes all of it (no work: the traction ends at zero).
    const double dn = tn > 0 ? tn / cn : 0.0, dt = tt / ct;
    apply_jump(lambda, mu, d, dn, dt, sxx, syy, szz, sxy);
    d.un += dn;
    d.ut += dt;
    return 0.0;
  }
  const double tnp = std::max(tn, 0.0);
  const double r0 = 1.0 - d.ubar;
  const double f0 = std::sqrt((tnp / d.tnf) * (tnp / d.tnf) + (tt / d.ttf) * (tt / d.ttf)) - r0;
  if (f0 <= 0) return 0.0;
  // Backward Euler with associated flow: for a multiplier x,
  //   tau_n(x) = tn / (1 + 2 cn x / tnf^2) (tension only), tau_t(x) = tt / (1 + 2 ct x / ttf^2),
  //   du_n = 2 x tau_n / tnf^2, du_t = 2 x tau_t / ttf^2, ubar(x) = ubar + |du|_normalised.
  const double kn = 2 / (d.tnf * d.tnf), kt = 2 / (d.ttf * d.ttf);
  auto eval = [&](double x, double& dn, double& dt) {
    const double taun = tnp / (1 + cn * kn * x), taut = tt / (1 + ct * kt * x);
    dn = kn * x * taun;
    dt = kt * x * taut;
    const double ub = d.ubar + std::sqrt((dn / P.u_nf) * (dn / P.u_nf) + (dt / P.u_tf) * (dt / P.u_tf));
    return std::sqrt((taun / d.tnf) * (taun / d.tnf) + (taut / d.ttf) * (taut / d.ttf)) - (1 - ub);
  };
  // Bracket: phi(0) > 0; grow the upper end until phi <= 0 (x -> infinity gives tau -> 0).
  double lo = 0, hi = 1.0 / (cn * kn + ct * kt), dn = 0, dt = 0;
  int grow = 0;
  while (eval(hi, dn, dt) > 0 && grow < 200) {
    lo = hi;
    hi *= 4;
    ++grow;
  }
  bool separates = grow >= 200;
  double x = hi;
  if (!separates) {
    for (int it = 0; it < 200; ++it) {
      x = 0.5 * (lo + hi);
      if (eval(x, dn, dt) > 0) lo = x; else hi = x;
      if (hi - lo <= 1e-14 * hi) break;
    }
    x = hi;
    eval(x, dn, dt);
    const double ub = d.ubar + std::sqrt((dn / P.u_nf) * (dn / P.u_nf) + (dt / P.u_tf) * (dt / P.u_tf));
    separates = ub >= 1.0;
  }
  if (separates) {
    // The step carries the plane past full separation: the jump takes all tension and shear.
    // Dissipation: the remaining area of the linear law, from the traction on the failure
    // surface at the start of the step (trial direction) down to zero.
    const double sdn = tnp / cn, sdt = tt / ct;
    const double fr = std::sqrt((tnp / d.tnf) * (tnp / d.tnf) + (tt / d.ttf) * (tt / d.ttf));
    const double sn = fr > 0 ? tnp * r0 / fr : 0.0, st = fr > 0 ? tt * r0 / fr : 0.0;
    const double len = std::sqrt((sdn / P.u_nf) * (sdn / P.u_nf) + (sdt / P.u_tf) * (sdt / P.u_tf));
    const double frac = len > 0 ? std::min(1.0, r0 / len) : 0.0;
    apply_jump(lambda, mu, d, sdn, sdt, sxx, syy, szz, sxy);
    d.un += sdn;
    d.ut += sdt;
    d.ubar = 1.0;
    state = kSeparated;
    return 0.5 * (sn * sdn + st * sdt) * frac / d.L;
  }
  apply_jump(lambda, mu, d, dn, dt, sxx, syy, szz, sxy);
  d.un += dn;
  d.ut += dt;
  d.ubar += std::sqrt((dn / P.u_nf) * (dn / P.u_nf) + (dt / P.u_tf) * (dt / P.u_tf));
  // Dissipation with the end-of-step tractions (backward Euler).
  const double taun = tnp / (1 + cn * kn * x), taut = tt / (1 + ct * kt * x);
  return (taun * dn + taut * dt) / d.L;
}

}  // namespace smpm
