#pragma once
// Helpers shared by the curve-probe tests (tests/unit/test_geometry_probes.cpp and
// tests/errors/test_geometry_probe_errors.cpp): the 30 degree inclined plate as a case file.
#include <cmath>
#include <string>

#include "test_geometry_common.hpp"

namespace smpm::geotest {

const double kAngle = 30.0 * M_PI / 180.0;

// A case on the inclined plate of test_geometry_common.hpp (right edge: curve 12, from (xb, 0) to
// (xt, H)), with the given probes.
inline std::string inclined_case(const std::string& geo, const std::string& probes) {
  return R"({
  "grid": { "origin": [-0.004, -0.004], "size": [0.034, 0.028], "cell": 0.001 },
  "time": { "end": 1e-7, "cfl": 0.3 },
  "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
  "geometry": { "file": ")" + geo + R"(" },
  "bodies": [ { "name": "plate", "material": "w", "surface": 1, "particles_per_cell": 4 } ],
  "probes": [ )" + probes + R"( ],
  "output": { "snapshots": 0, "progress": false }
})";
}

}  // namespace smpm::geotest
