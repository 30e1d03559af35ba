#pragma once
// J2 (von Mises) plasticity with linear hardening up to a peak, then linear softening
// (docs/physics.md §5, the tungsten film of paper §5).
//
//   yield function   f = q - sigma_bar(e),  q = sqrt(3/2) |s|
//   flow stress      sigma_bar = sigma_y + H_h e                 for e <= e_pk
//                    sigma_bar = sigma_peak + H_s (e - e_pk)     for e >  e_pk   (H_s < 0)
//                    (floored at zero: a fully softened point flows at zero deviatoric stress)
//   radial return    dgamma = (q_tr - sigma_bar(e_n)) / (3G + H), re-solved on the softening
//                    branch when the step crosses the peak; s = (1 - 3G dgamma / q_tr) s_tr
//   tangent          C_ep = C - 6G^2 / (3G + H) N (x) N,  N = s / |s|
//
// The moduli E_h, E_s of the paper can be read two ways (an input):
//   Plastic  H_h = E_h, H_s = -E_s (default; docs/physics.md's assumption)
//   Tangent  E_h, E_s are slopes of the uniaxial stress-strain curve, H = E E_t / (E - E_t)
//            with E_t = E_h (hardening) and E_t = -E_s (softening).
// Stresses are four components (xx, yy, zz, xy), plane strain.
#include <algorithm>
#include <cmath>

namespace smpm {

enum class ModuliReading { Plastic, Tangent };

struct J2SoftParams {
  double sigma_y = 0;       // initial yield stress
  double sigma_peak = 0;    // peak stress (>= sigma_y)
  double E_h = 0;           // hardening modulus (> 0)
  double E_s = 0;           // softening modulus magnitude (> 0); the branch slope is negative
  ModuliReading reading = ModuliReading::Plastic;
  // Derived by derive(E):
  double H_h = 0, H_s = 0;  // plastic moduli of the two branches (H_s < 0)
  double e_peak = 0;        // equivalent plastic strain at the peak
  double e_zero = 0;        // equivalent plastic strain where the flow stress reaches zero

  void derive(double E) {
    if (reading == ModuliReading::Plastic) {
      H_h = E_h;
      H_s = -E_s;
    } else {
      H_h = E * E_h / (E - E_h);
      H_s = E * (-E_s) / (E + E_s);
    }
    e_peak = H_h > 0 ? (sigma_peak - sigma_y) / H_h : 0.0;
    e_zero = e_peak + sigma_peak / (-H_s);
  }
  double flow_stress(double e) const {
    if (e <= e_peak) return sigma_y + H_h * e;
    return std::max(0.0, sigma_peak + H_s * (e - e_peak));
  }
  // Plastic modulus governing further loading from equivalent plastic strain e.
  double modulus(double e) const {
    if (e < e_peak) return H_h;
    return e < e_zero ? H_s : 0.0;
  }
};

struct J2Return {
  bool plastic = false;
  double dgamma = 0;  // equivalent plastic strain increment
  double q = 0;       // von Mises stress after the update
  double H = 0;       // plastic modulus at the end of the step (for the tangent)
};

// Return mapping on a trial stress (already holding the elastic increment). e is the equivalent
// plastic strain, updated in place. mu is the shear modulus G.
inline J2Return j2soft_return(const J2SoftParams& P, double mu, double& sxx, double& syy,
                              double& szz, double& sxy, double& e) {
  J2Return r;
  const double p = (sxx + syy + szz) / 3.0;
  double a = sxx - p, b = syy - p, c = szz - p;
  const double ss = a * a + b * b + c * c + 2 * sxy * sxy;
  const double q = std::sqrt(1.5 * ss);
  const double sig = P.flow_stress(e);
  r.q = q;
  r.H = P.modulus(e);
  if (q <= sig) return r;
  double H = P.modulus(e);
  double dg = (q - sig) / (3 * mu + H);
  if (e < P.e_peak && e + dg > P.e_peak) {
    // The step crosses the peak: re-solve on the softening branch.
    H = P.H_s;
    dg = (q - P.sigma_peak - P.H_s * (e - P.e_peak)) / (3 * mu + P.H_s);
  }
  if (e + dg > P.e_zero && H < 0) {
    // Softened to zero strength: perfectly plastic at zero deviatoric stress.
    H = 0;
    dg = q / (3 * mu);
  }
  const double qn = std::max(0.0, q - 3 * mu * dg);
  const double scale = q > 0 ? qn / q : 0.0;
  a *= scale; b *= scale; c *= scale;
  sxx = p + a; syy = p + b; szz = p + c; sxy *= scale;
  e += dg;
  r.plastic = true;
  r.dgamma = dg;
  r.q = qn;
  r.H = P.modulus(e);
  return r;
}

// In-plane continuum tangent C_ijkl (i, j, k, l in {x, y}) as C[((i*2+j)*2+k)*2+l].
// beta = 6 G^2 / (3G + H) for plastic loading, 0 for the elastic tangent.
inline void j2_tangent(double lambda, double mu, double sxx, double syy, double szz, double sxy,
                       double beta, double C[16]) {
  const double p = (sxx + syy + szz) / 3.0;
  const double a = sxx - p, b = syy - p, c = szz - p;
  const double norm = std::sqrt(a * a + b * b + c * c + 2 * sxy * sxy);
  double N[2][2] = {{0, 0}, {0, 0}};
  if (norm > 0) {
    N[0][0] = a / norm; N[1][1] = b / norm; N[0][1] = N[1][0] = sxy / norm;
  }
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l) {
          const double d = lambda * (i == j) * (k == l) + mu * ((i == k) * (j == l) + (i == l) * (j == k));
          C[((i * 2 + j) * 2 + k) * 2 + l] = d - beta * N[i][j] * N[k][l];
        }
}

inline double j2_beta(double mu, double H) { return 6 * mu * mu / (3 * mu + H); }

}  // namespace smpm
