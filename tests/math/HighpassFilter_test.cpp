// HighpassFilter against the analytic responses of the continuous Butterworth filters.
#include "rp/math/HighpassFilter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "FilterTestSupport.hpp"
#include "rp/math/Matrix.hpp"

namespace rp {
namespace {

constexpr double kPi = std::numbers::pi;

// Continuous unit-step responses: e^{-wc t} (order 1) and e^{-at}(cos at - sin at), a = wc/sqrt(2)
// (order 2: the second derivative of the low-pass step response divided by wc^2).
double stepResponse(int order, double wc, double t) {
  if (order == 1) return std::exp(-wc * t);
  const double a = wc / std::numbers::sqrt2;
  return std::exp(-a * t) * (std::cos(a * t) - std::sin(a * t));
}

TEST(HighpassFilter, StepResponseMatchesContinuousFilter) {
  const double T = 0.0005, fc = 4, wc = 2 * kPi * fc;
  for (int order : {1, 2}) {
    HighpassFilter<double> f(fc, T, order);
    double worst = 0;
    // The first sample carries the jump itself (the bilinear transform's ramp over half a
    // sample); from the second sample on the output follows the continuous response at t + T/2.
    f.filter(1.0);
    for (int i = 1; i < 2000; ++i) {
      worst = std::max(worst, std::abs(f.filter(1.0) - stepResponse(order, wc, i * T + T / 2)));
    }
    EXPECT_LT(worst, (wc * T) * (wc * T)) << "order " << order;
  }
}

TEST(HighpassFilter, GainIsMinus3dBAtCutoffAndZeroAtDC) {
  for (int order : {1, 2}) {
    HighpassFilter<double> f(20, 0.0005, order);
    EXPECT_NEAR(test::steadyStateAmplitude(f, 20, 0.0005), 1 / std::numbers::sqrt2, 1e-9) << "order " << order;
    HighpassFilter<double> dc(20, 0.0005, order);
    double y = 1;
    for (int i = 0; i < 20000; ++i) y = dc.filter(4.0);
    EXPECT_NEAR(y, 0.0, 1e-10);
  }
}

TEST(HighpassFilter, WorksOnVectorsAndStartsAtRest) {
  HighpassFilter<Vector<2>> f(1, 0.01, 2);
  Vector<2> x;
  x = 1.5, -2;
  f.reset(x);
  const Vector<2>& y = f.filter(x);
  EXPECT_EQ(y(0), 0.0);
  EXPECT_EQ(y(1), 0.0);
  EXPECT_THROW(HighpassFilter<double>(60, 0.01), MathException);
}

}  // namespace
}  // namespace rp
