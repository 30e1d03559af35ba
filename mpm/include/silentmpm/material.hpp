#pragma once

#include <type_traits>
// Materials: constants, derived wave speeds, and the stress updates used by the MPM kernels.
//
// Stresses are kept as four components (xx, yy, zz, xy) in plane strain: sigma_zz is integrated
// as its own component because plasticity makes it independent of sigma_xx + sigma_yy.
// Stress updates are free inline functions templated on the model, so a particle loop over a
// group of one material has no virtual call and no branch on the model inside.
#include <cmath>
#include <string>

#include "silentmpm/bifurcation.hpp"
#include "silentmpm/decohesion.hpp"
#include "silentmpm/j2soft.hpp"

namespace smpm {

// J2Film: J2 with hardening then softening, bifurcation check and decohesion (film.hpp).
enum class Model { Elastic, VonMises, J2Film };

const char* model_name(Model m);

struct Material {
  std::string name;
  Model model = Model::Elastic;
  double E = 0, nu = 0, rho = 0;
  double sigma_y = 0;  // von Mises yield stress (VonMises only)
  J2SoftParams j2;          // J2Film only (j2.sigma_y is its yield stress)
  BifurcationParams bif;    // J2Film only
  DecohesionParams coh;     // J2Film only
  // Derived (call derive() after setting the inputs).
  double lambda = 0, mu = 0, M = 0, K = 0, cd = 0, cs = 0;
  void derive() {
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu = E / (2 * (1 + nu));
    M = lambda + 2 * mu;
    K = lambda + 2.0 / 3.0 * mu;
    cd = std::sqrt(M / rho);
    cs = std::sqrt(mu / rho);
    if (model == Model::J2Film) {
      j2.derive(E);
      if (!(coh.min_strength > 0)) coh.min_strength = 1e-3 * j2.sigma_y;
    }
  }
  double impedance_p() const { return rho * cd; }
  double impedance_s() const { return rho * cs; }
};

// Stress state of one particle (plane strain, 4 components).
struct Stress4 {
  double xx, yy, zz, xy;
};

// Second invariant of the deviatoric stress, J2 = s:s / 2.
inline double j2_of(double sxx, double syy, double szz, double sxy) {
  const double p = (sxx + syy + szz) / 3.0;
  const double a = sxx - p, b = syy - p, c = szz - p;
  return 0.5 * (a * a + b * b + c * c) + sxy * sxy;
}

// Complementary (stored elastic) energy density for isotropic linear elasticity:
// W = (1+nu)/(2E) sigma:sigma - nu/(2E) (tr sigma)^2.
inline double elastic_energy_density(const Material& m, double sxx, double syy, double szz,
                                     double sxy) {
  const double ss = sxx * sxx + syy * syy + szz * szz + 2 * sxy * sxy;
  const double tr = sxx + syy + szz;
  return ((1 + m.nu) * ss - m.nu * tr * tr) / (2 * m.E);
}

// Elastic trial update from a plane-strain strain increment (dexx, deyy, dgxy = 2 dexy).
template <class T>  // double, or a SIMD register of four (the MPM kernels): the same operations
inline void elastic_increment(const Material& m, typename std::common_type<T>::type dexx,
                              typename std::common_type<T>::type deyy,
                              typename std::common_type<T>::type dgxy, T& sxx, T& syy, T& szz,
                              T& sxy) {
  const T lt = m.lambda * (dexx + deyy);
  sxx += lt + 2 * m.mu * dexx;
  syy += lt + 2 * m.mu * deyy;
  szz += lt;
  sxy += m.mu * dgxy;
}

// Stress update for one particle. Returns the plastic work density of the increment
// (energy dissipated per unit volume). eps_p is the accumulated equivalent plastic strain.
template <Model M>
inline double stress_update(const Material& m, double dexx, double deyy, double dgxy,
                            double& sxx, double& syy, double& szz, double& sxy, double& eps_p);

template <>
inline double stress_update<Model::Elastic>(const Material& m, double dexx, double deyy,
                                            double dgxy, double& sxx, double& syy, double& szz,
                                            double& sxy, double&) {
  elastic_increment(m, dexx, deyy, dgxy, sxx, syy, szz, sxy);
  return 0.0;
}

// von Mises, elastic-perfectly plastic, radial return on the four components.
template <>
inline double stress_update<Model::VonMises>(const Material& m, double dexx, double deyy,
                                             double dgxy, double& sxx, double& syy, double& szz,
                                             double& sxy, double& eps_p) {
  elastic_increment(m, dexx, deyy, dgxy, sxx, syy, szz, sxy);
  const double p = (sxx + syy + szz) / 3.0;
  double a = sxx - p, b = syy - p, c = szz - p;
  const double ss = a * a + b * b + c * c + 2 * sxy * sxy;
  const double q = std::sqrt(1.5 * ss);
  if (q <= m.sigma_y) return 0.0;
  const double scale = m.sigma_y / q;
  const double dgamma = (q - m.sigma_y) / (3 * m.mu);  // equivalent plastic strain increment
  // Plastic work: sigma_new : d eps_p, with d eps_p = (s_trial - s_new) / (2 mu).
  // sigma_new : (s_tr - s_new) = scale (1 - scale) s_tr : s_tr.
  const double wp = scale * (1 - scale) * ss / (2 * m.mu);
  a *= scale; b *= scale; c *= scale;
  sxx = p + a; syy = p + b; szz = p + c; sxy *= scale;
  eps_p += dgamma;
  return wp;
}

}  // namespace smpm
