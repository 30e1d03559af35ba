// Load time functions: values against their definitions.
#include <gtest/gtest.h>

#include <cmath>

#include "silentmpm/time_function.hpp"

using smpm::TimeFunction;
using K = TimeFunction::Kind;

TEST(TimeFunction, Shapes) {
  TimeFunction f;
  f.kind = K::Rectangular; f.start = 1.0; f.duration = 2.0;
  EXPECT_EQ(f(0.99), 0.0); EXPECT_EQ(f(1.0), 1.0); EXPECT_EQ(f(2.99), 1.0); EXPECT_EQ(f(3.01), 0.0);
  f.kind = K::Triangular;
  EXPECT_DOUBLE_EQ(f(1.5), 0.5); EXPECT_DOUBLE_EQ(f(2.0), 1.0); EXPECT_DOUBLE_EQ(f(2.75), 0.25);
  EXPECT_EQ(f(3.5), 0.0);
  f.kind = K::Sin2Pulse; f.ramp = 0.5;
  EXPECT_DOUBLE_EQ(f(1.25), 0.5);       // half way up the sin^2 ramp
  EXPECT_DOUBLE_EQ(f(2.0), 1.0);        // plateau
  EXPECT_NEAR(f(2.75), 0.5, 1e-12);     // half way down
  EXPECT_EQ(f(0.5), 0.0);
  f.kind = K::Step; f.ramp = 0;
  EXPECT_EQ(f(0.9), 0.0); EXPECT_EQ(f(100.0), 1.0);
  f.ramp = 1.0;
  EXPECT_DOUBLE_EQ(f(1.5), 0.5);
  f.kind = K::Table; f.table = {{0.0, 0.0}, {1.0, 2.0}, {3.0, -2.0}};
  EXPECT_DOUBLE_EQ(f(0.5), 1.0); EXPECT_DOUBLE_EQ(f(2.0), 0.0); EXPECT_DOUBLE_EQ(f(5.0), -2.0);
  f.kind = K::Constant;
  EXPECT_EQ(f(-3.0), 1.0);
}

// The half-sine pulse: sin(pi s / T) on [start, start + T], zero outside; its impulse is 2T/pi.
TEST(TimeFunction, HalfSine) {
  TimeFunction f;
  f.kind = K::HalfSine;
  f.start = 1.0;
  f.duration = 2.0;
  EXPECT_EQ(f(0.99), 0.0);
  EXPECT_EQ(f(3.01), 0.0);
  EXPECT_DOUBLE_EQ(f(2.0), 1.0);
  EXPECT_NEAR(f(1.5), std::sqrt(0.5), 1e-15);
  double impulse = 0;
  const int n = 200000;
  for (int k = 0; k < n; ++k) impulse += f(1.0 + (k + 0.5) * 2.0 / n) * 2.0 / n;
  EXPECT_NEAR(impulse, 4.0 / M_PI, 1e-9);
  EXPECT_NE(f.describe().find("half-sine"), std::string::npos);
}
