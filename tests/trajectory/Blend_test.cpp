// The blend planner's building blocks against independent references: the exact peaks of a
// quintic against dense sampling, blends that meet both segments in position, velocity and
// acceleration and keep the limits, and the quintic Hermite joint path against an analytic path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "Blend.hpp"
#include "Segment.hpp"

namespace rp::internal {
namespace {

TEST(Quintic, CoefficientsMeetTheBoundaryConditions) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 1000; ++trial) {
    const double p0 = u(rng), v0 = u(rng), a0 = u(rng), p1 = u(rng), v1 = u(rng), a1 = u(rng);
    const double D = 0.1 + std::abs(u(rng));
    double c[6];
    quinticCoefficients(p0, v0, a0, p1, v1, a1, D, c);
    const double pD = c[0] + D * (c[1] + D * (c[2] + D * (c[3] + D * (c[4] + D * c[5]))));
    const double vD = c[1] + D * (2 * c[2] + D * (3 * c[3] + D * (4 * c[4] + D * 5 * c[5])));
    const double aD = 2 * c[2] + D * (6 * c[3] + D * (12 * c[4] + D * 20 * c[5]));
    EXPECT_EQ(c[0], p0);
    EXPECT_EQ(c[1], v0);
    EXPECT_EQ(2 * c[2], a0);
    EXPECT_NEAR(pD, p1, 1e-11);
    EXPECT_NEAR(vD, v1, 1e-10);
    EXPECT_NEAR(aD, a1, 1e-9);
  }
}

TEST(Quintic, PeaksEqualDenseSampling) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int trial = 0; trial < 1000; ++trial) {
    double c[6];
    for (double& x : c) x = u(rng);
    const double D = 0.2 + 2 * std::abs(u(rng)) / 3;
    const QuinticPeaks peaks = quinticPeaks(c, D);
    double v = 0, a = 0, j = 0;
    const int samples = 50000;
    for (int k = 0; k <= samples; ++k) {
      const double t = D * k / samples;
      v = std::max(v, std::abs(c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])))));
      a = std::max(a, std::abs(2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]))));
      j = std::max(j, std::abs(6 * c[3] + t * (24 * c[4] + t * 60 * c[5])));
    }
    // Sampling finds at most the true peak, and within its spacing of it.
    EXPECT_GE(peaks.velocity, v - 1e-12);
    EXPECT_LE(peaks.velocity, v + 1e-5 * (1 + v));
    EXPECT_GE(peaks.acceleration, a - 1e-12);
    EXPECT_LE(peaks.acceleration, a + 1e-5 * (1 + a));
    EXPECT_GE(peaks.jerk, j - 1e-12);
    EXPECT_LE(peaks.jerk, j + 1e-5 * (1 + j));
  }
}

SegmentPlan line(const JointVector& from, const JointVector& to, const JointVector& v, const JointVector& a,
                 const JointVector& j, double radius) {
  SegmentPlan p;
  p.kind = SegmentKind::Line;
  p.line = SynchronizedJointMotion(from, to, v, a, j, Synchronization::Phase);
  p.duration = p.line.getDuration();
  p.end = to;
  const double d = (to - from).norm();
  p.exitTime = p.timeAtFraction(std::max(0.5, 1 - radius / d));
  p.entryTime = p.timeAtFraction(std::min(0.5, radius / d));
  return p;
}

