// Bifurcation sweep, its Fourier-form fast check, the closed-form J2 criterion and the
// decohesion return mapping (bifurcation.hpp, decohesion.hpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "silentmpm/bifurcation.hpp"
#include "silentmpm/decohesion.hpp"
#include "silentmpm/film.hpp"

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

// ------------------------------------------------------------------------------------------
// Fourier form

namespace {
// Coefficients (c0, cos phi, sin phi, cos 2phi, sin 2phi) of (p1 + r1 cos phi + s1 sin phi) *
// (p2 + r2 cos phi + s2 sin phi), added with the sign sg.
inline void add_product(double sg, double p1, double r1, double s1, double p2, double r2,
                        double s2, AcousticFourier& F) {
  F.a0 += sg * (p1 * p2 + 0.5 * (r1 * r2 + s1 * s2));
  F.a1 += sg * (p1 * r2 + p2 * r1);
  F.b1 += sg * (p1 * s2 + p2 * s1);
  F.a2 += sg * 0.5 * (r1 * r2 - s1 * s2);
  F.b2 += sg * 0.5 * (r1 * s2 + r2 * s1);
}
}  // namespace

AcousticFourier acoustic_fourier(const double C[16]) {
  // Q_jk = A_jk c^2 + B_jk c s + D_jk s^2 (c = cos th, s = sin th)
  //      = P_jk + R_jk cos 2th + S_jk sin 2th,  P = (A + D)/2, R = (A - D)/2, S = B/2.
  double P[2][2], R[2][2], S[2][2];
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k) {
      const double A = C[((0 * 2 + j) * 2 + k) * 2 + 0];
      const double B = C[((0 * 2 + j) * 2 + k) * 2 + 1] + C[((1 * 2 + j) * 2 + k) * 2 + 0];
      const double D = C[((1 * 2 + j) * 2 + k) * 2 + 1];
      P[j][k] = 0.5 * (A + D);
      R[j][k] = 0.5 * (A - D);
      S[j][k] = 0.5 * B;
    }
  AcousticFourier F;
  add_product(1, P[0][0], R[0][0], S[0][0], P[1][1], R[1][1], S[1][1], F);
  add_product(-1, P[0][1], R[0][1], S[0][1], P[1][0], R[1][0], S[1][0], F);
  return F;
}

double AcousticFourier::operator()(double th) const {
  const double c = std::cos(2 * th), s = std::sin(2 * th);
  return a0 + a1 * c + b1 * s + a2 * (c * c - s * s) + b2 * (2 * s * c);
}

double AcousticFourier::lower_bound() const {
  return a0 - std::sqrt(a1 * a1 + b1 * b1) - std::sqrt(a2 * a2 + b2 * b2);
}

double AcousticFourier::magnitude() const {
  return std::fabs(a0) + std::sqrt(a1 * a1 + b1 * b1) + std::sqrt(a2 * a2 + b2 * b2);
}

namespace {
// cos and sin of phi_k = k 2 pi / 64, k = 0 .. 63: the sample points of the Fourier form (the
// even ones) and their midpoints (the odd ones), without a trigonometric call per particle.
constexpr int kTab = 64;
struct Table {
  double c[kTab], s[kTab];
  Table() {
    for (int k = 0; k < kTab; ++k) {
      c[k] = std::cos(k * 2 * kPi / kTab);
      s[k] = std::sin(k * 2 * kPi / kTab);
    }
  }
};
const Table kTable;

// (c, s) = (cos, sin) of the angle of (c0, s0) plus d, |d| <= 0.2: Taylor series of cos d and
// sin d to round-off (the first omitted terms are below 1e-18), no trigonometric call.
inline void rotate(double c0, double s0, double d, double& c, double& s) {
  const double d2 = d * d;
  const double sd = d * (1 - d2 / 6 * (1 - d2 / 20 * (1 - d2 / 42 * (1 - d2 / 72 * (1 - d2 / 110 * (1 - d2 / 156))))));
  const double cd = 1 - d2 / 2 * (1 - d2 / 12 * (1 - d2 / 30 * (1 - d2 / 56 * (1 - d2 / 90 * (1 - d2 / 132 * (1 - d2 / 182))))));
  c = c0 * cd - s0 * sd;
  s = s0 * cd + c0 * sd;
}

// g(phi) = det Q at th = phi / 2 and its first two derivatives in phi, from cos phi and sin phi.
struct FourierPhi {
  const AcousticFourier& F;
  double g(double c, double s) const {
    return F.a0 + F.a1 * c + F.b1 * s + F.a2 * (c * c - s * s) + F.b2 * 2 * s * c;
  }
  double d1(double c, double s) const {
    return -F.a1 * s + F.b1 * c + 2 * (-F.a2 * 2 * s * c + F.b2 * (c * c - s * s));
  }
  double d2(double c, double s) const {
    return -F.a1 * c - F.b1 * s - 4 * (F.a2 * (c * c - s * s) + F.b2 * 2 * s * c);
  }
};
}  // namespace

