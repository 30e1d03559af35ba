// The fast bifurcation check (bifurcation.hpp): det Q as a five-term Fourier series in the normal
// angle, its exact lower bounds, its minimiser, and the check the film model runs, against the
// reference 1-degree sweep and brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "silentmpm/bifurcation.hpp"
#include "silentmpm/j2soft.hpp"
#include "silentmpm/material.hpp"

namespace smpm {
namespace {

constexpr double kPi = 3.14159265358979323846;

Material tungsten() {
  Material m;
  m.name = "W";
  m.model = Model::J2Film;
  m.E = 411e9; m.nu = 0.28; m.rho = 15000;
  m.j2.sigma_y = 1.5e9; m.j2.sigma_peak = 1.55e9; m.j2.E_h = 64e9; m.j2.E_s = 64e9 / 100;
  m.derive();
  return m;
}

// Brute-force minimum of acoustic_det over 18 000 angles (0.01 deg).
double brute_min(const double C[16], double* theta_deg = nullptr) {
  double dmin = 1e300, tmin = 0;
  for (int k = 0; k < 18000; ++k) {
    const double d = acoustic_det(C, k * 0.01 * kPi / 180);
    if (d < dmin) dmin = d, tmin = k * 0.01;
  }
  if (theta_deg) *theta_deg = tmin;
  return dmin;
}

// Angle difference of two planes (degrees, modulo 180).
double plane_diff(double a, double b) {
  const double d = std::fmod(std::fabs(a - b), 180.0);
  return std::min(d, 180.0 - d);
}

// A random J2 tangent near its critical modulus: stress components uniform in +-2 GPa, H within
// +-0.2 mu of H_cr (and 3G + H > 0.05 mu).
struct J2State {
  double C[16];
  bool ok = false;
};
J2State random_j2(const Material& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2e9, 2e9), w(-0.2, 0.2);
  const double sxx = u(rng), syy = u(rng), szz = u(rng), sxy = u(rng);
  const double H = hcr_j2_max(sxx, syy, szz, sxy, m.mu, m.M) + w(rng) * m.mu;
  J2State s;
  s.ok = 3 * m.mu + H > 0.05 * m.mu;
  j2_tangent(m.lambda, m.mu, sxx, syy, szz, sxy, j2_beta(m.mu, H), s.C);
  return s;
}

// A random tangent: a J2 state's (j2 true) or 16 independent entries in [-M, M] (no symmetry).
void random_tangent(const Material& m, std::mt19937& rng, bool j2, double C[16]) {
  if (j2) {
    const J2State s = random_j2(m, rng);
    std::copy(s.C, s.C + 16, C);
  } else {
    std::uniform_real_distribution<double> e(-1, 1);
    for (int k = 0; k < 16; ++k) C[k] = e(rng) * m.M;
  }
}

// The five-term form is det Q itself: equal to acoustic_det to round-off at every angle, on
// random J2 tangents and on tangents with 16 independent random entries (no symmetry at all).
TEST(FastBifurcation, FourierFormEqualsAcousticDet) {
  const Material m = tungsten();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> e(-1, 1), th(0, kPi);
  double worst = 0;
  for (int trial = 0; trial < 400; ++trial) {
    double C[16];
    random_tangent(m, rng, trial % 2 == 0, C);
    const AcousticFourier F = acoustic_fourier(C);
    for (int k = 0; k < 50; ++k) {
      const double t = th(rng);
      const double err = std::fabs(F(t) - acoustic_det(C, t)) / F.magnitude();
      worst = std::max(worst, err);
    }
  }
  std::printf("Fourier form vs acoustic_det: worst relative difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-14);
}

// Both bounds are lower bounds of the true minimum (brute force, 0.01 deg), and the closed-form
// one is exact for a pure first harmonic: a0 + a1 cos 2th has minimum a0 - |a1|.
TEST(FastBifurcation, BoundsAreLowerBounds) {
  const Material m = tungsten();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> e(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    double C[16];
    random_tangent(m, rng, trial % 2 == 0, C);
    const AcousticFourier F = acoustic_fourier(C);
    const double dmin = brute_min(C);
    const double tiny = 1e-13 * F.magnitude();
    EXPECT_LE(F.lower_bound(), dmin + tiny) << trial;
    // The sampled bounds (32 samples: threshold -inf; 64: threshold +inf) are within
    // max|g''| h^2 / 8 of the minimum (h = 2 pi / 32 or 2 pi / 64 in 2 theta).
    const double L2 = std::hypot(F.a1, F.b1) + 4 * std::hypot(F.a2, F.b2);
    const double b32 = acoustic_sampled_bound(F, -1e300), b64 = acoustic_sampled_bound(F, 1e300);
    EXPECT_LE(b32, dmin + tiny) << trial;
    EXPECT_LE(b64, dmin + tiny) << trial;
    EXPECT_GE(b32, dmin - L2 * std::pow(2 * kPi / 32, 2) / 8 - tiny) << trial;
    EXPECT_GE(b64, dmin - L2 * std::pow(2 * kPi / 64, 2) / 8 - tiny) << trial;
    EXPECT_GE(b64, b32) << trial;
  }
  AcousticFourier F;
  F.a0 = 3; F.a1 = -1.25;
  EXPECT_DOUBLE_EQ(F.lower_bound(), 1.75);
  EXPECT_NEAR(F(0), 1.75, 1e-15);
}

// The Fourier minimiser against the reference sweep (bifurcation_sweep) and brute force on
// random J2 states around the critical modulus: same verdict, the same plane (to 1e-6 deg where
// the sweep refines), the same minimum to 1e-9 mu M there; on random non-symmetric tangents the
// minimum agrees with brute force (never above it by more than the 0.01-deg sampling allows).
TEST(FastBifurcation, MinimiserAgreesWithSweep) {
  const Material m = tungsten();
  const double scale = m.mu * m.M;
  std::mt19937 rng(11);
  int compared = 0, bif = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const J2State s = random_j2(m, rng);
    if (!s.ok) continue;
    const BifurcationResult ref = bifurcation_sweep(s.C, m.bif, scale);
    const BifurcationResult r = acoustic_min_fourier(acoustic_fourier(s.C), m.bif, scale);
    EXPECT_EQ(r.bifurcated, ref.bifurcated) << trial;
    // The minimiser is exact: never above the brute-force minimum, below it by at most what
    // 0.01-deg sampling misses (curvature <= 20 mu M per rad^2).
    const double dmin = brute_min(s.C);
    EXPECT_LE(r.det_min, dmin + 1e-12 * scale) << trial;
    EXPECT_GE(r.det_min, dmin - 20 * std::pow(0.005 * kPi / 180, 2) * scale) << trial;
    if (ref.det_min <= 0.01 * scale) {  // the sweep refined its minima: compare the planes
      EXPECT_NEAR(r.det_min, ref.det_min, 1e-9 * scale) << trial;
      EXPECT_LT(plane_diff(r.theta, ref.theta), 1e-6) << trial << ": " << r.theta << " vs " << ref.theta;
      EXPECT_EQ(r.minima, ref.minima) << trial;
      ++compared;
    }
    bif += r.bifurcated;
  }
  EXPECT_GT(compared, 80);
  EXPECT_GT(bif, 40);
  // Random tangents without any symmetry: the minimum and its plane against brute force.
  std::uniform_real_distribution<double> e(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    double C[16];
    for (double& c : C) c = e(rng) * m.M;
    const AcousticFourier F = acoustic_fourier(C);
    const BifurcationResult r = acoustic_min_fourier(F, m.bif, scale);
    double tb;
    const double dmin = brute_min(C, &tb);
    EXPECT_LE(r.det_min, dmin + 1e-13 * F.magnitude()) << trial;
    EXPECT_NEAR(F(r.theta * kPi / 180), r.det_min, 1e-13 * F.magnitude()) << trial;
    EXPECT_GE(r.det_min, dmin - 1e-6 * F.magnitude()) << trial;
  }
}

// Tied minima keep the sweep's tie rule: plate tension at bifurcation (two planes at +-44.7 deg,
// docs/physics.md §5) and pure shear at H = 0 (n along x or y).
TEST(FastBifurcation, TieRuleOnSymmetricStates) {
  const Material m = tungsten();
  const double scale = m.mu * m.M;
  // Plate-tension state at bifurcation (docs/physics.md §5): sxx 1.7837, syy 0, szz 0.8309 GPa,
  // with the critical modulus of that state (det min = 0 at two mirror planes).
  const double sxx = 1.7837e9, szz = 0.8309e9;
  double th_cf;
  const double hcr = hcr_j2_max(sxx, 0, szz, 0, m.mu, m.M, &th_cf);
  double C[16];
  j2_tangent(m.lambda, m.mu, sxx, 0, szz, 0, j2_beta(m.mu, hcr - 1e-6 * m.mu), C);
  BifurcationParams P = m.bif;
  for (int tie = 0; tie < 2; ++tie) {
    P.tie = tie == 0 ? TieBreak::SmallestAngle : TieBreak::LargestAngle;
    const BifurcationResult ref = bifurcation_sweep(C, P, scale);
    const BifurcationResult r = acoustic_min_fourier(acoustic_fourier(C), P, scale);
    const BifurcationResult k = bifurcation_check(C, P, scale);
    EXPECT_TRUE(r.bifurcated && ref.bifurcated && k.bifurcated);
    EXPECT_EQ(r.minima, 2);
    EXPECT_EQ(ref.minima, 2);
    EXPECT_NEAR(r.theta, tie == 0 ? 44.7 : 135.3, 0.2);
    EXPECT_LT(plane_diff(r.theta, ref.theta), 1e-6);
    EXPECT_EQ(k.theta, ref.theta);  // the check hands the plane to the sweep at bifurcation
  }
  // Simple shear (sxy only) just below H = 0: det Q < 0 on the planes n = x and n = y, tied.
  j2_tangent(m.lambda, m.mu, 0, 0, 0, 1e9, j2_beta(m.mu, -1e-6 * m.mu), C);
  P.tie = TieBreak::SmallestAngle;
  BifurcationResult r = acoustic_min_fourier(acoustic_fourier(C), P, scale);
  EXPECT_TRUE(r.bifurcated);
  EXPECT_EQ(r.minima, 2);
  EXPECT_NEAR(r.theta, 0.0, 1e-9);
  P.tie = TieBreak::LargestAngle;
  r = acoustic_min_fourier(acoustic_fourier(C), P, scale);
  EXPECT_NEAR(r.theta, 90.0, 1e-9);
}

// The check gives the sweep's verdict, and at bifurcation the sweep's plane bit for bit, on
// random J2 states around the critical modulus; with hardening (H > 0) no state bifurcates
// (associated J2: H_cr <= 0 for every stress, docs/physics.md §5), and the closed-form bound alone
// settles it (stage 1) for the tungsten hardening modulus.
TEST(FastBifurcation, CheckGivesTheSweepVerdictAndPlane) {
  const Material m = tungsten();
  const double scale = m.mu * m.M;
  std::mt19937 rng(17);
  int stages[5] = {0, 0, 0, 0, 0};
  for (int trial = 0; trial < 600; ++trial) {
    const J2State s = random_j2(m, rng);
    if (!s.ok) continue;
    int stage = 0;
    const BifurcationResult k = bifurcation_check(s.C, m.bif, scale, &stage);
    const BifurcationResult ref = bifurcation_sweep(s.C, m.bif, scale);
    ASSERT_GE(stage, 1);
    ASSERT_LE(stage, 4);
    ++stages[stage];
    EXPECT_EQ(k.bifurcated, ref.bifurcated) << trial;
    if (ref.bifurcated) {
      EXPECT_EQ(stage, 4);
      EXPECT_EQ(k.theta, ref.theta) << trial;
      EXPECT_EQ(k.det_min, ref.det_min) << trial;
    }
  }
  std::printf("check stages on states near H_cr: bound %d, sampled bound %d, minimiser %d, sweep %d\n",
              stages[1], stages[2], stages[3], stages[4]);
  EXPECT_GT(stages[3] + stages[2], 50);
  EXPECT_GT(stages[4], 50);
  // Hardening: never a bifurcation; max over random stresses of H_cr is <= 0.
  std::uniform_real_distribution<double> u(-2e9, 2e9);
  for (int trial = 0; trial < 300; ++trial) {
    const double sxx = u(rng), syy = u(rng), szz = u(rng), sxy = u(rng);
    EXPECT_LE(hcr_j2_max(sxx, syy, szz, sxy, m.mu, m.M), 1e-12 * m.mu) << trial;
    double C[16];
    j2_tangent(m.lambda, m.mu, sxx, syy, szz, sxy, j2_beta(m.mu, m.j2.H_h), C);
    int stage = 0;
    EXPECT_FALSE(bifurcation_check(C, m.bif, scale, &stage).bifurcated);
    EXPECT_EQ(stage, 1) << trial;
  }
}

// The closed-form maximum of H_cr over the normal (the film model's pre-check) against the
// sweep-and-refine hcr_j2_max on random stresses, and the exact relation behind the pre-check,
// det Q(n) = G M (H - H_cr(n)) / (3G + H), against acoustic_det.
TEST(FastBifurcation, ClosedFormCriticalModulus) {
  const Material m = tungsten();
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-2e9, 2e9), hh(-0.5, 0.5), th(0, kPi);
  double worst = 0, worst_det = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const double sxx = u(rng), syy = u(rng), szz = u(rng), sxy = u(rng);
    const double ref = hcr_j2_max(sxx, syy, szz, sxy, m.mu, m.M);
    const double cf = hcr_j2_max_closed(sxx, syy, szz, sxy, m.mu, m.M);
    worst = std::max(worst, std::fabs(cf - ref) / m.mu);
    EXPECT_LE(cf, 1e-12 * m.mu) << trial;  // never above zero
    const double H = hh(rng) * m.mu;
    double C[16];
    j2_tangent(m.lambda, m.mu, sxx, syy, szz, sxy, j2_beta(m.mu, H), C);
    for (int k = 0; k < 10; ++k) {
      const double t = th(rng);
      const double d = m.mu * m.M * (H - hcr_j2(sxx, syy, szz, sxy, m.mu, m.M, t)) / (3 * m.mu + H);
      worst_det = std::max(worst_det, std::fabs(d - acoustic_det(C, t)) / (m.mu * m.M));
    }
  }
  std::printf("closed-form max H_cr vs sweep: worst %.2e G; det Q relation: worst %.2e G M\n", worst,
              worst_det);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worst_det, 1e-13);
  // The film model's pre-check (no square root, no normalisation) is the same test as
  // H - max H_cr > 1e-8 G, away from the margin itself.
  int excluded = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double sxx = u(rng), syy = u(rng), szz = u(rng), sxy = u(rng);
    const double hcr = hcr_j2_max_closed(sxx, syy, szz, sxy, m.mu, m.M);
    const double H = hcr + hh(rng) * 1e-2 * m.mu;
    if (std::fabs(H - hcr - 1e-8 * m.mu) < 1e-12 * m.mu) continue;
    const bool ref = H - hcr > 1e-8 * m.mu;
    EXPECT_EQ(j2_cannot_bifurcate(sxx, syy, szz, sxy, m.mu, m.M, H), ref) << trial;
    excluded += ref;
  }
  EXPECT_GT(excluded, 500);
  EXPECT_LT(excluded, 1500);
  // Pure shear in plane: 0 (docs/physics.md §5); uniaxial strain: about -0.64 G.
  EXPECT_NEAR(hcr_j2_max_closed(1e9, -1e9, 0, 0, m.mu, m.M), 0.0, 1e-12 * m.mu);
  const double lat = m.lambda / m.M * -1.6e9;
  EXPECT_NEAR(hcr_j2_max_closed(-1.6e9, lat, lat, 0, m.mu, m.M),
              hcr_j2_max(-1.6e9, lat, lat, 0, m.mu, m.M), 1e-9 * m.mu);
}

}  // namespace
}  // namespace smpm
