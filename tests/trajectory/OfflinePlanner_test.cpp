// OfflinePlanner: the default generator's motions planned and sampled for a model alone, checked
// against the closed-form jerk-limited profile, the straight line in Cartesian space, and a
// simulated arm following the same motions.
#include <gtest/gtest.h>

#include <cmath>

#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

TEST(OfflinePlanner, AJointMoveIsTheTimeOptimalSCurve) {
  Puma560Model puma;
  OfflinePlanner planner(puma, puma.getHomePosition());
  JointVector target = puma.getHomePosition();
  target(0) += 1.5;
  planner.generator().moveRadians(target);
  const OfflinePlanner::Samples s = planner.sample(1000);
  // Joint 1 alone: T = d / v + v / a + a / j when the cruise speed is reached (closed form), with
  // the generator's limits: the model's times its speed fraction (0.8 by default).
  const double f = planner.generator().getSpeedFraction();
  const double v = f * puma.getVelocityLimit()(0), a = f * puma.getAccelerationLimit()(0), j = f * puma.getJerkLimit()(0);
  ASSERT_GT(1.5 / v, v / a + a / j);
  const double T = 1.5 / v + v / a + a / j;
  EXPECT_GE(s.duration, T - 1e-9);
  EXPECT_LE(s.duration, T + 1e-3 + 1e-9) << "the first sample after the end";
  EXPECT_NEAR(s.q(0, 0), puma.getHomePosition()(0), 1e-12);
  EXPECT_NEAR(s.q(s.q.rows() - 1, 0), target(0), 1e-12);
  EXPECT_EQ(s.qd(s.q.rows() - 1, 0), 0.0);
  for (Eigen::Index k = 0; k < s.q.rows(); ++k) {
    EXPECT_LE(std::abs(s.qd(k, 0)), v * (1 + 1e-9));
    EXPECT_LE(std::abs(s.qdd(k, 0)), a * (1 + 1e-9));
  }
  // Velocity: the central difference of the positions.
  for (Eigen::Index k = 1; k + 1 < s.q.rows(); ++k)
    EXPECT_NEAR((s.q(k + 1, 0) - s.q(k - 1, 0)) / 2e-3, s.qd(k, 0), 2e-3) << "sample " << k;
}

TEST(OfflinePlanner, ACartesianMoveKeepsTheEndEffectorOnTheLine) {
  Puma560Model puma;
  // From a pose away from the ready pose's singularity, 0.15 m along a line, same orientation.
  JointVector start(6);
  start << 0.2, -0.3, 0.8, 0.3, -0.7, 0.1;  // the end-effector at (0.25, -0.10, 0.93) m
  ManipulatorData data(puma);
  const Transform a = forwardKinematics(puma, data, start);
  Transform b = a;
  b.topRightCorner<3, 1>() += Eigen::Vector3d(0.1, -0.1, -0.05);
  OfflinePlanner planner(puma, start);
  planner.generator().moveTo(b);
  const OfflinePlanner::Samples s = planner.sample(500);
  ASSERT_GT(s.q.rows(), 10);
  const Eigen::Vector3d pa = a.topRightCorner<3, 1>(), pb = b.topRightCorner<3, 1>();
  for (Eigen::Index k = 0; k < s.q.rows(); ++k) {
    const Eigen::Vector3d p = forwardKinematics(puma, data, JointVector(s.q.row(k).transpose())).topRightCorner<3, 1>();
    const Eigen::Vector3d along = (pb - pa).normalized();
    const double off = ((p - pa) - (p - pa).dot(along) * along).norm();
    EXPECT_LT(off, 1e-6) << "sample " << k << " is " << off << " m off the line";
  }
  const Transform end = forwardKinematics(puma, data, JointVector(s.q.row(s.q.rows() - 1).transpose()));
  EXPECT_LT((end - b).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(OfflinePlanner, BlendingAtAViaPointShortensThePlanAndDwellsAndCapacityAreKept) {
  Puma560Model puma;
  const JointVector home = puma.getHomePosition();
  JointVector via = home, target = home;
  via(0) += 0.5;
  target(0) += 0.5;
  target(1) -= 0.5;
  auto plan = [&](double radius) {
    OfflinePlanner planner(puma, home);
    planner.generator().setJointBlendRadius(radius);
    planner.generator().moveRadians(via);
    planner.generator().moveRadians(target);
    return planner.sample(1000);
  };
  const OfflinePlanner::Samples stop = plan(0), blend = plan(0.1);
  EXPECT_LT(blend.duration, stop.duration - 0.05) << "a blend does not stop at the via point";
  EXPECT_NEAR(blend.q(blend.q.rows() - 1, 1), target(1), 1e-12);

  // A dwell adds its time to motions that stop at the via point (radius 0: blending is on by
  // default).
  OfflinePlanner planner(puma, home);
  planner.generator().setJointBlendRadius(0);
  planner.generator().moveRadians(via);
  planner.dwell(0.5);
  planner.generator().moveRadians(home);
  const OfflinePlanner::Samples dwell = planner.sample(1000);
  const OfflinePlanner::Samples noDwell = [&] {
    OfflinePlanner p(puma, home);
    p.generator().setJointBlendRadius(0);
    p.generator().moveRadians(via);
    p.generator().moveRadians(home);
    return p.sample(1000);
  }();
  EXPECT_NEAR(dwell.duration - noDwell.duration, 0.5, 2e-3);

  OfflinePlanner full(puma, home);
  EXPECT_THROW(
      {
        for (int i = 0; i < QueueTrajectoryGenerator::kCapacity; ++i) full.generator().moveRadians(i % 2 ? home : via);
      },
      std::length_error);
  EXPECT_THROW(OfflinePlanner(puma, JointVector::Zero(5)), std::invalid_argument);
  EXPECT_TRUE(OfflinePlanner(puma, home).sample(100).time.empty()) << "nothing queued, nothing sampled";
}

}  // namespace
}  // namespace rp
