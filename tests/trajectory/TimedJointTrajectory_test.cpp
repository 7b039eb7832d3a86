// TimedJointTrajectory against independent references: cubic and quintic polynomials that the
// Hermite pieces must reproduce exactly from their own positions, velocities and accelerations,
// finite differences of the position against the velocity (and of the velocity against the
// acceleration), the monotone estimate for positions only; TimedTrajectoryGenerator's hand-over
// (continuity at a replacement, a delayed start, freeing) and its servo side without allocation.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "AllocationCounter.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

JointVector vec(std::initializer_list<double> values) {
  JointVector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v(i++) = x;
  return v;
}

TimedJointPoint point(double t, const JointVector& q, const JointVector& v = JointVector(), const JointVector& a = JointVector()) {
  TimedJointPoint p;
  p.time = t;
  p.position = q;
  p.velocity = v;
  p.acceleration = a;
  return p;
}

Setpoint state(const JointVector& q, const JointVector& v, const JointVector& a) {
  Setpoint s;
  s.position = q;
  s.velocity = v;
  s.acceleration = a;
  return s;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The message of the std::invalid_argument `f` throws ("" if it throws none).
std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// A reference motion per joint: p(t) and its first two derivatives.
struct Reference {
  std::function<double(int, double)> p, v, a;
};

// Cubics at rest at time T (p'(T) = 0): p_i(t) = c_i + k_i (t - T)^2 (t - s_i).
Reference cubicReference(double T) {
  const double c[2] = {0.3, -0.2}, k[2] = {0.8, -0.5}, s[2] = {-1.0, 3.0};
  Reference r;
  r.p = [=](int i, double t) { return c[i] + k[i] * (t - T) * (t - T) * (t - s[i]); };
  r.v = [=](int i, double t) { return k[i] * (2 * (t - T) * (t - s[i]) + (t - T) * (t - T)); };
  r.a = [=](int i, double t) { return k[i] * (2 * (t - s[i]) + 4 * (t - T)); };
  return r;
}

// Quintics at rest at time T (p'(T) = p''(T) = 0): p_i(t) = c_i + k_i (t - T)^3 (t - s_i)(t - r_i).
Reference quinticReference(double T) {
  const double c[2] = {0.1, 0.4}, k[2] = {0.3, -0.2}, s[2] = {-1.0, 2.5}, r[2] = {3.0, -0.5};
  Reference ref;
  ref.p = [=](int i, double t) { return c[i] + k[i] * std::pow(t - T, 3) * (t - s[i]) * (t - r[i]); };
  ref.v = [=](int i, double t) {
    const double u = t - T, f = (t - s[i]) * (t - r[i]), fd = 2 * t - s[i] - r[i];
    return k[i] * (3 * u * u * f + u * u * u * fd);
  };
  ref.a = [=](int i, double t) {
    const double u = t - T, f = (t - s[i]) * (t - r[i]), fd = 2 * t - s[i] - r[i];
    return k[i] * (6 * u * f + 6 * u * u * fd + 2 * u * u * u);
  };
  return ref;
}

// The trajectory equals the reference (both joints) every millisecond from 0 to its end.
void expectReproduces(const TimedJointTrajectory& traj, const Reference& r) {
  Setpoint s;
  for (double t = 0; t <= traj.getDuration(); t += 0.001) {
    traj.evaluate(t, s);
    for (int i = 0; i < 2; ++i) {
      ASSERT_NEAR(s.position(i), r.p(i, t), 1e-12) << t;
      ASSERT_NEAR(s.velocity(i), r.v(i, t), 1e-11) << t;
      ASSERT_NEAR(s.acceleration(i), r.a(i, t), 1e-10) << t;
    }
  }
}

TEST(TimedJointTrajectory, CubicHermiteReproducesACubicFromItsPointsAndVelocities) {
  const double T = 2.0;
  const Reference r = cubicReference(T);
  const double times[] = {0.3, 0.7, 1.2, T};
  std::vector<TimedJointPoint> points;
  for (double t : times) points.push_back(point(t, vec({r.p(0, t), r.p(1, t)}), vec({r.v(0, t), r.v(1, t)})));
  TimedJointTrajectory traj(points);
  EXPECT_EQ(traj.getInterpolation(), TimedJointTrajectory::Interpolation::CubicHermite);
  EXPECT_EQ(traj.getDuration(), T);
  // Started from the reference's own state at 0, the first piece is the reference too.
  traj.start(state(vec({r.p(0, 0), r.p(1, 0)}), vec({r.v(0, 0), r.v(1, 0)}), vec({0, 0})));
  expectReproduces(traj, r);
  Setpoint s;
  traj.evaluate(T + 1, s);  // after the end: the last point, at rest
  EXPECT_NEAR(s.position(0), r.p(0, T), 1e-15);
  EXPECT_EQ(s.velocity.norm(), 0);
}

TEST(TimedJointTrajectory, QuinticHermiteReproducesAQuinticFromItsPointsVelocitiesAndAccelerations) {
  const double T = 1.5;
  const Reference r = quinticReference(T);
  std::vector<TimedJointPoint> points;
  for (double t : {0.25, 0.5, 1.0, T})
    points.push_back(point(t, vec({r.p(0, t), r.p(1, t)}), vec({r.v(0, t), r.v(1, t)}), vec({r.a(0, t), r.a(1, t)})));
  TimedJointTrajectory traj(points);
  EXPECT_EQ(traj.getInterpolation(), TimedJointTrajectory::Interpolation::QuinticHermite);
  traj.start(state(vec({r.p(0, 0), r.p(1, 0)}), vec({r.v(0, 0), r.v(1, 0)}), vec({r.a(0, 0), r.a(1, 0)})));
  expectReproduces(traj, r);
}

// Finite differences: the velocity is the derivative of the position, the acceleration of the
// velocity, on every piece, and position and velocity are continuous at the points.
void expectConsistentDerivatives(const TimedJointTrajectory& traj, bool accelerationContinuous) {
  const double h = 1e-6;
  Setpoint a, b, c;
  for (double t = h; t < traj.getDuration() - h; t += 0.0037) {
    traj.evaluate(t - h, a);
    traj.evaluate(t, b);
    traj.evaluate(t + h, c);
    for (int i = 0; i < traj.getNumberOfJoints(); ++i) {
      EXPECT_NEAR((c.position(i) - a.position(i)) / (2 * h), b.velocity(i), 1e-5) << "t " << t << " joint " << i;
      EXPECT_NEAR((c.velocity(i) - a.velocity(i)) / (2 * h), b.acceleration(i), 2e-3) << "t " << t << " joint " << i;
    }
  }
  for (const TimedJointPoint& p : traj.getPoints()) {
    traj.evaluate(p.time - 1e-9, a);
    traj.evaluate(p.time + 1e-9, c);
    for (int i = 0; i < traj.getNumberOfJoints(); ++i) {
      EXPECT_NEAR(a.position(i), p.position(i), 1e-7) << "at " << p.time;
      EXPECT_NEAR(c.position(i), p.position(i), 1e-7) << "at " << p.time;
      EXPECT_NEAR(a.velocity(i), c.velocity(i), 1e-6) << "velocity jumps at " << p.time;
      if (accelerationContinuous) {
        EXPECT_NEAR(a.acceleration(i), c.acceleration(i), 1e-4) << "at " << p.time;
      }
    }
  }
}

TEST(TimedJointTrajectory, PositionsOnlyGoThroughThePointsWithoutOvershootAndStopAtTheLast) {
  // Joint 0 rises throughout (it must never go back); joint 1 turns at 0.4 s and 0.9 s.
  std::vector<TimedJointPoint> points = {point(0.4, vec({0.1, 0.5})), point(0.9, vec({0.5, 0.2})),
                                         point(1.3, vec({0.6, 0.4})), point(2.0, vec({0.9, 0.4}))};
  TimedJointTrajectory traj(points);
  EXPECT_EQ(traj.getInterpolation(), TimedJointTrajectory::Interpolation::Cubic);
  traj.start(state(vec({0, 0}), vec({0, 0}), vec({0, 0})));
  expectConsistentDerivatives(traj, false);
  Setpoint s;
  double previous = -1;
  for (double t = 0; t <= 2.0; t += 0.001) {
    traj.evaluate(t, s);
    EXPECT_GE(s.position(0), previous - 1e-12) << "joint 0 goes back at " << t;
    previous = s.position(0);
    // Joint 1 stays between the points on either side of each piece.
    double lo = 0, hi = 0.5;
    if (t > 0.4 && t <= 0.9) lo = 0.2, hi = 0.5;
    if (t > 0.9) lo = 0.2, hi = 0.4;
    EXPECT_GE(s.position(1), lo - 1e-12) << t;
    EXPECT_LE(s.position(1), hi + 1e-12) << t;
  }
  traj.evaluate(0.9, s);  // a turning point: at rest there
  EXPECT_NEAR(s.velocity(1), 0, 1e-12);
  traj.evaluate(2.0, s);
  EXPECT_NEAR(s.position(0), 0.9, 1e-12);
  EXPECT_EQ(s.velocity.norm(), 0);
}

TEST(TimedJointTrajectory, TheFirstPieceContinuesTheMotionItStartsFrom) {
  const JointVector q0 = vec({0.2, -0.1}), v0 = vec({0.8, -0.3}), a0 = vec({2.0, 1.0});
  const std::vector<TimedJointPoint> cubic = {point(0.5, vec({0.5, -0.2})), point(1.0, vec({0.6, 0.0}))};
  const std::vector<TimedJointPoint> quintic = {point(0.5, vec({0.5, -0.2}), vec({0.1, 0.1}), vec({0, 0})),
                                                point(1.0, vec({0.6, 0.0}), vec({0, 0}), vec({0, 0}))};
  for (const auto& points : {cubic, quintic}) {
    TimedJointTrajectory traj(points);
    traj.start(state(q0, v0, a0));
    Setpoint s;
    traj.evaluate(0, s);
    EXPECT_NEAR((s.position - q0).norm(), 0, 1e-15);
    EXPECT_NEAR((s.velocity - v0).norm(), 0, 1e-14);
    if (traj.getInterpolation() == TimedJointTrajectory::Interpolation::QuinticHermite) {
      EXPECT_NEAR((s.acceleration - a0).norm(), 0, 1e-13);
    }
    expectConsistentDerivatives(traj, traj.getInterpolation() == TimedJointTrajectory::Interpolation::QuinticHermite);
  }
}

TEST(TimedJointTrajectory, BadPointsAreRefusedNamingThePointAndField) {
  const JointVector q = vec({0, 0});
  EXPECT_TRUE(contains(refusal([] { TimedJointTrajectory t({}); }), "at least one point"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q), point(1, q)}); }), "point 1 time"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(2, q), point(1, q)}); }), "point 1 time"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(-1, q)}); }), "point 0 time"));
  // The times as the user gave them, however small (std::to_string said "0.000000 s, not after
  // the point before (0.000000 s)" for 1 us and 2 us).
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(2e-6, q), point(1e-6, q)}); }),
                       "point 1 time: 1e-06 s, not after the point before (2e-06 s)"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q), point(2, vec({0, NAN}))}); }), "point 1 positions"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q), point(2, vec({0}))}); }), "point 1 positions"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q, q), point(2, q)}); }), "point 1 velocities"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q, q), point(2, q, vec({1, 0}))}); }), "point 1 velocities"));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t({point(1, q, JointVector(), q)}); }), "without velocities"));
  std::vector<TimedJointPoint> many;
  for (int k = 0; k <= TimedJointTrajectory::kMaxPoints; ++k) many.push_back(point(k + 1, q));
  EXPECT_TRUE(contains(refusal([&] { TimedJointTrajectory t(many); }), "10001 points"));
  many.pop_back();
  EXPECT_EQ(refusal([&] { TimedJointTrajectory t(many); }), "");
}