TEST(Blend, MeetsBothMotionsKeepsTheLimitsAndSavesTime) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.2, 3);
  int planned = 0, overlaps = 0, longer = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 7);
    JointVector a(n), b(n), c(n), vmax(n), amax(n), jmax(n);
    for (int i = 0; i < n; ++i) {
      a(i) = u(rng);
      b(i) = u(rng);
      c(i) = u(rng);
      vmax(i) = pos(rng);
      amax(i) = 2 * pos(rng);
      jmax(i) = 10 * pos(rng);
    }
    const double radius = 0.05 + 0.5 * std::abs(u(rng));
    SegmentPlan first = line(a, b, vmax, amax, jmax, radius), second = line(b, c, vmax, amax, jmax, radius);
    SegmentPlan blend;
    double entry = 0;
    if (!planBlend(first, second, vmax, amax, jmax, blend, entry)) continue;
    ++planned;
    if (blend.from != nullptr) ++overlaps;
    // From where the blend leaves the first motion to where it joins the second, stopping at the
    // via point would take (rest of the first) + (entry time): an overlap saves time, a quintic
    // takes at most three times as long.
    const double stopping = (first.duration - blend.fromStart) + entry;
    if (blend.from != nullptr) {
      EXPECT_LE(blend.duration, stopping + 1e-12);
    } else {
      EXPECT_LE(blend.duration, 3 * stopping + 1e-12);
      if (blend.duration > stopping) ++longer;
    }
    // Within the radius: it begins after the first motion's exit point and ends before the
    // second's entry point.
    EXPECT_GE(blend.fromStart, first.exitTime - 1e-12);
    EXPECT_LE(entry, second.entryTime + 1e-12);
    Setpoint x, y;
    x.position = x.velocity = x.acceleration = JointVector(n);
    y = x;
    first.evaluate(blend.fromStart, x);
    blend.evaluate(0, y);
    EXPECT_LT((x.position - y.position).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((x.velocity - y.velocity).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((x.acceleration - y.acceleration).cwiseAbs().maxCoeff(), 1e-12);
    second.evaluate(entry, x);
    blend.evaluate(blend.duration, y);
    EXPECT_LT((x.position - y.position).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((x.velocity - y.velocity).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((x.acceleration - y.acceleration).cwiseAbs().maxCoeff(), 1e-12);
    // Limits at dense samples (an independent check of the exact piecewise analysis); jerk from
    // differences of the acceleration.
    const int samples = 4000;
    const double dt = blend.duration / samples;
    Setpoint prev = y;
    blend.evaluate(0, prev);
    for (int k = 1; k <= samples; ++k) {
      blend.evaluate(k * dt, y);
      for (int i = 0; i < n; ++i) {
        ASSERT_LE(std::abs(y.velocity(i)), vmax(i) * (1 + 1e-9)) << trial;
        ASSERT_LE(std::abs(y.acceleration(i)), amax(i) * (1 + 1e-9)) << trial;
        ASSERT_LE(std::abs(y.acceleration(i) - prev.acceleration(i)), jmax(i) * dt * (1 + 1e-9) + 1e-12) << trial;
      }
      prev = y;
    }
  }
  EXPECT_GT(planned, 2900);
  EXPECT_GT(overlaps, 1500);
  RecordProperty("planned", planned);
  RecordProperty("overlaps", overlaps);
  std::printf("%d of 3000 blends planned, %d of them overlaps, %d quintics longer than stopping\n", planned, overlaps,
              longer);
}

TEST(JointPath, QuinticHermiteFollowsAnAnalyticPath) {
  // q(s) = (sin 3s, s^3, e^s), sampled with exact derivatives: the interpolant matches to the
  // sixth order in the spacing.
  for (int intervals : {10, 20}) {
    JointPath path;
    path.joints = 3;
    path.intervals = intervals;
    for (int k = 0; k <= intervals; ++k) {
      const double s = static_cast<double>(k) / intervals;
      for (double x : {std::sin(3 * s), s * s * s, std::exp(s)}) path.q.push_back(x);
      for (double x : {3 * std::cos(3 * s), 3 * s * s, std::exp(s)}) path.dq.push_back(x);
      for (double x : {-9 * std::sin(3 * s), 6 * s, std::exp(s)}) path.ddq.push_back(x);
    }
    JointVector q0(3), q1(3), q2(3);
    double worst = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double s = k / 1000.0;
      path.evaluate(s, q0, q1, q2);
      worst = std::max({worst, std::abs(q0(0) - std::sin(3 * s)), std::abs(q0(1) - s * s * s), std::abs(q0(2) - std::exp(s))});
      EXPECT_NEAR(q1(0), 3 * std::cos(3 * s), 1e-3);
      EXPECT_NEAR(q2(2), std::exp(s), 1e-2);
    }
    EXPECT_LT(worst, intervals == 10 ? 1e-7 : 2e-9) << intervals;
  }
}

}  // namespace
}  // namespace rp::internal
