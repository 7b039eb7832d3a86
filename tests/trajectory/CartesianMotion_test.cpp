// Straight-line Cartesian motion and blending through the queue, evaluated at 1 kHz on a paused
// simulated clock (the test calls getCurrentSetpoint() itself), and executed by simulated arms.
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <thread>
#include <vector>

#include "../manipulator/SimulatedArmTest.hpp"
#include "AllocationCounter.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

constexpr double kDeg = std::numbers::pi / 180;
// A Puma pose in the middle of the work space, gripper pointing down (as in Figure 21).
const Transform kWorkPose = translation(0.5, 0.2, 0.3) * xRotation(std::numbers::pi);

class CartesianMotionTest : public test::SimulatedArmTest {
 protected:
  SimulatedClock& clock() { return test::simClock(); }
  // Runs the arm's loop for one cycle, after which the cycle itself pauses the clock
  // (runCycles()); the test then drives time. (Pausing the clock from the test thread once a cycle
  // had run raced with the next tick, already given: that cycle could run during the test's own
  // evaluation of the generator.)
  void takeOver(DefaultManipulator& m) { ASSERT_TRUE(m.runCycles(1)); }
};

// Three Puma joint targets [deg] around a gentle corner: every joint keeps its direction.
std::array<Vector<6>, 3> gentleCorner() {
  std::array<Vector<6>, 3> p;
  p[0] = 0, 30, -120, 0, 30, 0;
  p[1] = 40, 50, -100, 30, 60, 20;
  p[2] = 70, 55, -70, 40, 80, 60;
  return p;
}

struct Sampled {
  std::vector<Setpoint> setpoints;
};

// Evaluates the generator at 1 kHz from `t0` until done; checks the limits and continuity.
Sampled run(QueueTrajectoryGenerator& tragen, const ManipulatorModel& model, int n, double t0, double fraction = 0.8) {
  Sampled out;
  Setpoint sp, prev;
  sp.position = sp.velocity = sp.acceleration = JointVector(n);
  prev = sp;
  EXPECT_TRUE(tragen.getCurrentSetpoint(t0, prev));
  out.setpoints.push_back(prev);
  const double dt = 1e-3;
  for (double t = t0 + dt; !tragen.isDone() && t < t0 + 100; t += dt) {
    EXPECT_TRUE(tragen.getCurrentSetpoint(t, sp));
    for (int i = 0; i < n; ++i) {
      EXPECT_LE(std::abs(sp.velocity(i)), fraction * model.getVelocityLimit()(i) * (1 + 1e-9)) << "joint " << i;
      EXPECT_LE(std::abs(sp.acceleration(i)), fraction * model.getAccelerationLimit()(i) * (1 + 1e-9)) << "joint " << i;
      EXPECT_LE(std::abs(sp.acceleration(i) - prev.acceleration(i)), fraction * model.getJerkLimit()(i) * dt * 1.0001 + 1e-12)
          << "joint " << i;
      EXPECT_LE(std::abs(sp.position(i) - prev.position(i)), fraction * model.getVelocityLimit()(i) * dt * 1.0001 + 1e-12);
    }
    out.setpoints.push_back(sp);
    prev = sp;
  }
  EXPECT_TRUE(tragen.isDone());
  return out;
}

// Largest distance of the end-effector from the segment p0-p1, and of its rotation axis (relative
// to the start) from the shortest-arc axis.
void checkStraight(const ManipulatorModel& model, const Sampled& s, const Transform& start, const Transform& goal) {
  ManipulatorData data(model);
  const Eigen::Vector3d p0 = start.block<3, 1>(0, 3), p1 = goal.block<3, 1>(0, 3);
  const Eigen::Matrix3d R0 = start.block<3, 3>(0, 0), R1 = goal.block<3, 3>(0, 0);
  const Eigen::AngleAxisd total(Eigen::Matrix3d(R0.transpose() * R1));
  double worstLine = 0, worstAxis = 0;
  for (const Setpoint& sp : s.setpoints) {
    const Transform& T = forwardKinematics(model, data, sp.position);
    const Eigen::Vector3d p = T.block<3, 1>(0, 3);
    const Eigen::Vector3d d = (p1 - p0).normalized();
    const double along = std::clamp((p - p0).dot(d), 0.0, (p1 - p0).norm());
    worstLine = std::max(worstLine, (p - (p0 + along * d)).norm());
    const Eigen::AngleAxisd part(Eigen::Matrix3d(R0.transpose() * T.block<3, 3>(0, 0)));
    if (std::abs(part.angle()) > 1e-3) worstAxis = std::max(worstAxis, part.axis().cross(total.axis()).norm());
  }
  EXPECT_LT(worstLine, 1e-6) << "metres off the straight line";
  EXPECT_LT(worstAxis, 1e-6) << "rotation axis off the shortest arc";
  const Transform& end = forwardKinematics(model, data, s.setpoints.back().position);
  EXPECT_LT((end - goal).cwiseAbs().maxCoeff(), 1e-9);
}