// The first limit violation of `points` started at rest at 0, against [-1, 1] rad and 2 rad/s.
TrajectoryLimitViolation violation(const std::vector<TimedJointPoint>& points) {
  TimedJointTrajectory traj(points);
  traj.start(state(vec({0, 0}), vec({0, 0}), vec({0, 0})));
  return traj.findLimitViolation(vec({-1, -1}), vec({1, 1}), vec({2, 2}));
}

TEST(TimedJointTrajectory, LimitViolationsAreFoundWithTheirPointAndJoint) {
  EXPECT_FALSE(violation({point(1.0, vec({0.5, -0.5})), point(2.0, vec({0.9, 0.0}))}).found) << "within the limits";
  // Too fast between points 0 and 1 on joint 1: 1.8 rad in 0.5 s.
  const TrajectoryLimitViolation v = violation({point(1.0, vec({0.0, -0.9})), point(1.5, vec({0.0, 0.9}))});
  ASSERT_TRUE(v.found);
  EXPECT_TRUE(v.velocity);
  EXPECT_EQ(v.point, 1);
  EXPECT_EQ(v.joint, 1);
  EXPECT_GT(std::abs(v.value), 2);
  // Points within the limits, but the velocities given carry joint 0 past 1 between them.
  const TrajectoryLimitViolation w =
      violation({point(1.0, vec({0.9, 0}), vec({1.5, 0})), point(2.0, vec({0.9, 0}), vec({0, 0}))});
  ASSERT_TRUE(w.found);
  EXPECT_FALSE(w.velocity);
  EXPECT_EQ(w.point, 1);
  EXPECT_EQ(w.joint, 0);
  EXPECT_GT(w.value, 1);
}

