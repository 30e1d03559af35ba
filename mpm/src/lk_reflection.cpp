#include "silentmpm/lk_reflection.hpp"

#include <cmath>

namespace smpm {

namespace {
using cd = std::complex<double>;

struct Angles {
  cd st, ct, sf, cf;  // sin/cos of the P angle theta and the SV angle phi
};

// The determinant D and both numerators share these groups of terms.
cd det(double k, double a, double b, const Angles& g) {
  const cd c2f = 1.0 - 2.0 * g.sf * g.sf, s2f = 2.0 * g.sf * g.cf, s2t = 2.0 * g.st * g.ct;
  return (c2f + a * g.ct) * (c2f + b * g.cf) + (k * s2f + a * g.sf) * (k * s2t + b * g.st);
}
}  // namespace

LKReflection lk_reflection(double nu, double a, double b, double angle_p, double angle_s) {
  const double k = std::sqrt((1 - 2 * nu) / (2 * (1 - nu)));
  LKReflection r;
  {  // incident P: Snell sin(phi) = k sin(theta), always real
    Angles g;
    g.st = std::sin(angle_p);
    g.ct = std::cos(angle_p);
    g.sf = k * g.st;
    g.cf = std::sqrt(1.0 - g.sf * g.sf);
    const cd c2f = 1.0 - 2.0 * g.sf * g.sf, s2f = 2.0 * g.sf * g.cf, s2t = 2.0 * g.st * g.ct;
    const cd D = det(k, a, b, g);
    r.rpp = ((a * g.ct - c2f) * (c2f + b * g.cf) + (k * s2f + a * g.sf) * (k * s2t - b * g.st)) / D;
    r.rps = 2.0 * g.st * g.ct * (2.0 * k * c2f - a * b) / D;
    r.epp = std::norm(r.rpp);
    r.eps = std::norm(r.rps) * k * g.cf.real() / g.ct.real();
  }
  {  // incident SV: sin(theta) = sin(phi) / k; evanescent P beyond the critical angle
    Angles g;
    g.sf = std::sin(angle_s);
    g.cf = std::cos(angle_s);
    g.st = g.sf / k;
    const double s2 = std::norm(g.st);
    const bool evanescent = s2 > 1.0;
    g.ct = evanescent ? cd(0.0, -std::sqrt(s2 - 1.0)) : cd(std::sqrt(1.0 - s2), 0.0);
    const cd c2f = 1.0 - 2.0 * g.sf * g.sf, s2f = 2.0 * g.sf * g.cf, s2t = 2.0 * g.st * g.ct;
    const cd D = det(k, a, b, g);
    r.rsp = 2.0 * g.sf * g.cf * (2.0 * k * c2f - a * b) / D;
    r.rss = ((c2f + a * g.ct) * (c2f - b * g.cf) - (k * s2t + b * g.st) * (k * s2f - a * g.sf)) / D;
    r.ess = std::norm(r.rss);
    r.esp = evanescent ? 0.0 : std::norm(r.rsp) * g.ct.real() / (k * g.cf.real());
  }
  return r;
}

}  // namespace smpm
