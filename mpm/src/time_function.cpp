#include "silentmpm/time_function.hpp"

#include <cmath>
#include <sstream>

namespace smpm {

namespace {
double sin2_ramp(double s) {  // 0 -> 1 smoothly for s in [0, 1]
  if (s <= 0) return 0;
  if (s >= 1) return 1;
  const double v = std::sin(0.5 * M_PI * s);
  return v * v;
}
}  // namespace

double TimeFunction::operator()(double t) const {
  const double s = t - start;
  switch (kind) {
    case Kind::Constant:
      return 1.0;
    case Kind::Step:
      if (s < 0) return 0;
      return ramp > 0 ? sin2_ramp(s / ramp) : 1.0;
    case Kind::Rectangular:
      return (s >= 0 && s < duration) ? 1.0 : 0.0;
    case Kind::Triangular: {
      if (s < 0 || s > duration) return 0;
      const double half = 0.5 * duration;
      return s <= half ? s / half : (duration - s) / half;
    }
    case Kind::Sin2Pulse: {
      if (s < 0 || s > duration) return 0;
      return std::min(sin2_ramp(s / ramp), sin2_ramp((duration - s) / ramp));
    }
    case Kind::HalfSine:  // sin(pi s / duration) over one half period
      if (s < 0 || s > duration) return 0;
      return std::sin(M_PI * s / duration);
    case Kind::Table: {
      if (table.empty()) return 0;
      if (t <= table.front().first) return table.front().second;
      if (t >= table.back().first) return table.back().second;
      size_t lo = 0, hi = table.size() - 1;
      while (hi - lo > 1) {
        const size_t mid = (lo + hi) / 2;
        (table[mid].first <= t ? lo : hi) = mid;
      }
      const auto& a = table[lo];
      const auto& b = table[hi];
      return a.second + (b.second - a.second) * (t - a.first) / (b.first - a.first);
    }
  }
  return 0;
}

std::string TimeFunction::describe() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::Constant: o << "constant"; break;
    case Kind::Step: o << "step at " << start << " s (ramp " << ramp << " s)"; break;
    case Kind::Rectangular: o << "rectangular pulse " << start << " s + " << duration << " s"; break;
    case Kind::Triangular: o << "triangular pulse " << start << " s + " << duration << " s"; break;
    case Kind::Sin2Pulse:
      o << "sin^2-ramped pulse " << start << " s + " << duration << " s (ramps " << ramp << " s)";
      break;
    case Kind::HalfSine: o << "half-sine pulse " << start << " s + " << duration << " s"; break;
    case Kind::Table: o << "table of " << table.size() << " points"; break;
  }
  return o.str();
}

}  // namespace smpm