// The generator called as a servo loop calls it, without a manipulator: every cycle from this thread.
class TimedGeneratorTest : public ::testing::Test {
 protected:
  void SetUp() override { RoboticPlatform::setSimulationModeOn(); }
  // One servo cycle at `time` with the hold `hold`; counts the allocations it makes.
  bool cycle(double time, const JointVector& hold) {
    sp_.position = hold;
    sp_.velocity = JointVector::Zero(hold.size());
    sp_.acceleration = JointVector::Zero(hold.size());
    test::AllocationGuard guard;
    const bool given = gen_.getCurrentSetpoint(time, sp_);
    allocations_ += guard.count();
    return given;
  }
  TimedTrajectoryGenerator gen_;
  Setpoint sp_;
  std::size_t allocations_ = 0;
};

TEST_F(TimedGeneratorTest, AReplacementContinuesTheMotionAndTheServoSideNeverAllocates) {
  const JointVector hold = vec({0.1, 0.2});
  EXPECT_FALSE(cycle(100.0, hold)) << "nothing to execute: hold";
  EXPECT_TRUE(gen_.isDone());
  // A: to (1, -0.5) in 2 s, positions only.
  gen_.execute(std::make_unique<TimedJointTrajectory>(std::vector<TimedJointPoint>{point(1.0, vec({0.5, 0})), point(2.0, vec({1.0, -0.5}))}));
  EXPECT_FALSE(gen_.isDone());
  const double dt = 0.001, t0 = 100.001;
  // The same trajectory as A, started as the generator starts it (from the hold), for reference.
  TimedJointTrajectory a({point(1.0, vec({0.5, 0})), point(2.0, vec({1.0, -0.5}))});
  a.start(state(hold, vec({0, 0}), vec({0, 0})));
  int k = 0;
  for (; k < 800; ++k) {  // 0.8 s of A
    ASSERT_TRUE(cycle(t0 + k * dt, hold));
    Setpoint r;
    a.evaluate(k * dt, r);
    ASSERT_NEAR((sp_.position - r.position).norm(), 0, 1e-12) << k;
  }
  EXPECT_EQ(gen_.getStartedCount(), 1u);
  // B replaces A in mid-motion (A moves at about 0.5 rad/s there): it starts from A's state.
  gen_.execute(std::make_unique<TimedJointTrajectory>(std::vector<TimedJointPoint>{point(0.5, vec({0.4, 0.3}), vec({-0.2, 0}), vec({0, 0})), point(1.5, vec({0.0, 0.0}), vec({0, 0}), vec({0, 0}))}));
  const double ts = t0 + k * dt;
  Setpoint atSwitch;
  a.evaluate(ts - t0, atSwitch);
  ASSERT_TRUE(cycle(ts, hold));
  EXPECT_EQ(gen_.getStartedCount(), 2u);
  EXPECT_NEAR((sp_.position - atSwitch.position).norm(), 0, 1e-12) << "position continuous at the switch";
  EXPECT_NEAR((sp_.velocity - atSwitch.velocity).norm(), 0, 1e-12) << "velocity continuous at the switch";
  EXPECT_NEAR((sp_.acceleration - atSwitch.acceleration).norm(), 0, 1e-9) << "acceleration too (quintic)";
  EXPECT_GT(atSwitch.velocity.norm(), 0.1) << "the switch is in mid-motion";
  for (++k; k < 800 + 1600; ++k) ASSERT_TRUE(cycle(t0 + k * dt, hold));
  EXPECT_TRUE(gen_.isDone());
  EXPECT_NEAR(sp_.position.norm(), 0, 1e-12) << "B's last point";
  EXPECT_EQ(sp_.velocity.norm(), 0);
  JointVector q, v;
  ASSERT_TRUE(gen_.getLastSetpoint(q, v));
  EXPECT_NEAR(q.norm(), 0, 1e-12);
  // A is freed by the next hand-over, in this thread (not the servo's): C is delayed by 0.5 s.
  gen_.execute(std::make_unique<TimedJointTrajectory>(std::vector<TimedJointPoint>{point(0.5, vec({0.1, 0.1}))}), 0.5);
  EXPECT_EQ(gen_.getHeldCount(), 2u) << "B (in use) and C";
  const double tc = t0 + k * dt;
  for (int j = 0; j < 499; ++j) {  // B's end held while C waits
    ASSERT_TRUE(cycle(tc + j * dt, hold));
    ASSERT_NEAR(sp_.position.norm(), 0, 1e-12) << j;
  }
  for (int j = 499; j < 1200; ++j) ASSERT_TRUE(cycle(tc + j * dt, hold));
  EXPECT_EQ(gen_.getStartedCount(), 3u);
  EXPECT_NEAR(sp_.position(0), 0.1, 1e-12);
  EXPECT_EQ(allocations_, 0u) << "getCurrentSetpoint() allocated";
}

TEST_F(TimedGeneratorTest, OnlyTheNewestOfTrajectoriesHandedOverBetweenTwoCyclesRuns) {
  const JointVector hold = vec({0.0});
  for (double target : {0.1, 0.2, 0.3})
    gen_.execute(std::make_unique<TimedJointTrajectory>(std::vector<TimedJointPoint>{point(0.1, vec({target}))}));
  for (int k = 0; k < 200; ++k) cycle(10 + k * 0.001, hold);
  EXPECT_EQ(gen_.getStartedCount(), 1u);
  EXPECT_NEAR(sp_.position(0), 0.3, 1e-12);
  EXPECT_TRUE(gen_.isDone());
  gen_.execute(std::make_unique<TimedJointTrajectory>(std::vector<TimedJointPoint>{point(0.1, vec({0.0}))}));
  EXPECT_LE(gen_.getHeldCount(), 2u) << "the two dropped ones are freed";
  EXPECT_EQ(allocations_, 0u);
}

}  // namespace
}  // namespace rp
