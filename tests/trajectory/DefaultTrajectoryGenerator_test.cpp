// DefaultTrajectoryGenerator driving simulated arms on the simulated clock.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include "../manipulator/SimulatedArmTest.hpp"
#include "AllocationCounter.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

using TrajectoryTest = test::SimulatedArmTest;

TEST_F(TrajectoryTest, JointMovesInDegreesReachTheirTargets) {
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  Vector<6> target;
  target = 0, 45, -90, 0, 0, 0;
  tragen.move(target);
  target = -50, 0, -70, 50, -80, 0;
  tragen.move(target);
  EXPECT_GE(tragen.getSegmentsLeft(), 1);
  tragen.stop(0.5);
  EXPECT_TRUE(tragen.isDone());
  const JointVector q = puma.getJointPosition();
  // Within the PID's Coulomb-friction dead band after half a second at rest (< 0.01 rad).
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q(i), target(i) * kDeg, 0.01) << "joint " << i + 1;
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(TrajectoryTest, TargetsOutsideTheLimitsAreRefusedBeforeTheArmMoves) {
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  Vector<6> target;
  target = 0, 120, 0, 0, 0, 0;  // joint 2 limit 110 degrees
  try {
    tragen.move(target);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("target joint 2 = 120"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(tragen.isDone());
  Vector<5> five;
  EXPECT_THROW(tragen.move(five), std::invalid_argument);
  EXPECT_THROW(tragen.moveTo(translation(3, 0, 0)), std::invalid_argument);  // out of reach
}

TEST_F(TrajectoryTest, CartesianTargetIsReached) {
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  const Transform goal = translation(0.5, 0.2, 0.3) * xRotation(M_PI);
  tragen.moveTo(goal);
  tragen.stop(1);
  const Transform reached = puma.getEndEffectorTransform();
  EXPECT_LT((getPosition(reached) - getPosition(goal)).norm(), 0.005);  // 5 mm: friction dead band
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(TrajectoryTest, AFixedSizeGeneratorRefusesAnotherArm) {
  WAM wam("", 7);
  DefaultTrajectoryGenerator<6> six;
  EXPECT_THROW(wam.setTrajectoryGenerator(six), std::invalid_argument);
  DefaultTrajectoryGenerator any;
  wam.setTrajectoryGenerator(any);
  JointVector home = wam.getModel().getHomePosition();
  home(0) += 0.2;
  any.moveRadians(home);
  any.stop(0.2);
  EXPECT_NEAR(wam.getJointPosition()(0), home(0), 0.01);
}

TEST_F(TrajectoryTest, SetpointEvaluationDoesNotAllocateAndStaysWithinLimits) {
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  Setpoint sp;
  sp.position = sp.velocity = sp.acceleration = JointVector(6);
  SimulatedClock& clock = dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
  clock.pause();  // evaluate here, not in the servo thread
  // The loop runs its first cycle when its thread starts, even on a paused clock: let it.
  while (puma.getCycleCount() < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  puma.clearTrajectoryGenerator();
  puma.setTrajectoryGenerator(tragen);
  const ManipulatorModel& model = puma.getModel();
  // Each synchronisation mode in turn (issue 17), each motion planned and evaluated in turn.
  const Synchronization modes[3] = {Synchronization::Time, Synchronization::Phase, Synchronization::None};
  Vector<6> targets[3];
  targets[0] = 30, 60, -60, 20, 20, 20;
  targets[1] = -20, 30, -100, 60, -40, 90;
  targets[2] = 10, 80, -30, -50, 60, -20;
  double t0 = 1000;
  for (int m = 0; m < 3; ++m) {
    tragen.setSynchronization(modes[m]);
    const Vector<6>& target = targets[m];
    test::AllocationGuard guard;
    tragen.move(target);  // planning, in the caller's thread, may allocate: only evaluation may not
    const std::size_t planning = guard.count();
    double worstVelocityRatio = 0;
    for (int i = 0; i < 20000; ++i) {
      ASSERT_TRUE(tragen.getCurrentSetpoint(t0 + i * 1e-3, sp));
      for (int k = 0; k < 6; ++k) {
        worstVelocityRatio = std::max(worstVelocityRatio, std::abs(sp.velocity(k)) / model.getVelocityLimit()(k));
        ASSERT_LE(std::abs(sp.acceleration(k)), 0.8 * model.getAccelerationLimit()(k) * (1 + 1e-9));
      }
    }
    EXPECT_EQ(guard.count(), planning) << "evaluation allocated, " << toString(modes[m]);
    EXPECT_LE(worstVelocityRatio, 0.8 * (1 + 1e-9)) << "planned with 80 % of the limits";
    EXPECT_TRUE(tragen.isDone());
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(sp.position(k), target(k) * kDeg, 1e-12);
    t0 += 30;
  }
  puma.clearTrajectoryGenerator();
  clock.resume();
}

}  // namespace
}  // namespace rp
