#pragma once
// Discontinuous bifurcation (docs/physics.md §5): the acoustic tensor Q_jk(n) = n_i C_ijkl n_l of a
// continuum tangent, its determinant swept over the normal angle, and the closed-form J2 criterion
// used as the sweep's test oracle.
//
// Normals n and -n describe one plane, so angles are taken in [0, 180) degrees, measured from +x.
// A symmetric state has two critical planes (+theta and -theta = 180 - theta); which one a
// particle takes is the tie-break, an input:
//   SmallestAngle  the candidate with the smaller angle in [0, 180)  (default: +44.7 deg in plate
//                  tension, n along x in simple shear)
//   LargestAngle   the candidate with the larger angle (135.3 deg = -44.7 deg; n along y)
// Two minima tie when their determinants differ by less than tie_tolerance * mu * M.

#include <algorithm>
#include <cmath>

namespace smpm {

enum class TieBreak { SmallestAngle, LargestAngle };

struct BifurcationParams {
  bool enabled = true;
  double step_deg = 1.0;          // sweep step
  TieBreak tie = TieBreak::SmallestAngle;
  double tie_tolerance = 1e-9;    // relative (to mu * M) difference under which minima tie
};

struct BifurcationResult {
  bool bifurcated = false;  // min det Q <= 0
  double theta = 0;         // critical angle in degrees, [0, 180)
  double det_min = 0;       // det Q at theta
  int minima = 0;           // number of tied minima the tie-break chose among
};

// det Q(n) for the tangent C (layout of j2_tangent) and n = (cos th, sin th), th in radians.
double acoustic_det(const double C[16], double theta_rad);

// Sweep theta over [0, 180) in steps of P.step_deg, refine every local minimum (golden section
// within one step on each side), pick the global minimum with the tie-break. scale = mu * M
// (for the tie tolerance).
BifurcationResult bifurcation_sweep(const double C[16], const BifurcationParams& P, double scale);

// ------------------------------------------------------------------------------------------
// Fourier form (the fast check). Q(n) is quadratic in n = (cos th, sin th), so det Q is a
// homogeneous quartic in (cos th, sin th), i.e. exactly
//   det Q(th) = a0 + a1 cos 2th + b1 sin 2th + a2 cos 4th + b2 sin 4th,
// with the five coefficients in closed form from the tangent (acoustic_fourier). Then
//   det Q(th) >= a0 - |(a1, b1)| - |(a2, b2)|   for every th   (lower_bound),
// and the minimum over th is located from the derivative of this form (acoustic_min_fourier).
struct AcousticFourier {
  double a0 = 0, a1 = 0, b1 = 0, a2 = 0, b2 = 0;
  double operator()(double theta_rad) const;  // det Q(theta)
  double lower_bound() const;                 // a0 - |(a1,b1)| - |(a2,b2)|
  double magnitude() const;                   // |a0| + |(a1,b1)| + |(a2,b2)| (round-off scale)
};
AcousticFourier acoustic_fourier(const double C[16]);

// Every local minimum of the Fourier form located (critical points of d/dth det Q bracketed on
// intervals certified by bounds on the second and third derivatives, then safeguarded Newton),
// the global one chosen with the tie-break of bifurcation_sweep (minima within
// tie_tolerance * |scale| tie). theta in degrees, [0, 180); bifurcated = det_min <= 0.
BifurcationResult acoustic_min_fourier(const AcousticFourier& F, const BifurcationParams& P,
                                       double scale);

// A lower bound of det Q from samples of the Fourier form: min over the samples minus
// max|d2/dphi2| h^2 / 8 (phi = 2 theta, max|d2/dphi2| <= |(a1,b1)| + 4 |(a2,b2)|), from 32
// samples (h = 2 pi / 32), and from 64 (h = 2 pi / 64) when the first is not above threshold.
double acoustic_sampled_bound(const AcousticFourier& F, double threshold = 1e300);

// The check the film model runs after every plastic step; same verdict and plane as
// bifurcation_sweep, cheaper:
//   1. lower bound > round-off margin: no bifurcation (theta = 0, det_min = the bound);
//   2. else the sampled bound > margin: no bifurcation (theta = 0, det_min = that bound);
//   3. else the Fourier minimum; above the margin: no bifurcation (theta, det_min from it);
//   4. else (at or near bifurcation) bifurcation_sweep decides and gives the plane, so that the
//      critical plane is the sweep's to the last bit.
// The margin, 1e-10 * magnitude(), is far above the round-off of evaluating det Q, so whenever
// 1, 2 or 3 answer "no", every evaluation of the sweep is positive too: the verdict is the same.
// stage (optional) gets 1 to 4.
BifurcationResult bifurcation_check(const double C[16], const BifurcationParams& P, double scale,
                                    int* stage = nullptr);

// Closed-form J2 criterion (docs/physics.md §5): bifurcation on the plane of normal n iff
// H <= H_cr(n) = 6G(|a|^2 - (a.n)^2) + (6G^2/M)(a.n)^2 - 3G, a = N n (in-plane block of s/|s|).
double hcr_j2(double sxx, double syy, double szz, double sxy, double mu, double M, double theta_rad);
// max over the normal angle of hcr_j2 (fine sweep and refinement); theta_deg gets the argmax.
double hcr_j2_max(double sxx, double syy, double szz, double sxy, double mu, double M,
                  double* theta_deg = nullptr);

// The same maximum in closed form. With N = s/|s|, its in-plane block N2, w = a.n = n.N2.n and
// u = cos(2 th - phi0): w = P + R u, |a|^2 = T + 2 P R u, P = (Nxx + Nyy)/2,
// R = |((Nxx - Nyy)/2, Nxy)|, T = (Nxx^2 + Nyy^2)/2 + Nxy^2, so
//   H_cr = 6G T - 3G - 12G P^2 + 12G P w - 6G (1 - G/M) w^2,   w in [P - R, P + R],
// a concave parabola in w: its maximum at w* = P / (1 - G/M), clamped to the interval.
// (For every stress H_cr <= 0: associated J2 never bifurcates while it hardens.)
inline double hcr_j2_max_closed(double sxx, double syy, double szz, double sxy, double mu,
                                double M) {
  const double p = (sxx + syy + szz) / 3.0;
  const double a = sxx - p, b = syy - p, c = szz - p;
  const double n2 = a * a + b * b + c * c + 2 * sxy * sxy;
  if (!(n2 > 0)) return -3 * mu;
  const double in = 1 / std::sqrt(n2);
  const double Nxx = a * in, Nyy = b * in, Nxy = sxy * in;
  const double P = 0.5 * (Nxx + Nyy), D = 0.5 * (Nxx - Nyy);
  const double R = std::sqrt(D * D + Nxy * Nxy);
  const double T = 0.5 * (Nxx * Nxx + Nyy * Nyy) + Nxy * Nxy;
  const double k = 1 - mu / M;
  const double w = std::min(P + R, std::max(P - R, P / k));
  return 6 * mu * (T - 0.5 - 2 * P * P + 2 * P * w - k * w * w);
}

// The film model's pre-check: true when H - max_n H_cr(n) > margin * G, i.e. no normal can
// bifurcate (det Q(n) = G M (H - H_cr(n)) / (3G + H) > 0 for all n; requires 3G + H > 0).
// hcr_j2_max_closed without normalising s (H_cr = 6G (f / |s|^2 - 1/2), f quadratic in s),
// so with one square root at most and none when the maximum is interior.
inline bool j2_cannot_bifurcate(double sxx, double syy, double szz, double sxy, double mu,
                                double M, double H, double margin = 1e-8) {
  if (!(3 * mu + H > 0)) return false;
  const double p = (sxx + syy + szz) / 3.0;
  const double a = sxx - p, b = syy - p, c = szz - p;
  const double n2 = a * a + b * b + c * c + 2 * sxy * sxy;
  const double P = 0.5 * (a + b), D = 0.5 * (a - b);
  const double T = 0.5 * (a * a + b * b) + sxy * sxy;
  const double R2 = D * D + sxy * sxy;
  const double ik = M / (M - mu);  // 1 / (1 - G/M)
  const double e = P * (ik - 1);   // w* - P
  double f;
  if (e * e <= R2) {
    f = T - 2 * P * P + P * P * ik;  // interior maximum, w = P / k
  } else {
    const double w = P + std::copysign(std::sqrt(R2), e);
    f = T - 2 * P * P + 2 * P * w - (1 - mu / M) * w * w;
  }
  return (H + 3 * mu - margin * mu) * n2 > 6 * mu * f;
}

}  // namespace smpm
