#pragma once
// Helpers shared by the contact tests: the two elastic materials of the 1D plate impact
// (aluminium flyer, steel target), the impact set-up, and its closed forms (docs/physics.md §4)
// (tests/physics/test_contact.cpp, tests/unit/test_contact_oracle.cpp); the same impact as a
// case document (tests/physics/test_contact_case.cpp, tests/errors/test_contact_case_errors.cpp).
#include <nlohmann/json.hpp>

#include "silentmpm/solver.hpp"

namespace smpm::contact_testing {

inline Material aluminium(Model model = Model::Elastic) {
  Material m;
  m.name = "aluminium"; m.model = model;
  m.E = 70e9; m.nu = 0.33; m.rho = 2700; m.sigma_y = 200e6;
  m.derive();
  return m;
}

inline Material steel(Model model = Model::Elastic) {
  Material m;
  m.name = "steel"; m.model = model;
  m.E = 200e9; m.nu = 0.30; m.rho = 7800; m.sigma_y = 400e6;
  m.derive();
  return m;
}

struct Impact {
  int flyer_cells = 50;    // d1 / h
  int target_cells = 160;  // d2 / h: its back-face echo returns after 2 d2 / c2 > t_end
  int height = 2;          // cells across, rollers on top and bottom
  int ppc_side = 1;
  double h = 1e-3;
  double v0 = 10.0;
  double cfl = 0.3;
  ContactType type = ContactType::Multi;
  double friction = 0;
  Scheme scheme = Scheme::MUSL;
  int threads = 1;
  int mass_correction = 0;  // scheme.mass_correction
  ShapeKind shape = ShapeKind::Bilinear;  // scheme.shape
  double offset = 0;  // the grid moved left by this fraction of a cell: the contact face off its lines
};

struct Oracle {
  double z1, z2, sigma, tc, rebound, c1, c2;
};

inline Oracle oracle(const Impact& c) {
  const Material a = aluminium(), b = steel();
  Oracle o;
  o.z1 = a.impedance_p();
  o.z2 = b.impedance_p();
  o.c1 = a.cd;
  o.c2 = b.cd;
  o.sigma = c.v0 * o.z1 * o.z2 / (o.z1 + o.z2);
  o.tc = 2 * c.flyer_cells * c.h / a.cd;
  o.rebound = c.v0 * (o.z1 - o.z2) / (o.z1 + o.z2);
  return o;
}

// Aluminium flyer (40 mm) at 10 m/s onto a steel target (120 mm), 1 mm cells, rollers.
inline nlohmann::json impact_case() {
  return nlohmann::json::parse(R"({
    "grid": { "origin": [-0.05, 0], "size": [0.18, 0.002], "cell": 0.001 },
    "time": { "end": 2.6e-5, "cfl": 0.3 },
    "materials": {
      "aluminium": { "model": "elastic", "young": 70e9, "poisson": 0.33, "density": 2700 },
      "steel": { "model": "elastic", "young": 200e9, "poisson": 0.30, "density": 7800 }
    },
    "bodies": [
      { "name": "flyer", "material": "aluminium", "box": [-0.04, 0, 0, 0.002], "velocity": [10, 0] },
      { "name": "target", "material": "steel", "box": [0, 0, 0.12, 0.002] }
    ],
    "boundaries": [
      { "type": "roller", "component": "y", "grid_side": "bottom" },
      { "type": "roller", "component": "y", "grid_side": "top" }
    ],
    "scheme": { "threads": 1 },
    "contact": { "type": "multi", "friction": 0 },
    "output": { "snapshots": 0, "progress": false }
  })");
}

}  // namespace smpm::contact_testing
