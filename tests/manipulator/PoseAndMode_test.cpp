// A manipulator's pose, mount and simulation mode changed after its declaration (the paper's
// Figure 23 switches a Puma to simulation right after declaring it): the model follows the new
// base, the arm switches between the simulation and the hardware behind `rp-hwserver`, and a
// change is refused (and undone) while something drives the arm.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "ChildProcess.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/io/HwServerIoBoard.hpp"

namespace rp {
namespace {

using test::simClock;

class PoseAndMode : public test::SimulatedArmTest {};

double maxDifference(const Transform& a, const Transform& b) { return (a - b).cwiseAbs().maxCoeff(); }

TEST_F(PoseAndMode, SetTransformMovesTheModelsBaseWhileTheArmHolds) {
  Puma560 puma("p");
  ASSERT_TRUE(puma.waitForCycles(20));
  const JointVector q0 = puma.getJointPosition();
  const Transform endEffector0 = puma.getEndEffectorTransform();
  const Transform base0 = puma.getModel().getBaseTransform();

  // Half a metre along x, turned 90 degrees about z.
  const Transform pose = Transform(translation(0.5, 0, 0) * zRotation(M_PI / 2));
  puma.setTransform(pose);
  EXPECT_LT(maxDifference(puma.getModel().getBaseTransform(), Transform(pose * base0)), 1e-12);
  // Same joints, the whole arm moved with its base: the end-effector pose is the pose times the old one.
  EXPECT_LT((puma.getJointPosition() - q0).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(maxDifference(puma.getEndEffectorTransform(), Transform(pose * endEffector0)), 1e-6);

  // The arm goes on holding where it was (gravity about the same axis: z turned about z).
  ASSERT_TRUE(puma.waitForCycles(500));
  EXPECT_LT((puma.getJointPosition() - q0).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_FALSE(ObjectManager::isShutdownRequested());
}

TEST_F(PoseAndMode, AMountedArmStandsOnItsMountsFrame) {
  PhysicalObject table("table");
  table.setTransform(translation(1.0, 0.2, 0.8));
  Puma560 leader("leader");
  Puma560 follower("follower");
  ASSERT_TRUE(follower.waitForCycles(10));
  const Transform base0 = follower.getModel().getBaseTransform();

  follower.setTransform(translation(0, 0, 0.05));
  follower.setConnection(table);
  EXPECT_LT(maxDifference(follower.getWorldTransform(), Transform(translation(1.0, 0.2, 0.85))), 1e-15);
  EXPECT_LT(maxDifference(follower.getModel().getBaseTransform(), Transform(translation(1.0, 0.2, 0.85) * base0)), 1e-12);

  // On the other arm's end-effector: the base is that frame's pose now, from the other arm's own
  // forward kinematics, times the object's pose.
  follower.setConnection(leader, "endEffector");
  const Transform mount = leader.getEndEffectorTransform();
  EXPECT_LT(maxDifference(follower.getModel().getBaseTransform(), Transform(mount * translation(0, 0, 0.05) * base0)), 1e-9);
  EXPECT_LT(maxDifference(leader.getFrameTransform("endEffector"), mount), 1e-12);
  EXPECT_THROW(leader.getFrameTransform("link7"), std::invalid_argument);
  EXPECT_THROW(leader.getFrameTransform("link1x"), std::invalid_argument);

  follower.clearConnection();
  EXPECT_LT(maxDifference(follower.getModel().getBaseTransform(), Transform(translation(0, 0, 0.05) * base0)), 1e-12);
  EXPECT_EQ(follower.getErrorCode(), 0) << follower.getErrorStatus().message;
}

TEST_F(PoseAndMode, AConnectionCycleIsRefused) {
  PhysicalObject a("a");
  PhysicalObject b("b");
  b.setConnection(a);
  EXPECT_THROW(a.setConnection(b), std::invalid_argument);
  EXPECT_THROW(a.setConnection(a), std::invalid_argument);
  EXPECT_EQ(a.getConnection(), nullptr);
}

TEST_F(PoseAndMode, NotARigidTransformIsRefused) {
  Puma560 puma("p");
  const Transform before = puma.getTransform();
  Transform scaled = Transform::unit() * 2.0;
  scaled(3, 3) = 1;
  EXPECT_THROW(puma.setTransform(scaled), std::invalid_argument);
  Transform nan = Transform::unit();
  nan(0, 3) = std::nan("");
  EXPECT_THROW(puma.setTransform(nan), std::invalid_argument);
  EXPECT_EQ(puma.getTransform(), before);
}

TEST_F(PoseAndMode, AChangeWhileSomethingDrivesTheArmIsRefusedAndUndone) {
  Puma560 puma("p");
  const Transform base0 = puma.getModel().getBaseTransform();
  {
    test::JointRamp ramp(0, 0.0);
    puma.setTrajectoryGenerator(ramp);
    EXPECT_THROW(puma.setTransform(translation(1, 0, 0)), std::logic_error);
    EXPECT_EQ(puma.getTransform(), Transform::unit()) << "the refused pose stays unset";
    EXPECT_LT(maxDifference(puma.getModel().getBaseTransform(), base0), 1e-15);
    puma.clearTrajectoryGenerator();
  }
  {
    test::ConstantTorque control(0, 0.0);
    puma.setServoControl(control);
    PhysicalObject table("table");
    table.setTransform(translation(0, 0, 0.7));
    EXPECT_THROW(puma.setConnection(table), std::logic_error);
    EXPECT_EQ(puma.getConnection(), nullptr);
    puma.releaseServoControl(control);
  }
  // Zero-gravity mode (someone may be guiding the arm by hand) is refused too.
  puma.setZeroGravityModeOn();
  EXPECT_THROW(puma.setTransform(translation(1, 0, 0)), std::logic_error);
  puma.setZeroGravityModeOff();
  // Nothing drives it any more: the change is taken.
  puma.setTransform(translation(1, 0, 0));
  EXPECT_LT(maxDifference(puma.getModel().getBaseTransform(), Transform(translation(1, 0, 0) * base0)), 1e-12);
}

TEST_F(PoseAndMode, OnAPausedSimulatedClockTheChangeTakesOneCycle) {
  Puma560 puma("p");
  ASSERT_TRUE(puma.waitForCycles(5));
  simClock().pause();
  const std::uint64_t cycles = puma.getCycleCount();
  puma.setTransform(translation(0, 1, 0));
  EXPECT_NEAR(puma.getModel().getBaseTransform()(1, 3), 1.0, 1e-12);
  EXPECT_TRUE(simClock().isPaused()) << "the clock stays paused";
  EXPECT_LE(puma.getCycleCount(), cycles + 2);
}

TEST_F(PoseAndMode, SimulationOffWithoutHardwareIsRefused) {
  RoboticPlatform::setConfiguration(Configuration::parse("[p]\nclass Puma560\nsimulationMode on\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();  // the platform does not force simulation
  Puma560 puma("p");
  ASSERT_TRUE(puma.isSimulationModeOn());
  try {
    puma.setSimulationModeOff();
    ADD_FAILURE() << "switching to hardware that is not configured was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no hardware is configured"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(puma.isSimulationModeOn()) << "the refused mode stays unset";
  EXPECT_FALSE(puma.usesHardware());
  ASSERT_TRUE(puma.waitForCycles(50));
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  RoboticPlatform::setSimulationModeOn();
}

// The same Puma switched from its simulation to the hardware behind `rp-hwserver -board puma560`
// and back, on the real clock; the server's applied outputs say what the arm really got.
TEST(PoseAndModeHardware, ASimulatedArmSwitchesToTheHardwareAndBackLeavingItsOutputsOff) {
  const std::string name = "mode-" + std::to_string(::getpid());
  RoboticPlatform::setConfiguration(
      Configuration::parse("[leader]\nclass Puma560\nsimulationMode on\nhwserver " + name + "\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  RoboticPlatform::useRealClock();
  ObjectManager::resetShutdown();
  test::ChildProcess server({RP_HWSERVER_PATH, "-name", name, "-rate", "1000", "-board", "puma560", "-watchdog", "5000"});
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  HwServerIoBoard monitor(name);
  auto amplifiersOn = [&] {
    bool enable = false;
    return monitor.readAppliedDigitalOutput(0, enable) == IoStatus::kOk && enable;
  };
  auto outputsOff = [&] {
    bool enable = true;
    if (monitor.readAppliedDigitalOutput(0, enable) != IoStatus::kOk || enable) return false;
    for (int j = 0; j < 6; ++j) {
      double volts = 1;
      if (monitor.readAppliedAnalogOutput(j, volts) != IoStatus::kOk || volts != 0.0) return false;
    }
    return true;
  };
  auto waitFor = [](const auto& condition) {  // at most 2 s: less than the server's 5 s watchdog
    for (int i = 0; i < 2000; ++i) {
      if (condition()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  };
  {
    Puma560 puma("leader");
    ASSERT_FALSE(puma.usesHardware());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_FALSE(amplifiersOn()) << "a simulated arm does not drive the hardware";

    puma.setSimulationModeOff();
    EXPECT_TRUE(puma.usesHardware());
    EXPECT_FALSE(puma.isSimulationModeOn());
    EXPECT_TRUE(waitFor(amplifiersOn)) << "the hardware arm is powered, holding";
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const JointVector held = puma.getJointPosition();
    const JointVector home = puma.getModel().getHomePosition();
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(held(i), home(i), 0.01) << "joint " << i + 1;
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;

    // Moving: leaving the hardware (its amplifiers off) is refused until the arm is at rest.
    {
      test::JointRamp ramp(0, 0.3);
      puma.setTrajectoryGenerator(ramp);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      puma.clearTrajectoryGenerator();
      try {
        puma.setSimulationModeOn();
        ADD_FAILURE() << "left the hardware while the arm moved at " << puma.getJointVelocity()(0) << " rad/s";
      } catch (const std::logic_error& e) {
        EXPECT_NE(std::string(e.what()).find("at rest"), std::string::npos) << e.what();
      }
      EXPECT_TRUE(puma.usesHardware());
      EXPECT_FALSE(puma.isSimulationModeOn()) << "the refused mode is undone";
      EXPECT_TRUE(amplifiersOn());
      std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the default control stops it
    }
    const JointVector stopped = puma.getJointPosition();

    const std::uint64_t trips = monitor.watchdogTrips();
    puma.setSimulationModeOn();
    // Switched off by the program as the call returned (applied at the server's next tick), not
    // by the server's watchdog (5 s).
    EXPECT_TRUE(waitFor(outputsOff)) << "the amplifiers or a DAC are still on after leaving the hardware";
    EXPECT_EQ(monitor.watchdogTrips(), trips);
    EXPECT_FALSE(puma.usesHardware());
    // The simulation takes over where the hardware arm was, and holds.
    EXPECT_LT((puma.getJointPosition() - stopped).cwiseAbs().maxCoeff(), 0.01);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_LT((puma.getJointPosition() - stopped).cwiseAbs().maxCoeff(), 0.01);
    EXPECT_TRUE(outputsOff());
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  }
  EXPECT_FALSE(ObjectManager::isShutdownRequested());
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
}

}  // namespace
}  // namespace rp
