// Differentiator: the backward difference of sin approaches cos within its error bound.
#include "rp/math/Differentiator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rp/math/Matrix.hpp"

namespace rp {
namespace {

TEST(Differentiator, DifferentiatingSinGivesCosWithinTheBackwardDifferenceBound) {
  for (double T : {0.01, 0.001}) {
    Differentiator<double> d(T);
    EXPECT_EQ(d.differentiate(std::sin(0.0)), 0.0) << "no earlier sample: zero";
    double worst = 0;
    for (int i = 1; i < static_cast<int>(10 / T); ++i) {
      const double t = i * T;
      worst = std::max(worst, std::abs(d.differentiate(std::sin(t)) - std::cos(t)));
    }
    // |(sin t - sin(t-T))/T - cos t| <= T/2 max|sin''| = T/2.
    EXPECT_LE(worst, T / 2);
    EXPECT_GT(worst, T / 4) << "the bound is tight: the error is first order";
  }
}

TEST(Differentiator, VectorsAndFilteredOutput) {
  const double T = 0.001;
  Differentiator<Vector<2>> d(T);
  Differentiator<double> filtered(T, 20.0, 2), raw(T);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0, 1e-4);
  double rawVar = 0, filtVar = 0;
  int n = 0;
  for (int i = 0; i < 5000; ++i) {
    const double t = i * T;
    Vector<2> x;
    x = 3 * t, -t;
    const Vector<2>& v = d.differentiate(x);
    if (i > 0) {
      EXPECT_NEAR(v(0), 3.0, 1e-9);
      EXPECT_NEAR(v(1), -1.0, 1e-9);
    }
    const double sample = 2 * t + noise(rng);
    const double r = raw.differentiate(sample), f = filtered.differentiate(sample);
    if (i > 1000) {
      rawVar += (r - 2) * (r - 2);
      filtVar += (f - 2) * (f - 2);
      ++n;
    }
  }
  EXPECT_LT(filtVar, rawVar / 10) << "the low-pass filter removes most of the noise";
  EXPECT_NEAR(std::sqrt(filtVar / n), 0.0, 0.05) << "and keeps the slope";
  EXPECT_THROW(Differentiator<double>(0.0), MathException);
}

TEST(Differentiator, ResetForgetsTheLastSample) {
  Differentiator<double> d(0.1);
  d.differentiate(5.0);
  d.reset();
  EXPECT_EQ(d.differentiate(100.0), 0.0);
  EXPECT_DOUBLE_EQ(d.differentiate(101.0), 10.0);
}

}  // namespace
}  // namespace rp