TEST_F(CartesianMotionTest, PumaFollowsAStraightLineWithTheShortestArcRotation) {
  Puma560 puma;
  takeOver(puma);
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  const ManipulatorModel& model = puma.getModel();
  tragen.moveTo(kWorkPose);  // from the singular ready pose: through joint space
  run(tragen, model, 6, 100);
  ManipulatorData data(model);
  const Transform start = forwardKinematics(model, data, tragen.getLastTarget());
  const Transform goal = translation(0.15, -0.2, -0.1) * start * zRotation(0.6) * xRotation(0.3);
  tragen.moveTo(goal);
  const Sampled s = run(tragen, model, 6, 200);
  EXPECT_GT(s.setpoints.size(), 100u);
  checkStraight(model, s, start, goal);
  // The arm kept its configuration (IK branch) at every setpoint along the way.
  const auto& pumaModel = dynamic_cast<const Puma560Model&>(model);
  const Puma560IkSolution first = pumaModel.branchOf(s.setpoints.front().position);
  for (const Setpoint& sp : s.setpoints) {
    const Puma560IkSolution here = pumaModel.branchOf(sp.position);
    ASSERT_EQ(here.rightShoulder, first.rightShoulder);
    ASSERT_EQ(here.elbowUp, first.elbowUp);
    ASSERT_EQ(here.wristFlipped, first.wristFlipped);
  }
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, EndEffectorKeepsTheCartesianLimits) {
  Puma560 puma;
  takeOver(puma);
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  const ManipulatorModel& model = puma.getModel();
  tragen.moveTo(kWorkPose);
  run(tragen, model, 6, 100);
  ManipulatorData data(model);
  const Transform start = forwardKinematics(model, data, tragen.getLastTarget());
  CartesianLimits limits;
  limits.linearVelocity = 0.2;
  limits.linearAcceleration = 1.0;
  limits.angularVelocity = 0.8;
  tragen.setCartesianLimits(limits);
  EXPECT_EQ(tragen.getCartesianLimits().linearVelocity, 0.2);
  const Transform goal = translation(0.0, -0.3, -0.1) * start * zRotation(0.5);
  tragen.moveTo(goal);
  const Sampled s = run(tragen, model, 6, 200);
  // End-effector speed and acceleration from finite differences of forward kinematics at 1 kHz
  // (central differences: their error is far below the 1 % allowed here).
  const double dt = 1e-3;
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Matrix3d> R;
  for (const Setpoint& sp : s.setpoints) {
    const Transform& T = forwardKinematics(model, data, sp.position);
    p.push_back(T.block<3, 1>(0, 3));
    R.push_back(T.block<3, 3>(0, 0));
  }
  double vPeak = 0, aPeak = 0, wPeak = 0;
  for (std::size_t k = 1; k + 1 < p.size(); ++k) {
    vPeak = std::max(vPeak, ((p[k + 1] - p[k - 1]) / (2 * dt)).norm());
    aPeak = std::max(aPeak, ((p[k + 1] - 2 * p[k] + p[k - 1]) / (dt * dt)).norm());
    wPeak = std::max(wPeak, Eigen::AngleAxisd(Eigen::Matrix3d(R[k - 1].transpose() * R[k + 1])).angle() / (2 * dt));
  }
  EXPECT_LE(vPeak, limits.linearVelocity * 1.01);
  EXPECT_LE(aPeak, limits.linearAcceleration * 1.01);
  EXPECT_LE(wPeak, limits.angularVelocity * 1.01);
  // The line is long enough to reach the speed limit, and the joints do not limit it here: the
  // motion is time-optimal under the Cartesian limits.
  EXPECT_GT(vPeak, limits.linearVelocity * 0.99);
  std::printf("Cartesian limits 0.2 m/s, 1 m/s^2, 0.8 rad/s: peaks %.4f m/s, %.4f m/s^2, %.4f rad/s\n", vPeak, aPeak,
              wPeak);
  CartesianLimits bad;
  bad.linearVelocity = 0;
  EXPECT_THROW(tragen.setCartesianLimits(bad), std::invalid_argument);
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, Wam7FollowsAStraightLine) {
  WAM wam("", 7);
  takeOver(wam);
  DefaultTrajectoryGenerator<7> tragen;
  wam.setTrajectoryGenerator(tragen);
  JointVector q(7);
  q << 0.3, 0.6, 0.2, 1.6, 0.3, 0.4, 0.2;
  tragen.moveRadians(q);
  const ManipulatorModel& model = wam.getModel();
  run(tragen, model, 7, 100);
  ManipulatorData data(model);
  const Transform start = forwardKinematics(model, data, q);
  const Transform goal = translation(-0.1, 0.15, 0.1) * start * yRotation(-0.4);
  tragen.moveTo(goal);
  checkStraight(model, run(tragen, model, 7, 200), start, goal);
  wam.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, LinesTheArmCannotFollowAreRefusedWhenQueued) {
  Puma560 puma;
  takeOver(puma);
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  tragen.moveTo(kWorkPose);
  run(tragen, puma.getModel(), 6, 100);
  const JointVector q = tragen.getLastTarget();
  ManipulatorData data(puma.getModel());
  const Transform start = forwardKinematics(puma.getModel(), data, q);
  try {
    tragen.moveTo(translation(1.5, 0, 0) * start);  // far out of reach
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("leaves the workspace"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(tragen.isDone());
  for (int i = 0; i < 6; ++i) EXPECT_EQ(tragen.getLastTarget()(i), q(i));
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, JointBlendPassesNearTheViaPointWithoutStopping) {
  Puma560 puma;
  takeOver(puma);
  const ManipulatorModel& model = puma.getModel();
  const auto [a, via, b] = gentleCorner();
  double unblendedTime = 0, blendedTime = 0;
  for (double radius : {0.0, 0.3}) {
    DefaultTrajectoryGenerator<6> tragen;
    puma.setTrajectoryGenerator(tragen);
    tragen.move(a);
    run(tragen, model, 6, 100);
    tragen.setJointBlendRadius(radius);
    tragen.move(via);
    tragen.move(b);
    EXPECT_EQ(tragen.getBlendCount(), radius > 0 ? 1 : 0);
    const Sampled s = run(tragen, model, 6, 200);
    double closest = INFINITY, slowest = INFINITY;
    JointVector v(6);
    for (int i = 0; i < 6; ++i) v(i) = via(i) * kDeg;
    for (const Setpoint& sp : s.setpoints) {
      const double d = (sp.position - v).norm();
      if (d < closest) {
        closest = d;
        slowest = sp.velocity.norm();
      }
    }
    if (radius > 0) {
      EXPECT_LT(closest, radius);
      EXPECT_GT(slowest, 0.1) << "rad/s at the point nearest the via point";
      blendedTime = static_cast<double>(s.setpoints.size());
    } else {
      EXPECT_LT(closest, 1e-6);  // sampled at 1 kHz near the instant of rest
      EXPECT_LT(slowest, 1e-3);
      unblendedTime = static_cast<double>(s.setpoints.size());
    }
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(s.setpoints.back().position(i), b(i) * kDeg, 1e-12);
    puma.clearTrajectoryGenerator();
  }
  EXPECT_LT(blendedTime, unblendedTime - 100) << "ms";
  clock().resume();
}

TEST_F(CartesianMotionTest, CartesianBlendKeepsMovingAroundTheCorner) {
  Puma560 puma;
  takeOver(puma);
  const ManipulatorModel& model = puma.getModel();
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  tragen.moveTo(kWorkPose);
  run(tragen, model, 6, 100);
  ManipulatorData data(model);
  const Transform start = forwardKinematics(model, data, tragen.getLastTarget());
  const Transform corner = translation(0.15, 0, 0) * start, end = translation(0.15, 0.15, 0) * start;
  const double radius = 0.05;
  tragen.setCartesianBlendRadius(radius);
  tragen.moveTo(corner);
  tragen.moveTo(end);
  EXPECT_EQ(tragen.getBlendCount(), 1);
  const Sampled s = run(tragen, model, 6, 200);
  double closest = INFINITY;
  for (const Setpoint& sp : s.setpoints) {
    const Transform& T = forwardKinematics(model, data, sp.position);
    closest = std::min(closest, (T.block<3, 1>(0, 3) - corner.block<3, 1>(0, 3)).norm());
  }
  EXPECT_GT(closest, 1e-3) << "the corner is cut";
  EXPECT_LT(closest, radius) << "but passed within the blend radius";
  const Transform& T = forwardKinematics(model, data, s.setpoints.back().position);
  EXPECT_LT((T - end).cwiseAbs().maxCoeff(), 1e-9);
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, ABlendQueuedTooLateIsSkippedAndTheArmStopsAtTheViaPoint) {
  Puma560 puma;
  takeOver(puma);
  const ManipulatorModel& model = puma.getModel();
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  const auto [a, via, b] = gentleCorner();
  tragen.move(a);
  run(tragen, model, 6, 100);
  tragen.setJointBlendRadius(0.3);
  tragen.move(via);
  // Run the first motion almost to its end (past the point where a blend would leave it).
  Setpoint sp;
  sp.position = sp.velocity = sp.acceleration = JointVector(6);
  double t = 200;
  JointVector v(6);
  for (int i = 0; i < 6; ++i) v(i) = via(i) * kDeg;
  do {
    ASSERT_TRUE(tragen.getCurrentSetpoint(t, sp));
    t += 1e-3;
  } while ((sp.position - v).norm() > 0.05);
  tragen.move(b);
  EXPECT_EQ(tragen.getBlendCount(), 0);  // too late: the arm is past the blend's start
  Setpoint prev = sp;
  double closest = INFINITY, slowest = INFINITY;
  for (; !tragen.isDone(); t += 1e-3) {
    ASSERT_TRUE(tragen.getCurrentSetpoint(t, sp));
    for (int i = 0; i < 6; ++i) ASSERT_LE(std::abs(sp.acceleration(i) - prev.acceleration(i)), 0.8 * model.getJerkLimit()(i) * 1e-3 * 1.0001);
    if ((sp.position - v).norm() < closest) {
      closest = (sp.position - v).norm();
      slowest = sp.velocity.norm();
    }
    prev = sp;
  }
  EXPECT_LT(closest, 1e-6) << "the arm comes to rest on the via point (sampled at 1 kHz)";
  EXPECT_LT(slowest, 1e-3);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(sp.position(i), b(i) * kDeg, 1e-12);
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, EvaluatingPathsAndBlendsDoesNotAllocate) {
  Puma560 puma;
  takeOver(puma);
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  tragen.moveTo(kWorkPose);
  run(tragen, puma.getModel(), 6, 100);
  ManipulatorData data(puma.getModel());
  const Transform start = forwardKinematics(puma.getModel(), data, tragen.getLastTarget());
  tragen.setCartesianBlendRadius(0.03);
  tragen.moveTo(translation(0.1, 0, 0) * start);
  tragen.moveTo(translation(0.1, 0.1, 0) * start);
  tragen.setJointBlendRadius(0.2);
  Vector<6> q;
  q = 0, 40, -120, 0, 30, 0;
  tragen.move(q);
  q = -20, 30, -120, 10, 40, 30;
  tragen.move(q);
  EXPECT_GE(tragen.getBlendCount(), 2);
  Setpoint sp;
  sp.position = sp.velocity = sp.acceleration = JointVector(6);
  test::AllocationGuard guard;
  int cycles = 0;
  for (double t = 200; !tragen.isDone(); t += 1e-3, ++cycles) ASSERT_TRUE(tragen.getCurrentSetpoint(t, sp));
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_GT(cycles, 1000);
  puma.clearTrajectoryGenerator();
  clock().resume();
}

TEST_F(CartesianMotionTest, SimulatedArmExecutesABlendedCartesianSequence) {
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  tragen.moveTo(kWorkPose);
  tragen.stop(0.2);
  const Transform start = kWorkPose;
  tragen.setCartesianBlendRadius(0.03);
  tragen.moveTo(translation(0.1, 0, 0) * start);
  tragen.moveTo(translation(0.1, 0.1, 0) * start);
  tragen.moveTo(translation(0, 0.1, 0) * start);
  tragen.stop(0.5);
  const Transform reached = puma.getEndEffectorTransform();
  const Transform goal = translation(0, 0.1, 0) * start;
  EXPECT_LT((getPosition(reached) - getPosition(goal)).norm(), 0.005);  // 5 mm: friction dead band
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_EQ(tragen.getBlendCount(), 2);
}

}  // namespace
}  // namespace rp
