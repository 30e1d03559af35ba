// The energy balance of an elastic run with a silent boundary (the von Mises return mapping is in
// tests/unit/test_material.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common.hpp"

using namespace smpm;
using namespace smpm::testing;

// Elastic column with a silent end, smooth pulse: kinetic + elastic + absorbed = external work.
TEST(EnergyBalance, ElasticWithSilentBoundary) {
  for (SilentForm form : {SilentForm::Nodal, SilentForm::Particle}) {
    ColumnSpec c;
    c.cells = 80;
    c.height = 6;
    c.form = form;
    c.anchor = form == SilentForm::Nodal ? Anchor::Boundary : Anchor::Particle;
    const double dur = 30 * c.h / 5918.5;
    c.fn = sin2_pulse(dur, 0.5 * dur);
    auto s = make_column(c);
    double worst = 0;
    while (s->t < dur + 2.5 * c.cells * c.h / 5918.5) {
      s->step();
      if (s->steps % 25 == 0) {
        s->update_energies();
        worst = std::max(worst, std::abs(s->energy.imbalance()));
      }
    }
    s->update_energies();
    // Most of the energy has left through the silent end.
    EXPECT_GT(s->energy.absorbed, 0.95 * s->energy.external_work);
    // The imbalance at every sampled time, relative to the total input.
    EXPECT_LT(worst / s->energy.external_work, 0.01) << "form " << int(form);
    std::printf("  form %d: worst imbalance %.2e of the input\n", int(form), worst / s->energy.external_work);
  }
}
