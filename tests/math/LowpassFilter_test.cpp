// LowpassFilter against the analytic responses of the continuous Butterworth filters.
#include "rp/math/LowpassFilter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "FilterTestSupport.hpp"
#include "rp/math/Matrix.hpp"

namespace rp {
namespace {

constexpr double kPi = std::numbers::pi;

// Continuous unit-step responses.
double firstOrderStep(double wc, double t) { return 1 - std::exp(-wc * t); }
double secondOrderStep(double wc, double t) {
  const double a = wc / std::numbers::sqrt2;  // zeta = 1/sqrt(2): decay rate = damped frequency
  return 1 - std::exp(-a * t) * (std::cos(a * t) + std::sin(a * t));
}

// Largest difference between the discrete step response and the continuous one. The bilinear
// transform treats the input as linear between samples, so the sampled step rises over the half
// sample before t = 0: it is compared with the continuous response at t + T/2. The remaining
// error is of order (wc T)^2.
double stepError(int order, double fc, double T) {
  LowpassFilter<double> f(fc, T, order);
  const double wc = 2 * kPi * fc;
  double worst = 0;
  for (int i = 0; i < static_cast<int>(5.0 / (fc * T)); ++i) {
    const double t = i * T + T / 2;
    const double expected = order == 1 ? firstOrderStep(wc, t) : secondOrderStep(wc, t);
    worst = std::max(worst, std::abs(f.filter(1.0) - expected));
  }
  return worst;
}

TEST(LowpassFilter, StepResponseMatchesContinuousFilter) {
  const double T = 0.001, fc = 5;
  const double wcT = 2 * kPi * fc * T;
  EXPECT_LT(stepError(1, fc, T), wcT * wcT);
  EXPECT_LT(stepError(2, fc, T), wcT * wcT);
  // Second-order convergence: halving the period divides the error by about four.
  EXPECT_LT(stepError(1, fc, T / 2), stepError(1, fc, T) / 3.5);
  EXPECT_LT(stepError(2, fc, T / 2), stepError(2, fc, T) / 3.5);
}

TEST(LowpassFilter, GainIsMinus3dBAtCutoffAndOneAtDC) {
  for (int order : {1, 2}) {
    LowpassFilter<double> f(10, 0.0005, order);
    EXPECT_NEAR(test::steadyStateAmplitude(f, 10, 0.0005), 1 / std::numbers::sqrt2, 1e-9) << "order " << order;
    LowpassFilter<double> dc(10, 0.0005, order);
    double y = 0;
    for (int i = 0; i < 20000; ++i) y = dc.filter(2.5);
    EXPECT_NEAR(y, 2.5, 1e-12);
  }
  // Far above the cutoff the second-order filter falls off at 40 dB per decade.
  LowpassFilter<double> f2(10, 0.0001, 2);
  EXPECT_NEAR(test::steadyStateAmplitude(f2, 100, 0.0001), 1.0 / std::sqrt(1 + std::pow(10.0, 4)), 1e-5);
}

TEST(LowpassFilter, VectorsAndMatricesAreFilteredElementByElement) {
  LowpassFilter<Vector<3>> fv(3, 0.01, 2);
  LowpassFilter<double> f0(3, 0.01, 2), f1(3, 0.01, 2), f2(3, 0.01, 2);
  LowpassFilter<Matrix<2, 2>> fm(3, 0.01, 1);
  LowpassFilter<double> g(3, 0.01, 1);
  for (int i = 0; i < 300; ++i) {
    const double t = i * 0.01;
    Vector<3> x;
    x = std::sin(t), std::cos(3 * t), t;
    const Vector<3>& y = fv.filter(x);
    EXPECT_DOUBLE_EQ(y(0), f0.filter(x(0)));
    EXPECT_DOUBLE_EQ(y(1), f1.filter(x(1)));
    EXPECT_DOUBLE_EQ(y(2), f2.filter(x(2)));
    Matrix<2, 2> m;
    m = t, -t, 2 * t, 0;
    const double gy = g.filter(t);
    EXPECT_DOUBLE_EQ(fm.filter(m)(1, 0), 2 * gy);
  }
}

TEST(LowpassFilter, ResetStartsAtRest) {
  LowpassFilter<double> f(5, 0.001, 2);
  f.reset(3.0);
  EXPECT_DOUBLE_EQ(f.filter(3.0), 3.0);
  f.filter(100.0);
  f.reset();
  EXPECT_NEAR(f.filter(0.0), 0.0, 0.0);
}

TEST(LowpassFilter, RejectsImpossibleSettings) {
  EXPECT_THROW(LowpassFilter<double>(0, 0.001), MathException);
  EXPECT_THROW(LowpassFilter<double>(500, 0.001), MathException) << "at Nyquist";
  EXPECT_THROW(LowpassFilter<double>(10, 0), MathException);
  EXPECT_THROW(LowpassFilter<double>(10, 0.001, 3), MathException);
  LowpassFilter<double> unset;
  EXPECT_THROW(unset.filter(1.0), MathException);
}

}  // namespace
}  // namespace rp