BifurcationResult acoustic_min_fourier(const AcousticFourier& F, const BifurcationParams& P,
                                       double scale) {
  // In phi = 2 th in [0, 2 pi): g(phi) = a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi,
  // whose derivatives are bounded: |g2| <= r1 + 4 r2 and |g3| <= r1 + 8 r2 (g2, g3 the second and
  // third derivatives, r1 = |(a1,b1)|, r2 = |(a2,b2)|). An interval [a, b] is settled when
  //   the slope g1 has one sign at both ends and |g1(a)| + |g1(b)| > (r1 + 4 r2)(b - a): no root
  //     of g1 (it cannot go to zero and back within the width at that rate), or
  //   |g2(mid)| > (r1 + 8 r2)(b - a)/2: g2 keeps its sign, g1 is monotone: no root (same signs)
  //     or exactly one (a minimum of g when g1 goes from - to +: Newton in the bracket);
  // otherwise it is halved. A root of g1 on a common end belongs to the interval on its right
  // (g1 = 0 counts as negative), so no minimum is found twice. 32 starting intervals.
  const double r1 = std::sqrt(F.a1 * F.a1 + F.b1 * F.b1), r2 = std::sqrt(F.a2 * F.a2 + F.b2 * F.b2);
  BifurcationResult res;
  if (!(r1 + r2 > 1e-14 * std::fabs(F.a0))) {  // constant: every angle is a minimum
    res.theta = 0;
    res.det_min = F.a0;
    res.minima = 1;
    res.bifurcated = F.a0 <= 0;
    return res;
  }
  const FourierPhi G{F};
  const double L2 = r1 + 4 * r2, L3 = r1 + 8 * r2;
  constexpr int N = kTab / 2;
  constexpr double h = 2 * kPi / N;
  struct Iv { double a, b, ga, gb, cm, sm; int depth; };  // (cm, sm): cos, sin of the midpoint
  constexpr int kStack = N + 256;
  Iv stack[kStack];
  int ns = 0;
  double g1[N + 1];
  for (int k = 0; k < N; ++k) g1[k] = G.d1(kTable.c[2 * k], kTable.s[2 * k]);
  g1[N] = g1[0];  // periodic: the same value at 0 and 2 pi
  for (int k = N - 1; k >= 0; --k)
    stack[ns++] = {k * h, (k + 1) * h, g1[k], g1[k + 1], kTable.c[2 * k + 1], kTable.s[2 * k + 1], 0};
  struct Cand { double phi, det; };
  Cand cands[8];
  int nc = 0;
  while (ns > 0) {
    const Iv iv = stack[--ns];
    const bool neg_a = !(iv.ga > 0), neg_b = !(iv.gb > 0);
    const double w = iv.b - iv.a, m = 0.5 * (iv.a + iv.b);
    const double cm = iv.cm, sm = iv.sm;
    const bool monotone = std::fabs(G.d2(cm, sm)) > L3 * 0.5 * w;
    if (neg_a == neg_b) {
      if (monotone || std::fabs(iv.ga) + std::fabs(iv.gb) > L2 * w) continue;
    } else if (monotone) {
      if (!neg_a) continue;  // + to -: a maximum of g
      // One root of g1 in [a, b), g1 increasing: Newton kept inside the bracket; the point is
      // x = m + d, its (cos, sin) rotated from the midpoint's (|d| <= w/2 <= 0.1).
      double lo = iv.a, hi = iv.b, x = iv.a - iv.ga * w / (iv.gb - iv.ga);
      double c = cm, s = sm;
      for (int it = 0; it < 60; ++it) {
        rotate(cm, sm, x - m, c, s);
        const double f1 = G.d1(c, s);
        if (!(f1 > 0)) lo = x; else hi = x;
        if (f1 == 0) break;
        double xn = x - f1 / G.d2(c, s);
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        // Quadratic convergence: after a step of 1e-12 the error is at round-off.
        const bool done = std::fabs(xn - x) <= 1e-12 || hi - lo <= 1e-15;
        x = xn;
        if (done) break;
      }
      rotate(cm, sm, x - m, c, s);
      if (nc < 8) cands[nc++] = {x, G.g(c, s)};
      continue;
    }
    if (iv.depth >= 40 || ns + 2 > kStack) {
      // Not certified within 2 pi / 2^45: a degenerate critical point; take the midpoint.
      if (neg_a && !neg_b && nc < 8) cands[nc++] = {m, G.g(cm, sm)};
      continue;
    }
    const double gm = G.d1(cm, sm);
    double cl, sl, cr, sr;
    rotate(cm, sm, -0.25 * w, cl, sl);
    rotate(cm, sm, 0.25 * w, cr, sr);
    stack[ns++] = {m, iv.b, gm, iv.gb, cr, sr, iv.depth + 1};
    stack[ns++] = {iv.a, m, iv.ga, gm, cl, sl, iv.depth + 1};
  }
  if (nc == 0) {  // cannot happen for a non-constant periodic g; keep the sampled minimum
    int best = 0;
    double gb = G.g(1, 0);
    for (int k = 1; k < N; ++k) {
      const double v = G.g(kTable.c[2 * k], kTable.s[2 * k]);
      if (v < gb) gb = v, best = k;
    }
    cands[nc++] = {best * h, gb};
  }
  double best = cands[0].det;
  for (int q = 1; q < nc; ++q) best = std::min(best, cands[q].det);
  const double tol = P.tie_tolerance * std::fabs(scale);
  res.det_min = best;
  bool first = true;
  for (int q = 0; q < nc; ++q) {
    if (cands[q].det > best + tol) continue;
    const double th = wrap_deg(cands[q].phi * 0.5 / kDeg);
    ++res.minima;
    const bool better = P.tie == TieBreak::SmallestAngle ? th < res.theta : th > res.theta;
    if (first || better) res.theta = th;
    first = false;
  }
  res.bifurcated = best <= 0;
  return res;
}

