// A Puma560 with simulation mode off drives the hardware path: a hardware server
// (`rp-hwserver -board puma560`, a Puma 560 wired to an I/O board) started as a child process.
// Encoder counts in, DAC volts out, amplifier enable; on the real clock.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

#include "ChildProcess.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

class StepTo : public TrajectoryGenerator {
 public:
  explicit StepTo(const JointVector& target) : target_(target) {}
  ~StepTo() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double, Setpoint& sp) override {
    sp.position = target_;
    return true;
  }

 private:
  JointVector target_;
};

// Starts `rp-hwserver -board puma560` named NAME-PID and configures [leader] as a Puma behind
// it, on the real clock. -watchdog 5000: a servo loop stalled by a loaded test machine is not cut
// off by the server.
test::ChildProcess startServer(const std::string& prefix) {
  const std::string name = prefix + "-" + std::to_string(::getpid());
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver " + name + "\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  RoboticPlatform::useRealClock();
  ObjectManager::resetShutdown();
  return test::ChildProcess({RP_HWSERVER_PATH, "-name", name, "-rate", "1000", "-board", "puma560", "-watchdog", "5000"});
}

TEST(HardwareManipulator, PumaBehindAHardwareServerHoldsMovesAndShutsDownWhenTheServerDies) {
  test::ChildProcess server = startServer("test-arm");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  {
    Puma560 puma("leader");
    ASSERT_TRUE(puma.usesHardware());
    const JointVector home = puma.getModel().getHomePosition();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    // Holding under gravity compensation through encoders and DACs (quantised at 5e-5 rad).
    const JointVector held = puma.getJointPosition();
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(held(i), home(i), 0.01) << "joint " << i + 1;
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;

    JointVector target = home;
    target(0) += 0.05;
    StepTo step(target);
    puma.setTrajectoryGenerator(step);
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    EXPECT_NEAR(puma.getJointPosition()(0), target(0), 0.01) << "the arm behind the server follows";
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
    puma.clearTrajectoryGenerator();

    // The server dies: the next reads fail and the servo loop requests a safe shutdown.
    server.signal(SIGKILL);
    ASSERT_TRUE(ObjectManager::waitForShutdown(5));
    EXPECT_NE(puma.getErrorStatus().message.find("hardware failure"), std::string::npos)
        << puma.getErrorStatus().message;
  }
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
}

// Delegates to the default control and stalls the servo thread once, as a busy machine may.
class StallOnce : public ServoControl {
 public:
  explicit StallOnce(DefaultPositionControl& inner) : inner_(inner) {}
  ~StallOnce() override { releaseFromManipulator(); }
  void calculate() override {
    if (++calls == 300) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    inner_.calculate();
  }
  std::atomic<int> calls{0};

 private:
  DefaultPositionControl& inner_;
};

TEST(HardwareManipulator, AStalledCycleIsNoVelocitySpike) {
  // 100 ms without a cycle while joint 1 moves at 0.5 rad/s: the encoders moved 0.05 rad, which
  // divided by one period (1 ms) read as 50 rad/s and tripped the 2 rad/s velocity limit. The
  // velocity is taken over the time that really passed.
  test::ChildProcess server = startServer("test-stall");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  {
    Puma560 puma("leader");
    StallOnce stall(puma.getDefaultPositionControl());
    test::JointRamp ramp(0, 0.5, 1.0);  // joint 1 at 0.5 rad/s for 1 s
    puma.setServoControl(stall);
    puma.setTrajectoryGenerator(ramp);
    for (int i = 0; i < 3000 && stall.calls.load() < 1000; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_GE(stall.calls.load(), 1000);
    EXPECT_GE(puma.getStatistics().missedCycles, 90u) << "the stall happened";
    EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
    puma.clearTrajectoryGenerator();
  }
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
}

TEST(HardwareManipulator, AnAbsentServerIsAClearError) {
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver no-such-server\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  EXPECT_THROW(Puma560("leader"), IoException);
  RoboticPlatform::setSimulationModeOn();
}

}  // namespace
}  // namespace rp
