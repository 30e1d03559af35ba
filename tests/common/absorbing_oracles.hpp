#pragma once
// Closed forms (or their numerical evaluation) for the absorbing ends of the 1D column
// (docs/physics.md section 9): the fraction of a pulse's energy an end sends back, from the
// end's reflection coefficient R(w) weighted by the energy spectrum |F(w)|^2 of the load history
// fn on [0, duration].
#include <cmath>
#include <complex>
#include <functional>

#include "silentmpm/time_function.hpp"

namespace smpm::testing {

// sum_w |F(w)|^2 |R(w)|^2 / sum_w |F(w)|^2 over 0 < w < 40 pi / duration.
inline double reflected_energy_fraction(const TimeFunction& fn, double duration,
                                        const std::function<double(double)>& r2) {
  const int nt = 1000, nw = 1000;
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
    const double e = re * re + im * im;
    num += e * r2(w);
    den += e;
  }
  return num / den;
}

// Kelvin-Voigt end: |R(w)|^2 = 1 / (1 + (2 w delta / c)^2) (section 9.1).
inline double kv_reflected_energy_fraction(const TimeFunction& fn, double duration, double delta,
                                           double c) {
  return reflected_energy_fraction(fn, duration, [&](double w) {
    const double q = 2 * w * delta / c;
    return 1 / (1 + q * q);
  });
}

// A graded damping layer of thickness L, mass-proportional alpha = alpha0 (x / L)^power and
// stiffness-proportional beta = beta0 (x / L)^power (x from its inner edge), ending in a fixed end
// (lk = false) or an LK dashpot (lk = true), in a medium of wave speed c (section 9.2): with
// S = c^2 (1 + i w beta) U' (the stress over the density), U' = S / (c^2 (1 + i w beta)) and
// S' = -(w^2 - i w alpha) U, integrated by RK4 from the end back to x = 0, where
// U = A e^{-ikx} + B e^{ikx} gives R = B / A.
inline double damping_layer_r2(double w, double L, double alpha0, double power, double c,
                               bool lk, double beta0 = 0) {
  using C = std::complex<double>;
  const C I(0, 1);
  auto ramp = [&](double x) { return std::pow(std::max(x, 0.0) / L, power); };
  auto f = [&](double x, C uu, C ss, C& fu, C& fs) {
    fu = ss / (c * c * (1.0 + I * w * beta0 * ramp(x)));
    fs = -(w * w - I * w * alpha0 * ramp(x)) * uu;
  };
  C u = lk ? C(1) : C(0), s = lk ? -I * w * c : C(c * c);
  const int n = 1000;
  const double h = -L / n;
  for (int k = 0; k < n; ++k) {
    const double x = L + k * h;
    C a1, b1, a2, b2, a3, b3, a4, b4;
    f(x, u, s, a1, b1);
    f(x + 0.5 * h, u + 0.5 * h * a1, s + 0.5 * h * b1, a2, b2);
    f(x + 0.5 * h, u + 0.5 * h * a2, s + 0.5 * h * b2, a3, b3);
    f(x + h, u + h * a3, s + h * b3, a4, b4);
    u += h / 6 * (a1 + 2. * a2 + 2. * a3 + a4);
    s += h / 6 * (b1 + 2. * b2 + 2. * b3 + b4);
  }
  const double k0 = w / c;
  const C q = s / (c * c) / (I * k0);  // U'(0) / (i k), beta(0) = 0
  return std::norm((u + q) / (u - q));
}

}  // namespace smpm::testing