double acoustic_sampled_bound(const AcousticFourier& F, double threshold) {
  // 32 samples in phi = 2 th (h = 2 pi / 32); between two samples g lies above the chord minus
  // max|g2| h^2 / 8, max|g2| <= |(a1,b1)| + 4 |(a2,b2)| (g2 the second derivative in phi). When
  // that bound is not above threshold, the 32 midpoints too (h = 2 pi / 64, a bound 4x closer).
  const FourierPhi G{F};
  constexpr double h = 2 * kPi / (kTab / 2);
  const double L2 = std::sqrt(F.a1 * F.a1 + F.b1 * F.b1) + 4 * std::sqrt(F.a2 * F.a2 + F.b2 * F.b2);
  double gmin = G.g(1, 0);
  for (int k = 2; k < kTab; k += 2) gmin = std::min(gmin, G.g(kTable.c[k], kTable.s[k]));
  const double b32 = gmin - L2 * h * h / 8;
  if (b32 > threshold) return b32;
  for (int k = 1; k < kTab; k += 2) gmin = std::min(gmin, G.g(kTable.c[k], kTable.s[k]));
  return std::max(b32, gmin - L2 * h * h / 32);
}

BifurcationResult bifurcation_check(const double C[16], const BifurcationParams& P, double scale,
                                    int* stage) {
  const AcousticFourier F = acoustic_fourier(C);
  const double margin = 1e-10 * F.magnitude();
  BifurcationResult r;
  r.minima = 1;
  r.det_min = F.lower_bound();
  if (r.det_min > margin) {
    if (stage) *stage = 1;
    return r;
  }
  r.det_min = acoustic_sampled_bound(F, margin);
  if (r.det_min > margin) {
    if (stage) *stage = 2;
    return r;
  }
  r = acoustic_min_fourier(F, P, scale);
  if (r.det_min > margin) {
    if (stage) *stage = 3;
    return r;
  }
  if (stage) *stage = 4;
  return bifurcation_sweep(C, P, scale);
}

// ------------------------------------------------------------------------------------------
// The film model's off-hot-path parts (film.hpp)

double film_decohesion(const Material& m, Particles& p, std::size_t k, double& sxx, double& syy,
                       double& szz, double& sxy) {
  Discontinuity d;
  d.nx = p.dnx[k]; d.ny = p.dny[k]; d.L = p.dL[k];
  d.tnf = p.dtnf[k]; d.ttf = p.dttf[k];
  d.un = p.jump_n[k]; d.ut = p.jump_t[k]; d.ubar = p.ubar[k];
  const double w = decohesion_update(m.coh, m.lambda, m.mu, d, p.state[k], sxx, syy, szz, sxy);
  p.jump_n[k] = d.un; p.jump_t[k] = d.ut; p.ubar[k] = d.ubar;
  return w;
}

