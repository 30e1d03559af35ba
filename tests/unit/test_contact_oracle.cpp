// The closed forms of the contact tests (tests/physics/test_contact.cpp): the 1D plate impact's
// contact stress from the P-wave impedances Z = rho c_d computed from E, nu, rho (docs/physics.md §4).
#include <gtest/gtest.h>

#include "test_contact_common.hpp"

using namespace smpm;
using namespace smpm::contact_testing;

// The oracle itself: 12.26 MPa per m/s from the P-wave impedances (docs/physics.md §4).
TEST(ContactOracle, ImpedancesFromConstants) {
  Impact c;
  c.v0 = 1.0;
  const Oracle o = oracle(c);
  EXPECT_NEAR(o.z1, 1.673e7, 0.001e7);
  EXPECT_NEAR(o.z2, 4.583e7, 0.001e7);
  EXPECT_NEAR(o.sigma, 12.26e6, 0.01e6);
}
