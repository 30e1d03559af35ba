#pragma once
// Exact plane-wave reflection at a Lysmer-Kuhlemeyer boundary (2D P-SV), docs/physics.md §4.1.
//
// Boundary z = 0 with outward normal +z; angles measured from the normal. The boundary condition
// is sigma_zz = -a rho c_d dot(u_z), sigma_xz = -b rho c_s dot(u_x); a = b = 0 is a free surface,
// a = b = 1 the standard LK dashpots. kappa = c_s / c_d = sqrt((1 - 2 nu) / (2 (1 - nu))).
// R are displacement-amplitude ratios (complex beyond the SV critical angle); E are the
// reflected energy fractions (E_PP + E_PS = 1 and E_SS + E_SP = 1 on a free surface).
#include <complex>

namespace smpm {

struct LKReflection {
  std::complex<double> rpp, rps;  // incident P: reflected P and SV
  std::complex<double> rss, rsp;  // incident SV: reflected SV and P
  double epp = 0, eps = 0;        // energy fractions, incident P
  double ess = 0, esp = 0;        // energy fractions, incident SV (esp = 0 beyond critical)
};

// Coefficients for a P wave incident at angle_p and an SV wave incident at angle_s (radians).
LKReflection lk_reflection(double nu, double a, double b, double angle_p, double angle_s);
// Both incident at the same angle.
inline LKReflection lk_reflection(double nu, double a, double b, double angle) {
  return lk_reflection(nu, a, b, angle, angle);
}

}  // namespace smpm
