#pragma once
// The Kelvin-Voigt end's reflection at normal incidence, |R(w)|^2 = 1 / (1 + (2 w delta / c)^2)
// (docs/physics.md section 9.1), weighted by the energy spectrum of a load history fn on
// [0, duration]: the fraction of a pulse's energy the end sends back.
#include <cmath>

#include "silentmpm/time_function.hpp"

namespace smpm::testing {

inline double kv_reflected_energy_fraction(const TimeFunction& fn, double duration, double delta,
                                           double c) {
  const int nt = 2000, nw = 4000;
  const double wmax = 40 * M_PI / duration, dw = wmax / nw, dtt = duration / nt;
  double num = 0, den = 0;
  for (int j = 0; j < nw; ++j) {
    const double w = (j + 0.5) * dw;
    double re = 0, im = 0;
    for (int i = 0; i < nt; ++i) {
      const double t = (i + 0.5) * dtt, f = fn(t);
      re += f * std::cos(w * t);
      im -= f * std::sin(w * t);
    }
    const double e = re * re + im * im, q = 2 * w * delta / c;
    num += e / (1 + q * q);
    den += e;
  }
  return num / den;
}

}  // namespace smpm::testing
