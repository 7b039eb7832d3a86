// Integrator: the trapezoidal integral of cos approaches sin within the trapezoidal error bound.
#include "rp/math/Integrator.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "rp/math/Matrix.hpp"

namespace rp {
namespace {

TEST(Integrator, IntegratingCosGivesSinWithinTheTrapezoidalBound) {
  for (double T : {0.01, 0.001}) {
    Integrator<double> in(T);
    EXPECT_EQ(in.integrate(std::cos(0.0)), 0.0);
    for (int i = 1; i <= static_cast<int>(10 / T); ++i) {
      const double t = i * T;
      const double y = in.integrate(std::cos(t));
      // Composite trapezoidal rule: |error| <= t T^2 / 12 max|cos''| = t T^2 / 12.
      ASSERT_LE(std::abs(y - std::sin(t)), t * T * T / 12 + 1e-13) << "t=" << t << " T=" << T;
    }
  }
}

TEST(Integrator, LinearSignalsAreIntegratedExactly) {
  Integrator<Vector<2>> in(0.5);
  Vector<2> x;
  for (int i = 0; i <= 8; ++i) {
    const double t = i * 0.5;
    x = 2 * t, 1;
    in.integrate(x);
  }
  EXPECT_DOUBLE_EQ(in.getIntegral()(0), 16.0);  // integral of 2t over [0, 4]
  EXPECT_DOUBLE_EQ(in.getIntegral()(1), 4.0);
}

TEST(Integrator, ResetToAnInitialValue) {
  Integrator<double> in(1.0);
  in.reset(10.0);
  EXPECT_EQ(in.integrate(2.0), 10.0);
  EXPECT_EQ(in.integrate(2.0), 12.0);
  in.reset();
  EXPECT_EQ(in.integrate(5.0), 0.0);
  EXPECT_THROW(Integrator<double>(-1.0), MathException);
}

}  // namespace
}  // namespace rp