void film_bifurcation(const Material& m, Particles& p, std::size_t k, double H, double sxx,
                      double syy, double szz, double sxy) {
  double C[16];
  j2_tangent(m.lambda, m.mu, sxx, syy, szz, sxy, j2_beta(m.mu, H), C);
  const BifurcationResult b = bifurcation_check(C, m.bif, m.mu * m.M);
  if (!b.bifurcated) return;
  const double th = b.theta * kPi / 180.0;
  Discontinuity d;
  d.nx = std::cos(th);
  d.ny = std::sin(th);
  p.dnx[k] = d.nx;
  p.dny[k] = d.ny;
  if (!m.coh.enabled) return;
  decohesion_start(m.coh, m.M, m.mu, sxx, syy, sxy, std::sqrt(p.vol[k]), d);
  p.dL[k] = d.L; p.dtnf[k] = d.tnf; p.dttf[k] = d.ttf;
  p.jump_n[k] = 0; p.jump_t[k] = 0; p.ubar[k] = 0;
  p.state[k] = kDecohesion;
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
  double phi_lo = f0, phi_hi;
  int grow = 0;
  while ((phi_hi = eval(hi, dn, dt)) > 0 && grow < 200) {
    lo = hi;
    phi_lo = phi_hi;
    hi *= 4;
    ++grow;
  }
  bool separates = grow >= 200;
  double x = hi;
  if (!separates) {
    // phi decreases in x (the tractions fall, ubar grows): Newton from the secant point, kept
    // inside the bracket (bisection when a step leaves it), to 1e-14 relative in x.
    const double An = cn * kn, At = ct * kt;
    const double iun2 = 1 / (P.u_nf * P.u_nf), iut2 = 1 / (P.u_tf * P.u_tf);
    const double itn2 = 1 / (d.tnf * d.tnf), itt2 = 1 / (d.ttf * d.ttf);
    // Start: the Newton step from x = 0 (phi(0) = f0; at x = 0, dS/dx = -(A_n tau_n^2 / tnf^2 +
    // A_t tau_t^2 / ttf^2) / S and dU/dx = |(k_n tau_n / u_nf, k_t tau_t / u_tf)|), close to the
    // root when the trial state is just outside the surface (the usual step); else the secant.
    {
      const double S0 = f0 + r0;
      const double dS0 = S0 > 0 ? -(tnp * tnp * An * itn2 + tt * tt * At * itt2) / S0 : 0.0;
      const double dU0 = std::sqrt(kn * kn * tnp * tnp * iun2 + kt * kt * tt * tt * iut2);
      const double x0 = dS0 + dU0 < 0 ? -f0 / (dS0 + dU0) : -1.0;
      x = x0 > lo && x0 < hi ? x0 : lo + (hi - lo) * phi_lo / (phi_lo - phi_hi);
    }
    for (int it = 0; it < 100; ++it) {
      const double en = 1 / (1 + An * x), et = 1 / (1 + At * x);
      const double taun = tnp * en, taut = tt * et;
      dn = kn * x * taun;
      dt = kt * x * taut;
      const double S = std::sqrt(taun * taun * itn2 + taut * taut * itt2);
      const double U2 = dn * dn * iun2 + dt * dt * iut2;
      const double U = std::sqrt(U2);
      const double phi = S - (1 - d.ubar - U);
      if (phi > 0) lo = x; else hi = x;
      // phi' = dS/dx + dU/dx, with dtau/dx = -A tau e and d(du)/dx = k tau e.
      const double dS = S > 0 ? -(taun * taun * An * en * itn2 + taut * taut * At * et * itt2) / S : 0.0;
      const double vn = kn * taun * en, vt = kt * taut * et;
      const double dU = U > 0 ? (dn * vn * iun2 + dt * vt * iut2) / U
                              : std::sqrt(vn * vn * iun2 + vt * vt * iut2);
      const double dphi = dS + dU;
      double xn = dphi < 0 ? x - phi / dphi : 0.5 * (lo + hi);
      if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
      // Quadratic convergence: after a relative step of 1e-12 the error is at round-off.
      const bool done = std::fabs(xn - x) <= 1e-12 * x || hi - lo <= 1e-14 * hi;
      x = xn;
      if (done) break;
    }
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
