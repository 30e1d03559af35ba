#pragma once
// Load time functions f(t) multiplying a traction amplitude.
#include <string>
#include <utility>
#include <vector>

namespace smpm {

struct TimeFunction {
  enum class Kind { Constant, Step, Rectangular, Triangular, Sin2Pulse, HalfSine, Table };
  Kind kind = Kind::Constant;
  double start = 0;     // onset time
  double duration = 0;  // pulse length (Rectangular, Triangular, Sin2Pulse, HalfSine)
  double ramp = 0;      // rise/fall time of the sin^2-ramped pulse, or rise time of a ramped step
  std::vector<std::pair<double, double>> table;  // (t, value), t increasing; linear in between
  double operator()(double t) const;
  std::string describe() const;
};

}  // namespace smpm
